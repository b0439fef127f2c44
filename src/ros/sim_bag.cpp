#include "map_aided_fusion/ros/sim_bag.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <ostream>

#include "map_aided_fusion/ros/bag_writing.hpp"
#include "map_aided_fusion/ros/conversions.hpp"

namespace map_aided_fusion {

namespace {

constexpr std::uint32_t kPointStep = 22;  // x y z intensity (float32), ring (uint16), time (float32, s after the stamp)
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

geometry_msgs::Quaternion yawQuaternion(double yaw)
{
  geometry_msgs::Quaternion q;
  q.w = std::cos(0.5 * yaw);
  q.z = std::sin(0.5 * yaw);
  return q;
}

}  // namespace

ros::Time SimConversions::stamp(const sim::Scenario& scenario, double t)
{
  ros::Time s;
  s.fromSec(scenario.start_stamp + t);
  return s;
}

void SimConversions::toPointCloud2(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                                   sensor_msgs::PointCloud2& msg)
{
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(frame.points.size());
  msg.fields = { pointField("x", 0, sensor_msgs::PointField::FLOAT32), pointField("y", 4, sensor_msgs::PointField::FLOAT32),
                 pointField("z", 8, sensor_msgs::PointField::FLOAT32),
                 pointField("intensity", 12, sensor_msgs::PointField::FLOAT32),
                 pointField("ring", 16, sensor_msgs::PointField::UINT16),
                 pointField("time", 18, sensor_msgs::PointField::FLOAT32) };
  msg.is_bigendian = false;
  msg.point_step = kPointStep;
  msg.row_step = kPointStep * msg.width;
  msg.is_dense = true;
  msg.data.resize(static_cast<std::size_t>(msg.row_step));
  std::uint8_t* out = msg.data.data();
  for (const sim::LidarPoint& p : frame.points)
  {
    std::memcpy(out + 0, &p.x, 4);
    std::memcpy(out + 4, &p.y, 4);
    std::memcpy(out + 8, &p.z, 4);
    std::memcpy(out + 12, &p.intensity, 4);
    std::memcpy(out + 16, &p.ring, 2);
    std::memcpy(out + 18, &p.time, 4);
    out += kPointStep;
  }
}

void SimConversions::toClassGrid(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                                 nav_msgs::OccupancyGrid& msg)
{
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  GridConversions::toMapMetaData(frame.truth_geometry, msg.info);
  msg.info.map_load_time = stamp;
  msg.data.assign(frame.truth_classes.begin(), frame.truth_classes.end());
}

void SimConversions::toObjectArray(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                                   GroundTruthObjectArray& msg)
{
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  msg.objects.clear();
  msg.objects.reserve(frame.objects.size());
  for (const sim::ObjectTruth& o : frame.objects)
  {
    GroundTruthObject m;
    m.id = o.id;
    m.cell_class = static_cast<std::int8_t>(o.cell_class);
    m.kind = o.kind;
    m.pose.position.x = o.x;
    m.pose.position.y = o.y;
    m.pose.position.z = o.z;
    m.pose.orientation = yawQuaternion(o.yaw);
    m.size.x = o.length;
    m.size.y = o.width;
    m.size.z = o.height;
    m.velocity.x = o.vx;
    m.velocity.y = o.vy;
    msg.objects.push_back(std::move(m));
  }
}

SimBagStats writeSimulationBag(sim::Simulator& simulator, const SimBagOptions& options)
{
  const auto wall_start = std::chrono::steady_clock::now();
  const sim::Scenario& sc = simulator.scenario();
  const SimBagNames& n = options.names;
  rosbag::Bag bag(options.path, rosbag::bagmode::Write);
  SimBagStats stats;

  // base_link -> lidar, latched.
  tf2_msgs::TFMessage statics;
  geometry_msgs::TransformStamped mount;
  mount.header.stamp = SimConversions::stamp(sc, 0.0);
  mount.header.frame_id = n.base_frame;
  mount.child_frame_id = n.lidar_frame;
  mount.transform.translation.x = sc.lidar.mount_x;
  mount.transform.translation.y = sc.lidar.mount_y;
  mount.transform.translation.z = sc.lidar.mount_z;
  mount.transform.rotation = yawQuaternion(sc.lidar.mount_yaw_deg * kDegToRad);
  statics.transforms.push_back(mount);
  bag.write(n.tf_static_topic, mount.header.stamp, statics, latchedConnectionHeader<tf2_msgs::TFMessage>("/simulate"));

  const int scans = simulator.numScans();
  const double tf_period = 1.0 / sc.tf_rate_hz;
  const long tf_count = static_cast<long>(std::floor(sc.duration * sc.tf_rate_hz + 1e-9)) + 1;
  long tf_index = 0;
  auto writeTfUntil = [&](double t_end) {
    for (; tf_index < tf_count && tf_index * tf_period <= t_end + 1e-9; ++tf_index)
    {
      const double t = tf_index * tf_period;
      const sim::Pose2 ego = simulator.reportedEgoPose(t);
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped ts;
      ts.header.stamp = SimConversions::stamp(sc, t);
      ts.header.frame_id = n.map_frame;
      ts.child_frame_id = n.base_frame;
      ts.transform.translation.x = ego.x;
      ts.transform.translation.y = ego.y;
      ts.transform.rotation = yawQuaternion(ego.yaw);
      tf.transforms.push_back(ts);
      bag.write(n.tf_topic, ts.header.stamp, tf);
      ++stats.tf_messages;
      const sim::LocalisationError& le = sc.localisation_error;
      const long every = std::max(1L, std::lround(sc.tf_rate_hz / le.covariance_rate_hz));
      if (!le.any() || tf_index % every != 0) continue;
      geometry_msgs::PoseWithCovarianceStamped pose;
      pose.header = ts.header;
      pose.pose.pose.position.x = ego.x;
      pose.pose.pose.position.y = ego.y;
      pose.pose.pose.orientation = ts.transform.rotation;
      const double var = le.reportedSigma() * le.reportedSigma();
      pose.pose.covariance[0] = pose.pose.covariance[7] = var;
      pose.pose.covariance[14] = pose.pose.covariance[21] = pose.pose.covariance[28] = pose.pose.covariance[35] = 1e-4;
      bag.write(n.pose_topic, ts.header.stamp, pose);
    }
  };

  sim::ScanFrame frame;
  sensor_msgs::PointCloud2 cloud;
  nav_msgs::OccupancyGrid classes;
  GroundTruthObjectArray objects;
  for (int k = 0; k < scans; ++k)
  {
    simulator.scan(k, frame);
    writeTfUntil(frame.time);
    const ros::Time stamp = SimConversions::stamp(sc, frame.time);
    SimConversions::toPointCloud2(frame, stamp, n.lidar_frame, cloud);
    SimConversions::toClassGrid(frame, stamp, n.map_frame, classes);
    SimConversions::toObjectArray(frame, stamp, n.map_frame, objects);
    bag.write(n.points_topic, stamp, cloud);
    bag.write(n.classes_topic, stamp, classes);
    bag.write(n.objects_topic, stamp, objects);
    ++stats.scans;
    stats.points += frame.points.size();
    if (options.progress)
    {
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      *options.progress << "\r[simulate] t " << std::fixed << std::setprecision(1) << frame.time << "/"
                        << sc.duration << " s  scan " << (k + 1) << "/" << scans << "  " << frame.points.size()
                        << " points  " << frame.objects.size() << " objects  wall " << wall << " s   "
                        << std::flush;
    }
  }
  writeTfUntil(sc.duration);
  bag.close();
  stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (options.progress) *options.progress << "\n";
  return stats;
}

}  // namespace map_aided_fusion
