#include "map_aided_fusion/ros/cloud_deskew.hpp"

#include <sensor_msgs/PointField.h>

#include "map_aided_fusion/ros/tf_helpers.hpp"

namespace map_aided_fusion {

namespace {

constexpr double kNanosecond = 1e-9;
/// A sweep shorter than this does not move the vehicle measurably: no deskewing needed.
constexpr double kMinSpan = 1e-6;

struct KnownField
{
  const char* name;
  std::uint8_t datatype;
  core::TimeEncoding encoding;
  double scale;
  bool absolute;
};

const KnownField kKnownFields[] = {
  { "time", sensor_msgs::PointField::FLOAT32, core::TimeEncoding::kFloat32, 1.0, false },
  { "t", sensor_msgs::PointField::UINT32, core::TimeEncoding::kUint32, kNanosecond, false },
  { "timestamp", sensor_msgs::PointField::FLOAT64, core::TimeEncoding::kFloat64, 1.0, true },
  { "offset_time", sensor_msgs::PointField::UINT32, core::TimeEncoding::kUint32, kNanosecond, false },
};

}  // namespace

const std::vector<std::string>& knownTimeFields()
{
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const KnownField& k : kKnownFields) n.emplace_back(k.name);
    return n;
  }();
  return names;
}

std::string findTimeField(const sensor_msgs::PointCloud2& cloud, const std::string& name, core::PointTimeField& field,
                          std::string* detail)
{
  for (const KnownField& k : kKnownFields)
  {
    if (name != "auto" && name != k.name) continue;
    for (const sensor_msgs::PointField& f : cloud.fields)
    {
      if (f.name != k.name) continue;
      if (f.datatype != k.datatype || f.count != 1)
      {
        if (detail)
          *detail = "field '" + f.name + "' has datatype " + std::to_string(f.datatype) + " and count " +
                    std::to_string(f.count) + ", expected " + std::to_string(k.datatype) + " and 1";
        return "time_field_type";
      }
      field.offset = f.offset;
      field.encoding = k.encoding;
      field.scale = k.scale;
      field.absolute = k.absolute;
      field.name = k.name;
      return "";
    }
  }
  if (detail) *detail = "no time field (" + name + ")";
  return "no_time_field";
}

bool sweepMotionFromTf(const tf2::BufferCore& tf, const std::string& fixed_frame, const std::string& sensor_frame,
                       const ros::Time& stamp, double span, core::SweepMotion& motion, std::string* detail)
{
  const std::string sensor = tfFrame(sensor_frame);
  const ros::Duration sweep(span);
  const auto pose = [&](const ros::Time& t) { return toEigen(tf.lookupTransform(fixed_frame, sensor, t).transform); };
  try
  {
    ros::Time at = stamp;
    std::string why;
    if (!tf.canTransform(fixed_frame, sensor, stamp, &why))
    {
      // The stamp is not in the buffer yet: the velocity of the latest sweep-long interval.
      at = tf.lookupTransform(fixed_frame, sensor, ros::Time(0)).header.stamp;
      if (at.toSec() < sweep.toSec()) throw tf2::ExtrapolationException("no tf at " + std::to_string(stamp.toSec()) + ": " + why);
    }
    const Eigen::Isometry3d at_stamp = pose(at);
    if (at == stamp && tf.canTransform(fixed_frame, sensor, stamp + sweep, &why))
    {
      motion.delta = at_stamp.inverse() * pose(stamp + sweep);
      motion.duration = span;
      return true;
    }
    motion.delta = at_stamp.inverse() * pose(at - sweep);
    motion.duration = -span;
    return true;
  }
  catch (const tf2::TransformException& e)
  {
    if (detail) *detail = e.what();
    return false;
  }
}

DeskewResult CloudDeskewer::apply(const sensor_msgs::PointCloud2& cloud, const core::PointCloudView& view,
                                  bool enabled, const std::string& time_field, double max_sweep_duration,
                                  const tf2::BufferCore& tf, const std::string& fixed_frame, core::PointCloudView& out)
{
  DeskewResult r;
  out = view;
  if (!enabled)
  {
    r.status = "off";
    return r;
  }
  core::PointTimeField field;
  const std::string missing = findTimeField(cloud, time_field, field, &r.detail);
  if (!missing.empty())
  {
    r.status = missing;
    return r;
  }
  const double stamp = cloud.header.stamp.toSec();
  const core::DeskewOutcome span_ok = core::sweepSpan(view, field, stamp, max_sweep_duration, r.span);
  if (span_ok != core::DeskewOutcome::kApplied)
  {
    r.status = core::toString(span_ok);
    r.detail = "field '" + field.name + "' of a cloud stamped " + std::to_string(stamp);
    return r;
  }
  if (r.span < kMinSpan)
  {
    // Every point at the stamp: a driver that declares the field but does not fill it, not a deskewed sweep.
    r.status = "time_field_constant";
    r.detail = "every point of a cloud stamped " + std::to_string(stamp) + " has the same time in field '" +
               field.name + "': nothing to deskew with";
    return r;
  }
  core::SweepMotion motion;
  if (!sweepMotionFromTf(tf, fixed_frame, cloud.header.frame_id, cloud.header.stamp, r.span, motion, &r.detail))
  {
    r.status = "no_motion";
    return r;
  }
  if (!motion.delta.matrix().allFinite())
  {
    r.status = core::toString(core::DeskewOutcome::kBadMotion);
    r.detail = "tf gave a non-finite motion for frame '" + cloud.header.frame_id + "'";
    return r;
  }
  core::deskewChecked(view, field, stamp, motion, r.span, buffer_, out);
  r.status = core::toString(core::DeskewOutcome::kApplied);
  r.applied = true;
  return r;
}

}  // namespace map_aided_fusion
