# PriorGrid component: map reading (GDAL/OGR + GeographicLib, ROS-free library map_aided_fusion_map_io),
# the core rasteriser and PriorGrid, the map-loader nodelet, the prior_grid_tool, tests and benchmarks.

# ---- ROS-free map reading -------------------------------------------------------------------
add_library(map_aided_fusion_map_io
  src/map_io/map_loader.cpp
  src/map_io/projection.cpp
  src/map_io/prior_png.cpp
  src/map_io/prior_grid_params.cpp
)
target_include_directories(map_aided_fusion_map_io PUBLIC
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
target_include_directories(map_aided_fusion_map_io SYSTEM PRIVATE ${GDAL_INCLUDE_DIRS} ${GeographicLib_INCLUDE_DIRS})
target_link_libraries(map_aided_fusion_map_io PUBLIC map_aided_fusion_core PRIVATE ${GDAL_LIBRARIES} ${GeographicLib_LIBRARIES})
set_target_properties(map_aided_fusion_map_io PROPERTIES POSITION_INDEPENDENT_CODE ON)

install(TARGETS map_aided_fusion_map_io
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# ---- Core: scanline rasteriser and PriorGrid (ROS-free) ---------------------------------------
target_sources(map_aided_fusion_core PRIVATE src/core/prior_grid.cpp src/core/prior_uncertainty.cpp)

# ---- ROS: nodelet (library name fixed by nodelet_plugins.xml) and plain node -------------------------
add_library(map_aided_fusion_prior_grid_nodelet
  src/ros/prior_grid_worker.cpp
  src/nodelets/prior_grid_nodelet.cpp
)
target_link_libraries(map_aided_fusion_prior_grid_nodelet map_aided_fusion_ros map_aided_fusion_map_io ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_prior_grid_nodelet ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})

add_executable(prior_grid_node src/nodes/prior_grid_node.cpp)
target_link_libraries(prior_grid_node map_aided_fusion_prior_grid_nodelet)

install(TARGETS map_aided_fusion_prior_grid_nodelet prior_grid_node
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# ---- Tests --------------------------------------------------------------------------------------
if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_prior_grid test/prior/test_prior_grid.cpp test/prior/test_prior_uncertainty.cpp test/test_main.cpp)
  target_link_libraries(test_prior_grid map_aided_fusion_core)

  catkin_add_gtest(test_map_loader test/prior/test_map_loader.cpp test/prior/test_reader_faults.cpp test/test_main.cpp)
  target_link_libraries(test_map_loader map_aided_fusion_map_io ${GeographicLib_LIBRARIES} ${GDAL_LIBRARIES})
  target_include_directories(test_map_loader SYSTEM PRIVATE ${GeographicLib_INCLUDE_DIRS} ${GDAL_INCLUDE_DIRS})
  target_compile_definitions(test_map_loader PRIVATE
    MAF_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data"
    MAF_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    MAF_PRIOR_GRID_TOOL="$<TARGET_FILE:prior_grid_tool>")
  add_dependencies(test_map_loader prior_grid_tool)

  catkin_add_gtest(test_prior_grid_params test/prior/test_prior_grid_params.cpp test/test_main.cpp)
  target_link_libraries(test_prior_grid_params map_aided_fusion_map_io yaml-cpp)
  target_compile_definitions(test_prior_grid_params PRIVATE MAF_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")

  # rostest: latched prior received by a late subscriber; a bad map path is reported and the node stays alive.
  add_executable(test_prior_grid_ros EXCLUDE_FROM_ALL test/prior/test_prior_grid_ros.cpp)
  target_link_libraries(test_prior_grid_ros ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(test_prior_grid_ros ${PROJECT_NAME}_generate_messages_cpp)
  add_dependencies(tests test_prior_grid_ros map_aided_fusion_prior_grid_nodelet)
  add_rostest(test/prior_grid.test DEPENDENCIES test_prior_grid_ros map_aided_fusion_prior_grid_nodelet)
endif()

# ---- Benchmarks -----------------------------------------------------------------------------------
if(TARGET bench_map_aided_fusion)
  target_sources(bench_map_aided_fusion PRIVATE bench/bench_prior_grid.cpp)
  target_link_libraries(bench_map_aided_fusion map_aided_fusion_map_io)
  target_compile_definitions(bench_map_aided_fusion PRIVATE
    MAF_PRIOR_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data")
endif()

# ---- Command-line tool (ROS-free) -----------------------------------------------------------------
add_executable(prior_grid_tool src/tools/prior_grid_tool.cpp)
target_link_libraries(prior_grid_tool map_aided_fusion_map_io yaml-cpp)
install(TARGETS prior_grid_tool RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
