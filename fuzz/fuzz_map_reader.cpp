// libFuzzer target: bytes -> an in-memory map file (GDAL /vsimem/) -> loadVectorMap (GDAL/OGR + GeographicLib)
// -> PriorGrid.
// The first byte picks the format (OSM XML or GeoJSON) and whether the coordinates are metric. Built and run
// by scripts/fuzz; every crash found becomes a unit test (test/prior/test_reader_faults.cpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include <cpl_error.h>
#include <cpl_vsi.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"

namespace {

/// Grids larger than this are not rasterised (the loader's own job ends at the vector map).
constexpr double kMaxFuzzCells = 4e6;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace map_aided_fusion;
  if (size < 1) return 0;
  static const bool quiet = [] {
    CPLSetErrorHandler(CPLQuietErrorHandler);
    return true;
  }();
  (void)quiet;
  const std::uint8_t mode = data[0];
  const std::string ext = (mode & 1) ? ".geojson" : ".osm";
  const std::string path = "/vsimem/maf_fuzz_map" + ext;
  VSIFCloseL(VSIFileFromMemBuffer(path.c_str(), const_cast<GByte*>(data + 1), static_cast<vsi_l_offset>(size - 1),
                                  FALSE));
  map_io::MapLoadParams p;
  p.file = path;
  p.metric = (mode & 2) != 0;
  if (mode & 4)
  {
    p.origin_latitude = 49.0;
    p.origin_longitude = 2.0;
  }
  try
  {
    const core::VectorMap map = map_io::loadVectorMap(p);
    const core::GridGeometry extent = core::PriorGrid::extentOf(map, 0.5, 5.0);
    if (extent.width > 0 && extent.height > 0 && static_cast<double>(extent.numCells()) <= kMaxFuzzCells)
    {
      core::PriorGrid grid;
      grid.build(map, extent);
    }
  }
  catch (const map_io::MapLoadError&)
  {
  }
  catch (const core::ParameterError&)
  {
  }
  VSIUnlink(path.c_str());
  return 0;
}
