# Real labelled datasets: ROS-free KITTI / SemanticKITTI reader, its bag writer, the `kitti_to_bag` tool, tests.
add_library(map_aided_fusion_dataset src/dataset/kitti.cpp src/dataset/kitti_tracking.cpp)
target_include_directories(map_aided_fusion_dataset PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
target_link_libraries(map_aided_fusion_dataset Eigen3::Eigen)
set_target_properties(map_aided_fusion_dataset PROPERTIES POSITION_INDEPENDENT_CODE ON)

add_library(map_aided_fusion_dataset_ros src/ros/kitti_bag.cpp)
target_link_libraries(map_aided_fusion_dataset_ros map_aided_fusion_dataset ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_dataset_ros ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})

add_executable(kitti_to_bag src/tools/kitti_to_bag.cpp)
target_link_libraries(kitti_to_bag map_aided_fusion_dataset_ros)

install(TARGETS map_aided_fusion_dataset map_aided_fusion_dataset_ros kitti_to_bag
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_dataset test/dataset/test_kitti.cpp test/dataset/test_kitti_ground.cpp
    test/dataset/test_kitti_tracking.cpp test/test_main.cpp)
  target_link_libraries(test_dataset map_aided_fusion_dataset_ros map_aided_fusion_core)
  target_compile_definitions(test_dataset PRIVATE MAF_SHARED_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../shared/data"
    MAF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
  add_dependencies(tests kitti_to_bag)
endif()
