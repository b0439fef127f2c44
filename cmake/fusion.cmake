# Fusion component: FusionNodelet, fusion_node, their tests and benchmarks.
add_library(map_aided_fusion_fusion_nodelet
  src/ros/fusion_worker.cpp
  src/ros/visualization.cpp
  src/nodelets/fusion_nodelet.cpp
)
target_link_libraries(map_aided_fusion_fusion_nodelet map_aided_fusion_ros ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_fusion_nodelet ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg)

add_executable(fusion_node src/nodes/fusion_node.cpp)
target_link_libraries(fusion_node map_aided_fusion_fusion_nodelet)

install(TARGETS map_aided_fusion_fusion_nodelet fusion_node
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_fusion_ros test/ros/test_visualization.cpp test/test_main.cpp)
  target_link_libraries(test_fusion_ros map_aided_fusion_fusion_nodelet)

  add_rostest_gtest(test_fusion_pipeline test/fusion_pipeline.test test/ros/test_fusion_pipeline.cpp)
  target_link_libraries(test_fusion_pipeline ${catkin_LIBRARIES} ${GTEST_LIBRARIES})

  # End to end at high resolution: ~130k-point clouds at 10 Hz, 800 x 800 cells at 0.2 m; latency reported.
  add_rostest_gtest(test_high_resolution test/high_resolution.test test/ros/test_high_resolution.cpp)
  target_link_libraries(test_high_resolution ${catkin_LIBRARIES} ${GTEST_LIBRARIES})

  # Faults (wall time) and a looping replay (simulated time): one executable, two launch files.
  add_rostest_gtest(test_faults test/faults.test test/ros/test_faults.cpp)
  target_link_libraries(test_faults ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  target_compile_definitions(test_faults PRIVATE MAF_FUSION_NODE="$<TARGET_FILE:fusion_node>")
  add_dependencies(test_faults fusion_node map_aided_fusion_fusion_nodelet)
  add_rostest(test/bag_loop.test DEPENDENCIES test_faults)
  add_rostest(test/clock_lag.test DEPENDENCIES test_faults)
  add_rostest_gtest(test_no_map test/no_map.test test/ros/test_no_map.cpp)
  target_link_libraries(test_no_map ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(test_no_map simulate map_aided_fusion_fusion_nodelet map_aided_fusion_scan_grid_nodelet)
endif()

if(TARGET bench_map_aided_fusion)
  target_sources(bench_map_aided_fusion PRIVATE bench/bench_map_grid.cpp)
endif()
