// libFuzzer target: bytes -> features in memory -> the map loader's own geometry path (coordinate checks, hole
// and validity repair with GEOS, projection with GeographicLib, origin and range checks; map_io::buildVectorMap)
// -> PriorGrid (rasteriser, both cell tests). No file and no GDAL driver, so that it runs ~10^6 inputs in minutes.
//
// Layout: byte 0 picks the options (bit 0 metric, bit 1 an origin given, bit 2 no repair, bit 3 coverage test);
// then features: [kind][parts][vertices per part]... and per vertex two int16 offsets (5 mm or 5e-8 degree
// steps around the origin); an offset of INT16_MIN reads the next 8 bytes as a raw double (NaN, infinities,
// huge values and the far side of the globe). Built and run by scripts/fuzz; every crash becomes a unit test.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"

namespace {

/// Grids larger than this are not rasterised: the rasteriser's cases are the same at any size, and small grids keep
/// an execution (with the coverage test's 16 samples a cell, under the sanitizers) well under a millisecond.
constexpr double kMaxFuzzCells = 2e4;
constexpr double kFuzzResolution = 1.0;  // m
constexpr double kOriginLat = 49.0;
constexpr double kOriginLon = 2.0;
constexpr double kDegreeStep = 5e-8;  // ~5 mm: int16 offsets span ±180 m
constexpr double kMetreStep = 0.005;
constexpr std::size_t kMaxFeatures = 16;
constexpr std::size_t kMaxParts = 4;
constexpr std::size_t kMaxVertices = 64;

class Reader
{
public:
  Reader(const std::uint8_t* d, std::size_t n) : d_(d), n_(n) {}
  bool more() const { return i_ < n_; }
  std::uint8_t byte() { return i_ < n_ ? d_[i_++] : 0; }
  std::int16_t i16()
  {
    const std::uint16_t lo = byte(), hi = byte();
    return static_cast<std::int16_t>(lo | (hi << 8));
  }
  double raw()
  {
    std::uint8_t b[8] = {};
    for (auto& x : b) x = byte();
    double v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

private:
  const std::uint8_t* d_;
  std::size_t n_;
  std::size_t i_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace map_aided_fusion;
  if (size < 2) return 0;
  Reader in(data, size);
  const std::uint8_t mode = in.byte();
  map_io::MapLoadParams p;
  p.metric = (mode & 1) != 0;
  if (mode & 2)
  {
    p.origin_latitude = kOriginLat;
    p.origin_longitude = kOriginLon;
  }
  p.repair_invalid = (mode & 4) == 0;
  p.max_vertices_per_feature = 200;
  const double base_x = p.metric ? 0.0 : kOriginLon, base_y = p.metric ? 0.0 : kOriginLat;
  const double step = p.metric ? kMetreStep : kDegreeStep;
  auto coordinate = [&](double base) {
    const std::int16_t v = in.i16();
    return v == std::numeric_limits<std::int16_t>::min() ? in.raw() : base + step * v;
  };
  std::vector<map_io::SourceFeature> features;
  while (in.more() && features.size() < kMaxFeatures)
  {
    map_io::SourceFeature f;
    const std::uint8_t kind = in.byte();
    f.kind = static_cast<map_io::SourceFeature::Kind>(kind % 3);
    f.id = "f" + std::to_string(features.size());
    f.height = (kind >> 2) & 7;
    f.width = 1.0 + ((kind >> 5) & 7);
    const std::size_t parts = 1 + in.byte() % kMaxParts;
    for (std::size_t k = 0; k < parts && in.more(); ++k)
    {
      const std::size_t vertices = in.byte() % kMaxVertices;
      std::vector<core::Point2> part;
      for (std::size_t v = 0; v < vertices && in.more(); ++v)
      {
        const double x = coordinate(base_x);
        const double y = coordinate(base_y);
        part.push_back({ x, y });
      }
      f.parts.push_back(std::move(part));
    }
    features.push_back(std::move(f));
  }
  try
  {
    const core::VectorMap map = map_io::buildVectorMap(features, p);
    const core::GridGeometry extent = core::PriorGrid::extentOf(map, kFuzzResolution, 5.0);
    if (extent.width > 0 && extent.height > 0 && static_cast<double>(extent.numCells()) <= kMaxFuzzCells)
    {
      core::PriorGrid grid;
      grid.build(map, extent, nullptr, (mode & 8) ? core::PriorCellTest::kCoverage : core::PriorCellTest::kCentre);
    }
  }
  catch (const map_io::MapLoadError&)
  {
  }
  catch (const core::ParameterError&)
  {
  }
  return 0;
}
