# ScanGrid component: lidar PointCloud2 -> evidential grid of masses on {F, O}.
# Included from CMakeLists.txt after the core, the ROS layer and the benchmark targets exist.

# The ground model is the one core file that uses PCL (RANSAC plane fits); its header does not include PCL.
find_package(PCL REQUIRED COMPONENTS common sample_consensus segmentation)
target_sources(map_aided_fusion_core PRIVATE src/core/scan_grid.cpp src/core/deskew.cpp src/core/ground_model.cpp)
target_include_directories(map_aided_fusion_core SYSTEM PRIVATE ${PCL_INCLUDE_DIRS})
target_link_libraries(map_aided_fusion_core ${PCL_COMMON_LIBRARIES} ${PCL_SAMPLE_CONSENSUS_LIBRARIES}
  ${PCL_SEGMENTATION_LIBRARIES})

# pcl_ros filter nodelets (launch/pcl_filters.launch): the launch file runs their manager through
# `rosrun map_aided_fusion with_pcl_ros_filters`, which lets pluginlib find Debian's library; nothing of pcl_ros is
# linked or installed.
install(PROGRAMS scripts/with_pcl_ros_filters DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# Nodelet library (name fixed by nodelet_plugins.xml) and its worker, shared with the plain node.
add_library(map_aided_fusion_scan_grid_nodelet
  src/ros/point_cloud_view.cpp
  src/ros/cloud_deskew.cpp
  src/ros/scan_grid_worker.cpp
  src/nodelets/scan_grid_nodelet.cpp
)
target_link_libraries(map_aided_fusion_scan_grid_nodelet map_aided_fusion_ros map_aided_fusion_core ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_scan_grid_nodelet ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg
  ${catkin_EXPORTED_TARGETS})

add_executable(scan_grid_node src/nodes/scan_grid_node.cpp)
target_link_libraries(scan_grid_node map_aided_fusion_scan_grid_nodelet)

install(TARGETS map_aided_fusion_scan_grid_nodelet scan_grid_node
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(TARGET bench_map_aided_fusion)
  target_sources(bench_map_aided_fusion PRIVATE bench/bench_scan_grid.cpp)
endif()

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_scan_grid
    test/core/test_scan_grid.cpp
    test/core/test_scan_grid_real.cpp
    test/core/test_deskew_ground.cpp
    test/test_main.cpp
  )
  target_link_libraries(test_scan_grid map_aided_fusion_core yaml-cpp)
  target_compile_definitions(test_scan_grid PRIVATE
    MAF_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data")

  catkin_add_gtest(test_scan_grid_ros test/ros/test_point_cloud_view.cpp test/ros/test_cloud_deskew.cpp test/test_main.cpp)
  target_link_libraries(test_scan_grid_ros map_aided_fusion_scan_grid_nodelet)

  add_executable(scan_grid_rostest_node EXCLUDE_FROM_ALL test/ros/scan_grid_rostest_node.cpp)
  target_link_libraries(scan_grid_rostest_node ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(scan_grid_rostest_node ${PROJECT_NAME}_generate_messages_cpp)
  add_dependencies(tests scan_grid_rostest_node)
  add_rostest(test/scan_grid.test DEPENDENCIES scan_grid_rostest_node scan_grid_node map_aided_fusion_scan_grid_nodelet)

  # pcl_ros composition (launch/pcl_filters.launch).
  add_executable(pcl_filters_rostest_node EXCLUDE_FROM_ALL test/ros/pcl_filters_rostest_node.cpp)
  target_link_libraries(pcl_filters_rostest_node ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(tests pcl_filters_rostest_node)
  add_rostest(test/pcl_filters.test DEPENDENCIES pcl_filters_rostest_node map_aided_fusion_scan_grid_nodelet)

  # The paper's sensor (launch/ibeo.launch, config/ibeo/scan_grid.yaml).
  add_executable(ibeo_rostest_node EXCLUDE_FROM_ALL test/ros/ibeo_rostest_node.cpp)
  target_link_libraries(ibeo_rostest_node ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(tests ibeo_rostest_node)
  add_rostest(test/ibeo.test DEPENDENCIES ibeo_rostest_node map_aided_fusion_scan_grid_nodelet)
endif()
