# Evaluation: ROS-free metrics library, the `evaluate` tool (reads bags) and its tests.
add_library(map_aided_fusion_eval src/eval/metrics.cpp src/eval/point_labels.cpp src/eval/scan_evidence.cpp
  src/eval/movers.cpp src/eval/clear_mot.cpp)
target_link_libraries(map_aided_fusion_eval map_aided_fusion_core)
target_include_directories(map_aided_fusion_eval PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)

install(TARGETS map_aided_fusion_eval
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_metrics test/eval/test_metrics.cpp test/eval/test_movers.cpp test/eval/test_clear_mot.cpp
    test/eval/test_point_labels.cpp test/eval/test_scan_evidence.cpp
    test/test_main.cpp)
  target_link_libraries(test_metrics map_aided_fusion_eval)
endif()

# The offline replay (bags through the core, scored, reported): a library, so that tests reach it piece by piece;
# `evaluate` parses its options and calls it.
add_library(map_aided_fusion_replay src/replay/offline_replay.cpp src/replay/options.cpp src/replay/report.cpp
  src/replay/variants.cpp src/replay/npy.cpp src/replay/labelled_sweeps.cpp)
target_link_libraries(map_aided_fusion_replay map_aided_fusion_eval map_aided_fusion_map_io
  map_aided_fusion_scan_grid_nodelet map_aided_fusion_dataset_ros yaml-cpp ${catkin_LIBRARIES})
add_dependencies(map_aided_fusion_replay ${PROJECT_NAME}_generate_messages_cpp)
add_executable(evaluate src/tools/evaluate.cpp)
target_link_libraries(evaluate map_aided_fusion_replay)
install(TARGETS map_aided_fusion_replay evaluate
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_replay test/replay/test_replay.cpp test/test_main.cpp)
  target_link_libraries(test_replay map_aided_fusion_replay map_aided_fusion_sim_bag)
  target_compile_definitions(test_replay PRIVATE MAF_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  add_rostest_gtest(test_demo_scores test/demo.test test/ros/test_demo_scores.cpp)
  target_link_libraries(test_demo_scores map_aided_fusion_eval ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_rostest_gtest(test_kitti_replay test/kitti_replay.test test/ros/test_kitti_replay.cpp)
  target_link_libraries(test_kitti_replay map_aided_fusion_eval map_aided_fusion_dataset_ros ${catkin_LIBRARIES}
    ${GTEST_LIBRARIES})
  target_compile_definitions(test_kitti_replay PRIVATE MAF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
  set(_maf_tools_xml "${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-tools.xml")
  catkin_run_tests_target("pytest" "tools" "pytest-tools.xml"
    COMMAND "env MAF_BIN=${CATKIN_DEVEL_PREFIX}/lib/${PROJECT_NAME} PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m pytest -q -p no:cacheprovider -rs --junitxml=${_maf_tools_xml} ${CMAKE_CURRENT_SOURCE_DIR}/test/tools ${CMAKE_CURRENT_SOURCE_DIR}/test/package"
    DEPENDENCIES simulate evaluate parameter_reference)
  add_dependencies(tests kitti_to_bag simulate evaluate map_aided_fusion_fusion_nodelet map_aided_fusion_scan_grid_nodelet
    map_aided_fusion_prior_grid_nodelet)
endif()
