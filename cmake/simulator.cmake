# Scenario simulator: ROS-free library (STL + yaml-cpp), rosbag writer, `simulate` tool, tests, benchmarks.
add_library(map_aided_fusion_sim
  src/sim/geometry.cpp
  src/sim/scene.cpp
  src/sim/motion.cpp
  src/sim/lidar.cpp
  src/sim/ground_truth.cpp
  src/sim/scenario.cpp
  src/sim/simulator.cpp
)
target_include_directories(map_aided_fusion_sim PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
target_link_libraries(map_aided_fusion_sim PUBLIC map_aided_fusion_core PRIVATE yaml-cpp)
set_target_properties(map_aided_fusion_sim PROPERTIES POSITION_INDEPENDENT_CODE ON)

install(TARGETS map_aided_fusion_sim
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY scenarios DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_simulator
    test/sim/test_geometry.cpp
    test/sim/test_motion.cpp
    test/sim/test_simulator.cpp
    test/sim/test_scenarios.cpp
    test/sim/test_real_data.cpp
    test/test_main.cpp
  )
  target_link_libraries(test_simulator map_aided_fusion_sim)
  target_compile_definitions(test_simulator PRIVATE MAF_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    MAF_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data")
endif()

if(TARGET bench_map_aided_fusion)
  target_sources(bench_map_aided_fusion PRIVATE bench/bench_simulator.cpp bench/bench_drive.cpp)
  target_link_libraries(bench_map_aided_fusion map_aided_fusion_sim)
  if(TARGET map_aided_fusion_map_io)
    target_link_libraries(bench_map_aided_fusion map_aided_fusion_map_io)
    target_compile_definitions(bench_map_aided_fusion PRIVATE MAF_SIM_BENCH_MAP_IO
      MAF_SIM_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data")
  endif()
endif()

# ROS layer: message converters and the rosbag writer over the ROS-free simulator.
add_library(map_aided_fusion_sim_bag src/ros/sim_bag.cpp)
target_link_libraries(map_aided_fusion_sim_bag map_aided_fusion_sim map_aided_fusion_ros ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_sim_bag ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})
install(TARGETS map_aided_fusion_sim_bag
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# `simulate` needs the map loader (map_aided_fusion_map_io, from cmake/prior_grid.cmake).
if(TARGET map_aided_fusion_map_io)
  add_executable(simulate src/tools/simulate.cpp)
  target_link_libraries(simulate map_aided_fusion_sim_bag map_aided_fusion_map_io)
  install(TARGETS simulate RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
else()
  message(STATUS "map_aided_fusion_map_io not found: the simulate tool is not built")
endif()

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_sim_bag test/ros/test_sim_bag.cpp test/test_main.cpp)
  target_link_libraries(test_sim_bag map_aided_fusion_sim_bag)
endif()

# Tests on maps read by the loader (town.osm, and the real Monaco extract when ../shared/data exists).
if(CATKIN_ENABLE_TESTING AND TARGET map_aided_fusion_map_io)
  catkin_add_gtest(test_sim_maps test/sim/test_sim_maps.cpp test/test_main.cpp)
  target_link_libraries(test_sim_maps map_aided_fusion_sim map_aided_fusion_map_io)
  target_compile_definitions(test_sim_maps PRIVATE MAF_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    MAF_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data")
endif()
