/**
 * @file prior_png.hpp
 * @brief Writes a PriorGrid as a paletted PNG in the paper's colours (GDAL's PNG driver): roads white,
 *        buildings blue, other grey, outside the map black. North is up (the grid's last row is the image's
 *        first), one pixel per cell.
 */
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "map_aided_fusion/core/prior_grid.hpp"

namespace map_aided_fusion {
namespace map_io {

/// RGB colour of a PriorClass in the PNG (indexed by the class value).
constexpr std::array<std::array<std::uint8_t, 3>, core::kNumPriorClasses> kPriorPngColours{ {
    { 0, 0, 0 },        // kUnknown: black
    { 0, 0, 255 },      // kBuilding: blue
    { 255, 255, 255 },  // kRoad: white
    { 128, 128, 128 },  // kOther: grey
} };

/// Writes @p grid to @p path. @throws std::runtime_error naming the file when GDAL cannot write it.
void writePriorPng(const core::PriorGrid& grid, const std::string& path);

}  // namespace map_io
}  // namespace map_aided_fusion
