# PriorGrid component: map reading (GDAL/OGR + GeographicLib, ROS-free library map_aided_fusion_map_io),
# the core rasteriser and PriorGrid, the map-loader nodelet, the prior_grid_tool, tests and benchmarks.

# ---- ROS-free map reading -------------------------------------------------------------------
add_library(map_aided_fusion_map_io
  src/map_io/map_loader.cpp
  src/map_io/projection.cpp
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
