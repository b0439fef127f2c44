# Learning: generated drives with a held-out split and the optuna tuner (learning/, Python, Debian's python3-optuna),
# installed beside the package's executables (`rosrun map_aided_fusion tune`), and their pytest suites.
catkin_install_python(PROGRAMS learning/tune learning/make_drives learning/held_out DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(DIRECTORY learning/maf_learning DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION}
  PATTERN "__pycache__" EXCLUDE)
install(FILES learning/drives.yaml learning/search_space.yaml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/learning)

if(CATKIN_ENABLE_TESTING)
  set(_maf_pytest_xml "${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-learning.xml")
  catkin_run_tests_target("pytest" "learning" "pytest-learning.xml"
    COMMAND "env MAF_BIN=${CATKIN_DEVEL_PREFIX}/lib/${PROJECT_NAME} PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m pytest -q -p no:cacheprovider -rs --junitxml=${_maf_pytest_xml} ${CMAKE_CURRENT_SOURCE_DIR}/test/learning"
    DEPENDENCIES simulate evaluate kitti_to_bag)
endif()
