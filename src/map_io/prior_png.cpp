#include "map_aided_fusion/map_io/prior_png.hpp"

#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <cpl_error.h>
#include <gdal_priv.h>

namespace map_aided_fusion {
namespace map_io {

namespace {

constexpr int kOpaque = 255;

struct GdalCloser
{
  void operator()(GDALDataset* ds) const { GDALClose(ds); }
};

}  // namespace

void writePriorPng(const core::PriorGrid& grid, const std::string& path)
{
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
  const core::GridGeometry& g = grid.geometry();
  const auto fail = [&](const std::string& why) { throw std::runtime_error("PNG '" + path + "': " + why); };
  if (g.width <= 0 || g.height <= 0) fail("the prior grid is empty");
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* png = GetGDALDriverManager()->GetDriverByName("PNG");
  if (mem == nullptr || png == nullptr) fail("GDAL has no MEM or PNG driver");
  std::unique_ptr<GDALDataset, GdalCloser> ds(mem->Create("", g.width, g.height, 1, GDT_Byte, nullptr));
  if (!ds) fail("cannot allocate the image");
  GDALRasterBand* band = ds->GetRasterBand(1);
  const auto* labels = reinterpret_cast<const std::uint8_t*>(grid.labels().data());
  for (int r = 0; r < g.height; ++r)
  {
    // Image row 0 is the north edge: the grid's last row.
    auto* row = const_cast<std::uint8_t*>(labels + g.index(0, g.height - 1 - r));
    if (band->RasterIO(GF_Write, 0, r, g.width, 1, row, g.width, 1, GDT_Byte, 0, 0) != CE_None)
      fail("cannot fill the image");
  }
  GDALColorTable colours;
  for (int c = 0; c < core::kNumPriorClasses; ++c)
  {
    const GDALColorEntry e{ kPriorPngColours[c][0], kPriorPngColours[c][1], kPriorPngColours[c][2], kOpaque };
    colours.SetColorEntry(c, &e);
  }
  band->SetColorTable(&colours);
  CPLErrorReset();
  std::unique_ptr<GDALDataset, GdalCloser> out(
      png->CreateCopy(path.c_str(), ds.get(), FALSE, nullptr, nullptr, nullptr));
  if (!out) fail(CPLGetLastErrorMsg()[0] != '\0' ? CPLGetLastErrorMsg() : "GDAL cannot write it");
}

}  // namespace map_io
}  // namespace map_aided_fusion
