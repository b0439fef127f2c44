/**
 * @file frame.hpp
 * @brief Frames of discernment of the paper and their subsets as bit masks.
 *
 * A subset of a frame with N elements is a bit mask in [0, 2^N): bit i set means
 * element i belongs to the subset. Mask 0 is the empty set, mask 2^N-1 is Ω.
 */
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace map_aided_fusion {
namespace core {

/// A subset of a frame of discernment, as a bit mask (bit i = element i).
using Subset = std::uint8_t;

/**
 * @brief Ω_MG = {F, C, N, S, V}: the frame of the MapGrid and of the PriorGrid.
 *
 * F: free space; C: mapped infrastructure (buildings); N: non-mapped infrastructure;
 * S: temporarily stopped objects; V: moving objects.
 */
struct FrameMG
{
  static constexpr int kSize = 5;                     ///< number of elements
  static constexpr int kNumSubsets = 1 << kSize;      ///< 32 subsets, ∅ included
  static constexpr Subset kEmpty = 0;                 ///< ∅
  static constexpr Subset kF = 1u << 0;               ///< free space
  static constexpr Subset kC = 1u << 1;               ///< mapped building
  static constexpr Subset kN = 1u << 2;               ///< non-mapped infrastructure
  static constexpr Subset kS = 1u << 3;               ///< stopped object
  static constexpr Subset kV = 1u << 4;               ///< moving object
  static constexpr Subset kOmega = kNumSubsets - 1;   ///< Ω
  static constexpr Subset kO = kC | kN | kS | kV;     ///< occupied, r_SG({O})
  static constexpr Subset kBuilding = kC;             ///< B of the PriorGrid
  static constexpr Subset kRoad = kF | kS | kV;       ///< R of the PriorGrid
  static constexpr Subset kOther = kF | kN | kS | kV; ///< T of the PriorGrid
  static constexpr Subset kWall = kF | kC;            ///< W of the PriorGrid: a cell a building outline crosses
  static constexpr Subset kStatic = kC | kN;          ///< θ_static of the coarsening Θ
  static constexpr Subset kDynamic = kS | kV;         ///< θ_dynamic of the coarsening Θ
  static constexpr Subset kFreeContext = kF;          ///< θ_free of the coarsening Θ
  /// Element names, in bit order.
  static constexpr std::array<std::string_view, kSize> kNames{ "F", "C", "N", "S", "V" };
};

/// Ω_SG = {F, O}: the frame of the ScanGrid.
struct FrameSG
{
  static constexpr int kSize = 2;
  static constexpr int kNumSubsets = 1 << kSize;
  static constexpr Subset kEmpty = 0;
  static constexpr Subset kF = 1u << 0;  ///< free
  static constexpr Subset kO = 1u << 1;  ///< occupied
  static constexpr Subset kOmega = kNumSubsets - 1;
  static constexpr std::array<std::string_view, kSize> kNames{ "F", "O" };
};

/// True when @p a ⊆ @p b.
constexpr bool isSubsetOf(Subset a, Subset b) { return (a & ~b) == 0; }

/// Number of elements of a subset.
constexpr int cardinality(Subset a)
{
  int n = 0;
  for (; a != 0; a = static_cast<Subset>(a & (a - 1))) ++n;
  return n;
}

/**
 * @brief Readable name of a subset: the element names in frame order ("F", "SV"),
 *        "Ω" for the whole frame and "∅" for the empty set.
 */
template <class Frame>
std::string subsetName(Subset a)
{
  if (a == 0) return "∅";
  if (a == Frame::kOmega) return "Ω";
  std::string s;
  for (int i = 0; i < Frame::kSize; ++i)
    if (a & (1u << i)) s += Frame::kNames[i];
  return s;
}

/**
 * @brief Parses a name written by subsetName() ("FSV", "Ω", "∅"; also "Omega" and "{}").
 * @throws std::invalid_argument naming the unknown element.
 */
template <class Frame>
Subset parseSubset(std::string_view name)
{
  if (name == "∅" || name == "{}") return 0;
  if (name == "Ω" || name == "Omega") return Frame::kOmega;
  Subset a = 0;
  for (std::size_t pos = 0; pos < name.size();)
  {
    bool found = false;
    for (int i = 0; i < Frame::kSize && !found; ++i)
    {
      const auto& n = Frame::kNames[i];
      if (name.substr(pos, n.size()) == n)
      {
        a = static_cast<Subset>(a | (1u << i));
        pos += n.size();
        found = true;
      }
    }
    if (!found)
      throw std::invalid_argument("parseSubset: unknown element in \"" + std::string(name) + "\" at position " +
                                  std::to_string(pos));
  }
  return a;
}

}  // namespace core
}  // namespace map_aided_fusion
