// KITTI tracking labels: a synthetic sequence with a known answer (boxes in the map frame, velocities by least
// squares, motion states, the valid-label mask), every malformed-label fault (file and line), the bag's objects.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include <nav_msgs/OccupancyGrid.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "kitti_folder.hpp"
#include "map_aided_fusion/GroundTruthObjectArray.h"
#include "map_aided_fusion/dataset/kitti_tracking.hpp"
#include "map_aided_fusion/ros/kitti_bag.hpp"

using namespace map_aided_fusion;
using dataset::BoxMotion;
using dataset::KittiError;
using dataset::KittiSequence;
using dataset::KittiTracking;
using maf_test::Folder;

namespace {

constexpr int kFrames = 11;
constexpr double kLidarHeight = 1.73;
constexpr double kEgoStep = 0.5;  // m per frame along the camera's z (the lidar's x): 5 m/s
// velodyne x → camera z, y → −x, z → −y; P2 of a 721 px focal length camera centred on (621, 187).
const std::string kCalib = "P2: 721 0 621 0 0 721 187 0 0 0 1 0\nTr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";

std::string label(int frame, int track, const std::string& type, double x, double z, double ry,
                  double h = 1.5, double w = 1.8, double l = 4.0)
{
  std::ostringstream s;
  s.precision(17);
  // Bottom centre on the ground under the lidar: camera y = +lidar height.
  s << frame << " " << track << " " << type << " 0 0 0 100 100 200 200 " << h << " " << w << " " << l << " " << x
    << " " << kLidarHeight << " " << z << " " << ry << "\n";
  return s.str();
}

/// The ego drives 0.5 m per frame; a parked car stays at map (20, 3), a van drives at 10 m/s along map x from
/// (20, −3), a pedestrian walks at 0.3 m/s from (30, 0), a cyclist is labelled in frame 5 only; frame 1 has a
/// DontCare region over the image's middle; a car moves at 10 m/s in frames 6–8 only (0.2 s: too short to be
/// judged moving).
void writeTracking(const Folder& f, const std::string& extra_labels = "")
{
  f.text("calib.txt", kCalib);
  std::string times, poses, labels;
  for (int k = 0; k < kFrames; ++k)
  {
    times += std::to_string(0.1 * k) + "\n";
    poses += "1 0 0 0 0 1 0 0 0 0 1 " + std::to_string(kEgoStep * k) + "\n";
    f.scan(k, { { 10, 0, 0, 0.1f } });
    const double ego = kEgoStep * k;
    labels += label(k, 0, "Car", -3.0, 20.0 - ego, -M_PI / 2);
    labels += label(k, 1, "Van", 3.0, 20.0 + 1.0 * k - ego, -M_PI / 2);
    labels += label(k, 2, "Pedestrian", 0.0, 30.0 + 0.03 * k - ego, 0.0, 1.7, 0.6, 0.8);
    if (k == 5) labels += label(k, 3, "Cyclist", 1.0, 12.0, -M_PI / 2, 1.7, 0.6, 1.8);
    if (k >= 6 && k <= 8) labels += label(k, 4, "Car", 6.0, 40.0 + 1.0 * (k - 6) - ego, -M_PI / 2);
    if (k == 1) labels += "1 -1 DontCare -1 -1 -10 500 0 700 375 -1 -1 -1 -1000 -1000 -1000 -10\n";
  }
  f.text("times.txt", times);
  f.text("poses.txt", poses);
  f.text("label_02.txt", labels + extra_labels);
}

const dataset::TrackedBox& find(const std::vector<dataset::TrackedBox>& boxes, int id)
{
  for (const auto& b : boxes)
    if (b.track_id == id) return b;
  throw std::runtime_error("no box of track " + std::to_string(id));
}

std::string trackingError(const Folder& f)
{
  try
  {
    const KittiSequence s(f.dir.string());
    KittiTracking t(s, kLidarHeight);
  }
  catch (const KittiError& e)
  {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(KittiTracking, BoxesInTheMapFrameWithLeastSquaresVelocityAndMotion)
{
  Folder f("tracking");
  writeTracking(f);
  ASSERT_TRUE(KittiTracking::present(f.dir.string()));
  const KittiSequence seq(f.dir.string());
  const KittiTracking t(seq, kLidarHeight);
  EXPECT_EQ(t.labels().size(), 3u * kFrames + 5u);
  for (int k = 0; k < kFrames; ++k)
  {
    const auto boxes = t.boxes(static_cast<std::size_t>(k));
    ASSERT_EQ(boxes.size(), k == 5 || (k >= 6 && k <= 8) ? 4u : 3u) << "frame " << k;
    const auto& car = find(boxes, 0);
    EXPECT_NEAR(car.centre.x(), 20.0, 1e-9);
    EXPECT_NEAR(car.centre.y(), 3.0, 1e-9);
    EXPECT_NEAR(car.centre.z(), 0.75, 1e-9);  // half its 1.5 m above the ground
    EXPECT_NEAR(car.yaw, 0.0, 1e-9);          // rotation_y = −π/2 heads along the camera's z, the map's x
    EXPECT_NEAR(car.velocity.norm(), 0.0, 1e-9);
    EXPECT_EQ(car.motion, BoxMotion::kParked);
    const auto& van = find(boxes, 1);
    EXPECT_NEAR(van.centre.x(), 20.0 + 1.0 * k, 1e-9);
    EXPECT_NEAR(van.velocity.x(), 10.0, 1e-9);
    EXPECT_NEAR(van.velocity.y(), 0.0, 1e-9);
    EXPECT_EQ(van.motion, BoxMotion::kMoving);
    EXPECT_DOUBLE_EQ(van.length, 4.0);
    const auto& ped = find(boxes, 2);
    EXPECT_NEAR(ped.velocity.x(), 0.3, 1e-9);
    EXPECT_EQ(ped.motion, BoxMotion::kAmbiguous);  // between 0.25 and 0.5 m/s
    EXPECT_NEAR(std::abs(ped.yaw), M_PI / 2, 1e-9);  // rotation_y = 0 heads along the camera's x, the map's −y
  }
  const auto& cyclist = find(t.boxes(5), 3);
  EXPECT_FALSE(cyclist.velocity_known);  // one box in ±0.5 s
  EXPECT_EQ(cyclist.motion, BoxMotion::kAmbiguous);
  for (int k = 6; k <= 8; ++k)
  {
    const auto& brief = find(t.boxes(static_cast<std::size_t>(k)), 4);
    EXPECT_NEAR(brief.velocity.x(), 10.0, 1e-9);
    EXPECT_EQ(brief.motion, BoxMotion::kAmbiguous) << "a 0.2 s moving spell is not judged";
  }
}

TEST(KittiTracking, ValidMaskIsTheCameraViewMinusDontCare)
{
  Folder f("tracking_mask");
  writeTracking(f);
  const KittiSequence seq(f.dir.string());
  const KittiTracking t(seq, kLidarHeight);
  // 0.5 m cells over [-10, 10) x [-10, 10) around the map origin.
  auto at = [](const std::vector<std::int8_t>& m, double x, double y) {
    return m[static_cast<std::size_t>(std::floor((y + 10.0) / 0.5)) * 40 + static_cast<std::size_t>(std::floor((x + 10.0) / 0.5))];
  };
  const auto m0 = t.validMask(0, 0.5, 40, 40, -10.0, -10.0);
  EXPECT_EQ(at(m0, 8.1, 0.1), 1);   // ahead
  EXPECT_EQ(at(m0, -8.1, 0.1), 0);  // behind
  EXPECT_EQ(at(m0, 2.1, 9.1), 0);   // far to the left: u < 0
  EXPECT_EQ(at(m0, 8.1, 4.1), 1);   // within the ±40° view
  const auto m1 = t.validMask(1, 0.5, 40, 40, -10.0, -10.0);
  EXPECT_EQ(at(m1, 8.1, 0.1), 0);   // in frame 1's DontCare region (u 500…700)
  EXPECT_EQ(at(m1, 8.1, 4.1), 1);   // u ≈ 267: outside it
}

TEST(KittiTracking, MalformedLabelsNameTheFileAndLine)
{
  Folder f("tracking_faults");
  writeTracking(f, "3 9 Car 0 0\n");
  std::string e = trackingError(f);
  EXPECT_NE(e.find("label_02.txt:" + std::to_string(3 * kFrames + 6) + ": 5 fields"), std::string::npos) << e;

  writeTracking(f, label(kFrames + 4, 9, "Car", 0, 10, 0));
  e = trackingError(f);
  EXPECT_NE(e.find("frame 15 is beyond the sequence's 11 sweeps"), std::string::npos) << e;
  {
    const KittiSequence seq(f.dir.string());
    const KittiTracking lenient(seq, kLidarHeight, {}, false);  // a sequence cut short skips it
    EXPECT_EQ(lenient.labels().size(), 3u * kFrames + 5u);
  }

  writeTracking(f, "4 9 Car 0 0 0 1 2 3 4 1.5 x 4 0 1.7 10 0\n");
  e = trackingError(f);
  EXPECT_NE(e.find(":" + std::to_string(3 * kFrames + 6) + ": field 12 'x' is not a finite number"), std::string::npos)
      << e;

  writeTracking(f, "4 9 Car 0 0 0 1 2 3 4 1.5 0 4 0 1.7 10 0\n");
  e = trackingError(f);
  EXPECT_NE(e.find("height, width and length > 0"), std::string::npos) << e;

  writeTracking(f);
  f.text("calib.txt", "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n");
  e = trackingError(f);
  EXPECT_NE(e.find("calib.txt: no 'P2:' line"), std::string::npos) << e;
  f.text("calib.txt", "P2: 1 2 3\nTr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n");
  e = trackingError(f);
  EXPECT_NE(e.find("calib.txt:1: the P2 line needs 12 finite numbers"), std::string::npos) << e;
}

TEST(KittiTracking, BagCarriesObjectsAndTheValidMask)
{
  Folder f("tracking_bag");
  writeTracking(f);
  const KittiSequence seq(f.dir.string());
  KittiBagOptions o;
  o.path = (f.dir / "out.bag").string();
  const KittiBagStats stats = writeKittiBag(seq, o);
  EXPECT_EQ(stats.scans, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(stats.object_boxes, 3u * kFrames + 4u);
  EXPECT_EQ(stats.moving_tracks, 1u);  // the van
  EXPECT_EQ(stats.parked_tracks, 1u);  // the car

  rosbag::Bag bag(o.path, rosbag::bagmode::Read);
  int arrays = 0, masks = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag))
  {
    if (auto a = m.instantiate<GroundTruthObjectArray>())
    {
      const int k = arrays++;
      EXPECT_EQ(a->header.frame_id, "map");
      for (const auto& obj : a->objects)
      {
        if (obj.id != 1) continue;
        EXPECT_EQ(obj.kind, "van");
        EXPECT_EQ(obj.cell_class, GroundTruthObject::MOVING);
        EXPECT_NEAR(obj.pose.position.x, 20.0 + k, 1e-9);
        EXPECT_NEAR(obj.velocity.x, 10.0, 1e-9);
        EXPECT_DOUBLE_EQ(obj.size.x, 4.0);
        EXPECT_DOUBLE_EQ(obj.size.z, 1.5);
      }
      for (const auto& obj : a->objects)
      {
        if (obj.id == 2)
        {
          EXPECT_EQ(obj.cell_class, GroundTruthObject::MOTION_NOT_JUDGED);
        }
      }
    }
    else if (auto g = m.instantiate<nav_msgs::OccupancyGrid>())
    {
      const int k = masks++;
      EXPECT_EQ(m.getTopic(), "/ground_truth/valid");
      EXPECT_EQ(g->info.width, 480u);
      const double x = 8.0 + kEgoStep * k, y = 0.1;  // 8 m ahead of the lidar
      const auto cx = static_cast<std::size_t>((x - g->info.origin.position.x) / g->info.resolution);
      const auto cy = static_cast<std::size_t>((y - g->info.origin.position.y) / g->info.resolution);
      EXPECT_EQ(g->data[cy * g->info.width + cx], k == 1 ? 0 : 100) << "mask " << k;  // frame 1: DontCare
    }
  }
  EXPECT_EQ(arrays, kFrames);
  EXPECT_EQ(masks, kFrames);
}
