# Generated documentation: the parameter reference (doc/parameters.md) printed from the parameter structs.
add_executable(parameter_reference src/tools/parameter_reference.cpp)
target_link_libraries(parameter_reference map_aided_fusion_fusion_nodelet map_aided_fusion_scan_grid_nodelet
  map_aided_fusion_map_io)
install(TARGETS parameter_reference RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
