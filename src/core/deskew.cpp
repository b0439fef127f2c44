#include "map_aided_fusion/core/deskew.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>


namespace map_aided_fusion {
namespace core {

namespace {

template <class T>
inline double readRaw(const std::uint8_t* p)
{
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

/// Calls f(raw reader) with the reader for @p encoding, so the per-point loop has no switch.
template <class F>
auto withReader(TimeEncoding encoding, F&& f)
{
  switch (encoding)
  {
    case TimeEncoding::kFloat64: return f(&readRaw<double>);
    case TimeEncoding::kUint32: return f(&readRaw<std::uint32_t>);
    case TimeEncoding::kFloat32: break;
  }
  return f(&readRaw<float>);
}

inline float readFloat(const std::uint8_t* p)
{
  float v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::size_t encodingSize(TimeEncoding e)
{
  return e == TimeEncoding::kFloat64 ? sizeof(double) : sizeof(float);
}

}  // namespace

const char* toString(DeskewOutcome outcome)
{
  switch (outcome)
  {
    case DeskewOutcome::kApplied: return "applied";
    case DeskewOutcome::kNonFinite: return "time_non_finite";
    case DeskewOutcome::kNegative: return "time_negative";
    case DeskewOutcome::kOutOfSweep: return "time_out_of_sweep";
    case DeskewOutcome::kBadMotion: return "bad_motion";
  }
  return "unknown";
}

Eigen::Isometry3d interpolateMotion(const Eigen::Isometry3d& delta, double alpha)
{
  const Eigen::AngleAxisd aa(delta.rotation());
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(alpha * aa.angle(), aa.axis()).toRotationMatrix();
  t.translation() = alpha * delta.translation();
  return t;
}

DeskewOutcome sweepSpan(const PointCloudView& points, const PointTimeField& time, double reference,
                        double max_sweep_duration, double& max_offset)
{
  max_offset = 0.0;
  if (points.size() == 0) return DeskewOutcome::kApplied;
  if (time.offset + encodingSize(time.encoding) > points.point_step) return DeskewOutcome::kNonFinite;
  const double scale = time.scale;
  const double base = time.absolute ? reference : 0.0;
  return withReader(time.encoding, [&](auto read) {
    double hi = 0.0;
    for (std::size_t row = 0; row < points.height; ++row)
    {
      const std::uint8_t* p = points.data + row * points.row_step + time.offset;
      for (std::size_t col = 0; col < points.width; ++col, p += points.point_step)
      {
        const double t = scale * read(p) - base;
        if (!std::isfinite(t)) return DeskewOutcome::kNonFinite;
        if (t < -kDeskewNegativeSlack) return DeskewOutcome::kNegative;
        if (t > max_sweep_duration) return DeskewOutcome::kOutOfSweep;
        hi = std::max(hi, t);
      }
    }
    max_offset = hi;
    return DeskewOutcome::kApplied;
  });
}

DeskewOutcome deskew(const PointCloudView& points, const PointTimeField& time, double reference,
                     const SweepMotion& motion, double max_sweep_duration, std::vector<float>& out_xyz,
                     PointCloudView& out_view)
{
  if (!motion.delta.matrix().allFinite() || !std::isfinite(motion.duration) || motion.duration == 0.0)
    return DeskewOutcome::kBadMotion;
  double span = 0.0;
  const DeskewOutcome checked = sweepSpan(points, time, reference, max_sweep_duration, span);
  if (checked != DeskewOutcome::kApplied) return checked;
  deskewChecked(points, time, reference, motion, span, out_xyz, out_view);
  return DeskewOutcome::kApplied;
}

void deskewChecked(const PointCloudView& points, const PointTimeField& time, double reference,
                   const SweepMotion& motion, double span, std::vector<float>& out_xyz, PointCloudView& out_view)
{
  // Table of interpolated transforms over [0, span] (offsets are within it).
  const double step = span / (kDeskewSteps - 1);
  std::vector<std::array<float, 12>> table(kDeskewSteps);
  for (int k = 0; k < kDeskewSteps; ++k)
  {
    const Eigen::Isometry3d t = interpolateMotion(motion.delta, k * step / motion.duration);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c) table[k][4 * r + c] = static_cast<float>(t.linear()(r, c));
      table[k][4 * r + 3] = static_cast<float>(t.translation()(r));
    }
  }
  const double to_step = step > 0.0 ? 1.0 / step : 0.0;

  const std::size_t n = points.size();
  out_xyz.resize(3 * n);
  float* out = out_xyz.data();
  const double scale = time.scale;
  const double base = time.absolute ? reference : 0.0;
  // Index of a point's transform: its offset in steps, rounded (offsets were checked to lie in [0, span]).
  const float index_scale = static_cast<float>(scale * to_step);
  const auto transformAll = [&](auto index_of) {
    for (std::size_t row = 0; row < points.height; ++row)
    {
      const std::uint8_t* p = points.data + row * points.row_step;
      for (std::size_t col = 0; col < points.width; ++col, p += points.point_step, out += 3)
      {
        const float x = readFloat(p + points.x_offset);
        const float y = readFloat(p + points.y_offset);
        const float z = readFloat(p + points.z_offset);
        // (0, 0, 0) "no return" stays (0, 0, 0) (selected without a branch: a third of a sweep can be such points);
        // non-finite coordinates stay non-finite through the transform (the ScanGrid rejects them).
        const float keep = (x == 0.0f && y == 0.0f && z == 0.0f) ? 0.0f : 1.0f;
        const int k = std::clamp(index_of(p + time.offset), 0, kDeskewSteps - 1);
        const float* m = table[static_cast<std::size_t>(k)].data();
        out[0] = keep * (m[0] * x + m[1] * y + m[2] * z + m[3]);
        out[1] = keep * (m[4] * x + m[5] * y + m[6] * z + m[7]);
        out[2] = keep * (m[8] * x + m[9] * y + m[10] * z + m[11]);
      }
    }
  };
  switch (time.encoding)
  {
    case TimeEncoding::kFloat32:
      transformAll([&](const std::uint8_t* q) { return static_cast<int>(readFloat(q) * index_scale + 0.5f); });
      break;
    case TimeEncoding::kUint32:
      transformAll([&](const std::uint8_t* q) {
        return static_cast<int>(static_cast<float>(readRaw<std::uint32_t>(q)) * index_scale + 0.5f);
      });
      break;
    case TimeEncoding::kFloat64:
      transformAll([&](const std::uint8_t* q) { return static_cast<int>((scale * readRaw<double>(q) - base) * to_step + 0.5); });
      break;
  }
  out_view = PointCloudView::packed(out_xyz.data(), n, 3 * sizeof(float));
}

}  // namespace core
}  // namespace map_aided_fusion
