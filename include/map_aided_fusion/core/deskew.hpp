/**
 * @file deskew.hpp
 * @brief Sweep deskewing (not in the paper): a spinning lidar takes each point at its own instant while the
 *        vehicle moves, so one sweep at 15 m/s smears a facade by 1.5 m. Each point is moved to where it would
 *        have been seen from the sensor's pose at the sweep's reference time (the cloud's stamp).
 *
 * The sensor's motion over the sweep is a constant twist: `motion.delta` is the sensor's pose at
 * `reference + motion.duration` expressed in the sensor frame at the reference time (duration may be negative:
 * the motion then comes from the past and is extrapolated). A point taken at offset τ is mapped by the
 * interpolated transform at α = τ / duration (rotation by α·angle about the axis, translation α·t), taken
 * from a table of kDeskewSteps transforms over the sweep (the table's step moves a point by at most
 * |t| / kDeskewSteps plus the same share of the rotation).
 *
 * Per-point time fields of the common ROS drivers are described by PointTimeField; offsets must lie in
 * [0, max_sweep_duration] (seconds after the reference time) or the whole cloud is left as it is and the
 * reason returned (counted by the caller). Switched by ScanGridParams::deskew. ROS-free.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "map_aided_fusion/core/scan_grid.hpp"

namespace map_aided_fusion {
namespace core {

/// Transforms in the interpolation table of a sweep (first = identity, last = motion.delta).
constexpr int kDeskewSteps = 1024;
/// Offsets down to this far below 0 (s) are rounding, taken as 0.
constexpr double kDeskewNegativeSlack = 1e-6;

/// How a per-point time is stored.
enum class TimeEncoding
{
  kFloat32,  ///< float32
  kFloat64,  ///< float64
  kUint32,   ///< uint32
};

/// Where and how a cloud stores each point's time. time(point) = scale · raw − (absolute ? reference : 0).
struct PointTimeField
{
  std::size_t offset = 0;         ///< byte offset in a point
  TimeEncoding encoding = TimeEncoding::kFloat32;
  double scale = 1.0;             ///< raw unit in seconds (1e-9 for nanoseconds)
  bool absolute = false;          ///< seconds since the epoch rather than since the reference time
  std::string name;               ///< field name, for messages
};

/// The sensor's motion over a sweep (see the file comment).
struct SweepMotion
{
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  double duration = 0.0;  ///< s, non-zero
};

/// Outcome of one deskew() call.
enum class DeskewOutcome
{
  kApplied,       ///< points moved (the output view is set)
  kNonFinite,     ///< a time is NaN or infinite
  kNegative,      ///< a time is before the reference time
  kOutOfSweep,    ///< a time is later than max_sweep_duration
  kBadMotion,     ///< motion not finite, or duration 0 with a non-identity delta
};

const char* toString(DeskewOutcome outcome);

/**
 * @brief Scans the time field of @p points: the largest offset (seconds after @p reference) in
 *        @p max_offset, and kApplied when every offset is valid, else the first reason found.
 * @p reference is used only for absolute fields (seconds since the epoch).
 */
DeskewOutcome sweepSpan(const PointCloudView& points, const PointTimeField& time, double reference,
                        double max_sweep_duration, double& max_offset);

/**
 * @brief Deskews @p points into @p out_xyz (packed x, y, z float32, 12 bytes per point, same order) and sets
 *        @p out_view to it. Exact (0, 0, 0) "no return" points are copied unchanged (non-finite ones stay non-finite).
 *        Nothing is written unless the result is kApplied.
 */
DeskewOutcome deskew(const PointCloudView& points, const PointTimeField& time, double reference,
                     const SweepMotion& motion, double max_sweep_duration, std::vector<float>& out_xyz,
                     PointCloudView& out_view);

/**
 * @brief deskew() without the checks: @p span is what sweepSpan() returned kApplied with for these points, and
 *        @p motion is finite with a non-zero duration. For callers that ran sweepSpan() already (one pass less).
 */
void deskewChecked(const PointCloudView& points, const PointTimeField& time, double reference,
                   const SweepMotion& motion, double span, std::vector<float>& out_xyz, PointCloudView& out_view);

/// Interpolated transform at fraction @p alpha of @p delta (α = 0: identity, α = 1: delta).
Eigen::Isometry3d interpolateMotion(const Eigen::Isometry3d& delta, double alpha);

}  // namespace core
}  // namespace map_aided_fusion
