#include "map_aided_fusion/ros/kitti_bag.hpp"

#include <cctype>
#include <cstdio>
#include <optional>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <cmath>
#include <map>
#include <set>

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include "map_aided_fusion/GroundTruthObjectArray.h"
#include <tf2_msgs/TFMessage.h>

#include "map_aided_fusion/ros/bag_writing.hpp"

namespace map_aided_fusion {

namespace {

constexpr std::uint32_t kPointStep = 16;         // x y z intensity, float32
constexpr std::uint32_t kLabelledPointStep = 17;  // x y z float32, label uint32, state uint8
constexpr std::uint32_t kLabelOffset = 12;
constexpr std::uint32_t kStateOffset = 16;
constexpr std::int8_t kValidCode = 100;
constexpr std::int8_t kMovingCode = 4;     // core::CellClass::kMoving
constexpr std::int8_t kParkedCode = 3;     // core::CellClass::kStopped
constexpr std::int8_t kAmbiguousCode = -1;  // core::CellClass::kUnknown: motion not judged

std::string lowerCase(std::string s)
{
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& t, const ros::Time& stamp,
                                            const std::string& parent, const std::string& child)
{
  geometry_msgs::TransformStamped m;
  m.header.stamp = stamp;
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = t.translation().x();
  m.transform.translation.y = t.translation().y();
  m.transform.translation.z = t.translation().z();
  const Eigen::Quaterniond q(t.rotation());
  m.transform.rotation.w = q.w();
  m.transform.rotation.x = q.x();
  m.transform.rotation.y = q.y();
  m.transform.rotation.z = q.z();
  return m;
}

void header(sensor_msgs::PointCloud2& msg, const ros::Time& stamp, const std::string& frame_id, std::size_t n,
            std::uint32_t step)
{
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(n);
  msg.is_bigendian = false;
  msg.is_dense = false;
  msg.point_step = step;
  msg.row_step = step * msg.width;
  msg.data.resize(static_cast<std::size_t>(msg.row_step));
}

}  // namespace

void KittiConversions::toPointCloud2(const std::vector<dataset::KittiPoint>& points, const ros::Time& stamp,
                                     const std::string& frame_id, sensor_msgs::PointCloud2& msg)
{
  header(msg, stamp, frame_id, points.size(), kPointStep);
  msg.fields = { pointField("x", 0, sensor_msgs::PointField::FLOAT32), pointField("y", 4, sensor_msgs::PointField::FLOAT32),
                 pointField("z", 8, sensor_msgs::PointField::FLOAT32),
                 pointField("intensity", 12, sensor_msgs::PointField::FLOAT32) };
  static_assert(sizeof(dataset::KittiPoint) == kPointStep, "KITTI points are 16 bytes");
  if (!points.empty()) std::memcpy(msg.data.data(), points.data(), msg.data.size());
}

void KittiConversions::toLabelledCloud(const std::vector<dataset::KittiPoint>& points,
                                       const std::vector<std::uint32_t>& labels, const ros::Time& stamp,
                                       const std::string& frame_id, sensor_msgs::PointCloud2& msg)
{
  if (labels.size() != points.size()) throw std::invalid_argument("toLabelledCloud: one label per point");
  header(msg, stamp, frame_id, points.size(), kLabelledPointStep);
  msg.fields = { pointField("x", 0, sensor_msgs::PointField::FLOAT32), pointField("y", 4, sensor_msgs::PointField::FLOAT32),
                 pointField("z", 8, sensor_msgs::PointField::FLOAT32),
                 pointField("label", kLabelOffset, sensor_msgs::PointField::UINT32),
                 pointField("state", kStateOffset, sensor_msgs::PointField::UINT8) };
  std::uint8_t* p = msg.data.data();
  for (std::size_t k = 0; k < points.size(); ++k, p += kLabelledPointStep)
  {
    std::memcpy(p, &points[k], 3 * sizeof(float));
    std::memcpy(p + kLabelOffset, &labels[k], sizeof(std::uint32_t));
    p[kStateOffset] = static_cast<std::uint8_t>(dataset::stateOf(labels[k]));
  }
}

std::vector<LabelledCloudPoint> KittiConversions::fromLabelledCloud(const sensor_msgs::PointCloud2& msg)
{
  auto offset = [&](const std::string& name, std::uint8_t type) -> std::uint32_t {
    for (const auto& f : msg.fields)
      if (f.name == name && f.datatype == type) return f.offset;
    throw std::runtime_error("labelled cloud without a " + name + " field of the expected type");
  };
  const std::uint32_t ox = offset("x", sensor_msgs::PointField::FLOAT32);
  const std::uint32_t oy = offset("y", sensor_msgs::PointField::FLOAT32);
  const std::uint32_t oz = offset("z", sensor_msgs::PointField::FLOAT32);
  const std::uint32_t ol = offset("label", sensor_msgs::PointField::UINT32);
  const std::uint32_t os = offset("state", sensor_msgs::PointField::UINT8);
  const std::size_t n = static_cast<std::size_t>(msg.width) * msg.height;
  if (msg.point_step < kLabelledPointStep || msg.data.size() < n * msg.point_step || msg.is_bigendian)
    throw std::runtime_error("labelled cloud: inconsistent size or big-endian data");
  std::vector<LabelledCloudPoint> out(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::uint8_t* p = msg.data.data() + k * msg.point_step;
    std::memcpy(&out[k].x, p + ox, sizeof(float));
    std::memcpy(&out[k].y, p + oy, sizeof(float));
    std::memcpy(&out[k].z, p + oz, sizeof(float));
    std::memcpy(&out[k].label, p + ol, sizeof(std::uint32_t));
    out[k].state = p[os];
  }
  return out;
}

GroundTruthObject KittiConversions::toGroundTruthObject(const dataset::TrackedBox& b)
{
  GroundTruthObject m;
  m.id = static_cast<std::uint32_t>(b.track_id);
  m.cell_class = b.motion == dataset::BoxMotion::kMoving   ? kMovingCode
                 : b.motion == dataset::BoxMotion::kParked ? kParkedCode
                                                           : kAmbiguousCode;
  m.kind = lowerCase(b.type);
  m.pose.position.x = b.centre.x();
  m.pose.position.y = b.centre.y();
  m.pose.position.z = b.centre.z();
  m.pose.orientation.w = std::cos(0.5 * b.yaw);
  m.pose.orientation.z = std::sin(0.5 * b.yaw);
  m.size.x = b.length;
  m.size.y = b.width;
  m.size.z = b.height;
  m.velocity.x = b.velocity.x();
  m.velocity.y = b.velocity.y();
  return m;
}

void KittiConversions::toValidGrid(const std::vector<std::int8_t>& mask, double resolution, int width, int height,
                                   double origin_x, double origin_y, const ros::Time& stamp,
                                   const std::string& frame_id, nav_msgs::OccupancyGrid& msg)
{
  if (mask.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw std::invalid_argument("toValidGrid: the mask does not hold width x height cells");
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  msg.info.map_load_time = stamp;
  msg.info.resolution = static_cast<float>(resolution);
  msg.info.width = static_cast<std::uint32_t>(width);
  msg.info.height = static_cast<std::uint32_t>(height);
  msg.info.origin.position.x = origin_x;
  msg.info.origin.position.y = origin_y;
  msg.info.origin.orientation.w = 1.0;
  msg.data.resize(mask.size());
  for (std::size_t i = 0; i < mask.size(); ++i) msg.data[i] = mask[i] ? kValidCode : 0;
}

Eigen::Isometry3d KittiConversions::toIsometry(const geometry_msgs::TransformStamped& t)
{
  Eigen::Isometry3d s = Eigen::Isometry3d::Identity();
  const auto& q = t.transform.rotation;
  s.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
  s.translation() = Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
  return s;
}

std::vector<eval::LabelledPoint> KittiConversions::toScoredPoints(const sensor_msgs::PointCloud2& msg,
                                                                  const Eigen::Isometry3d& map_sensor,
                                                                  const Eigen::Isometry3d& base_sensor,
                                                                  double obstacle_low, double obstacle_high)
{
  const auto points = fromLabelledCloud(msg);
  std::vector<eval::LabelledPoint> out;
  out.reserve(points.size());
  for (const LabelledCloudPoint& p : points)
  {
    const Eigen::Vector3d v(p.x, p.y, p.z);
    const Eigen::Vector3d m = map_sensor * v;
    const double z = (base_sensor * v).z();
    eval::LabelledPoint lp;
    lp.p = core::Point2{ m.x(), m.y() };
    lp.state = static_cast<eval::LabelState>(p.state);
    const std::uint16_t semantic = dataset::semanticClass(p.label);
    lp.ground = dataset::isGroundClass(semantic);
    lp.vegetation = semantic == dataset::kClassVegetation;
    lp.obstacle = z >= obstacle_low && z <= obstacle_high && !lp.ground;
    lp.instance = lp.state == eval::LabelState::kMoving ? p.label : 0;
    out.push_back(lp);
  }
  return out;
}

KittiBagStats writeKittiBag(const dataset::KittiSequence& sequence, const KittiBagOptions& o)
{
  if (!(o.start_stamp > 0.0)) throw std::invalid_argument("start_stamp must be > 0 (a zero stamp is rejected)");
  const std::string partial = o.path + ".partial";
  KittiBagStats stats;
  try
  {
    rosbag::Bag bag(partial, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::LZ4);
    Eigen::Isometry3d lift = Eigen::Isometry3d::Identity();
    lift.translation().z() = o.lidar_height;
    ros::Time first;
    first.fromSec(o.start_stamp + sequence.time(0));
    tf2_msgs::TFMessage statics;
    statics.transforms.push_back(toTransform(lift, first, o.base_frame, o.lidar_frame));
    bag.write("/tf_static", first, statics, latchedConnectionHeader<tf2_msgs::TFMessage>("/kitti_to_bag"));
    const Eigen::Isometry3d lift_inv = lift.inverse();
    std::optional<dataset::KittiTracking> tracking;
    if (dataset::KittiTracking::present(sequence.folder()))
      tracking.emplace(sequence, o.lidar_height, o.motion, o.strict_labels);
    std::map<int, std::set<dataset::BoxMotion>> track_motions;
    const int valid_cells = static_cast<int>(std::lround(o.valid_size / o.valid_resolution));
    for (std::size_t k = 0; k < sequence.size(); ++k)
    {
      ros::Time stamp;
      stamp.fromSec(o.start_stamp + sequence.time(k));
      const auto points = sequence.readScan(k);
      const auto labels = sequence.readLabels(k, points.size());
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(toTransform(lift * sequence.lidarPose(k) * lift_inv, stamp, o.map_frame, o.base_frame));
      bag.write("/tf", stamp, tf);
      sensor_msgs::PointCloud2 cloud;
      KittiConversions::toPointCloud2(points, stamp, o.lidar_frame, cloud);
      bag.write(o.points_topic, stamp, cloud);
      if (!labels.empty())
      {
        sensor_msgs::PointCloud2 truth;
        KittiConversions::toLabelledCloud(points, labels, stamp, o.lidar_frame, truth);
        bag.write(o.labels_topic, stamp, truth);
        ++stats.labelled_scans;
        for (std::uint32_t l : labels) stats.moving_points += dataset::stateOf(l) == dataset::PointState::kMoving;
      }
      if (tracking)
      {
        GroundTruthObjectArray objects;
        objects.header.stamp = stamp;
        objects.header.frame_id = o.map_frame;
        for (const dataset::TrackedBox& b : tracking->boxes(k))
        {
          objects.objects.push_back(KittiConversions::toGroundTruthObject(b));
          track_motions[b.track_id].insert(b.motion);
        }
        stats.object_boxes += objects.objects.size();
        bag.write(o.objects_topic, stamp, objects);
        const Eigen::Vector3d lidar = (lift * sequence.lidarPose(k)).translation();
        const double ox = std::floor((lidar.x() - 0.5 * o.valid_size) / o.valid_resolution) * o.valid_resolution;
        const double oy = std::floor((lidar.y() - 0.5 * o.valid_size) / o.valid_resolution) * o.valid_resolution;
        nav_msgs::OccupancyGrid valid;
        KittiConversions::toValidGrid(tracking->validMask(k, o.valid_resolution, valid_cells, valid_cells, ox, oy),
                                      o.valid_resolution, valid_cells, valid_cells, ox, oy, stamp, o.map_frame, valid);
        bag.write(o.valid_topic, stamp, valid);
      }
      ++stats.scans;
      stats.points += points.size();
      if (o.progress) o.progress(k + 1, sequence.size());
    }
    for (const auto& [id, motions] : track_motions)
    {
      stats.moving_tracks += motions.count(dataset::BoxMotion::kMoving) > 0;
      stats.parked_tracks += motions.count(dataset::BoxMotion::kParked) > 0 && !motions.count(dataset::BoxMotion::kMoving);
    }
    bag.close();
  }
  catch (...)
  {
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    throw;
  }
  std::filesystem::rename(partial, o.path);
  return stats;
}

}  // namespace map_aided_fusion
