// KITTI / SemanticKITTI reader and kitti_to_bag: a tiny synthetic sequence written by the test (known answer),
// every malformed-folder fault (a message naming the file and line, no bag left looking complete), and the real
// frames of ../shared/data when present.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include "kitti_folder.hpp"
#include "map_aided_fusion/ros/kitti_bag.hpp"

namespace fs = std::filesystem;
using namespace map_aided_fusion;
using dataset::KittiError;
using dataset::KittiSequence;
using maf_test::Folder;

namespace {

constexpr const char* kTr = "Tr: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 -0.3\n";  // velodyne x → camera z, y → −x, z → −y

/// Three frames of 4 points; camera 0 moves 1 m along its z axis (the lidar's x) per frame; frames 0 and 1 labelled.
void writeSequence(const Folder& f)
{
  f.text("calib.txt", std::string("P0: 1 0 0 0 0 1 0 0 0 0 1 0\n") + kTr);
  f.text("times.txt", "0.0\n0.1\n0.2\n");
  f.text("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n1 0 0 0 0 1 0 0 0 0 1 2\n");
  const std::vector<dataset::KittiPoint> pts{ { 5, 0, -1.7f, 0.1f }, { 6, 1, 0, 0.2f }, { 7, -1, 0.5f, 0.3f },
                                              { 8, 2, 1, 0.4f } };
  for (int k = 0; k < 3; ++k) f.scan(k, pts);
  const std::vector<std::uint32_t> labels{ 40, 10 | (3u << 16), 252 | (7u << 16), 0 };
  f.labels(0, labels);
  f.labels(1, labels);
}

std::string errorOf(const std::string& folder)
{
  try
  {
    KittiSequence s(folder);
    for (std::size_t k = 0; k < s.size(); ++k) s.readLabels(k, s.readScan(k).size());
  }
  catch (const KittiError& e)
  {
    return e.what();
  }
  return "";
}

std::string convertError(const Folder& f, const std::string& bag)
{
  try
  {
    KittiBagOptions o;
    o.path = bag;
    writeKittiBag(KittiSequence(f.dir.string()), o);
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Kitti, LabelStatesAndGroundClasses)
{
  EXPECT_EQ(dataset::stateOf(0), dataset::PointState::kUnlabelled);
  EXPECT_EQ(dataset::stateOf(1), dataset::PointState::kUnlabelled);
  EXPECT_EQ(dataset::stateOf(10 | (5u << 16)), dataset::PointState::kStatic);
  for (std::uint32_t c = 252; c <= 259; ++c) EXPECT_EQ(dataset::stateOf(c), dataset::PointState::kMoving) << c;
  EXPECT_EQ(dataset::stateOf(260), dataset::PointState::kStatic);
  EXPECT_EQ(dataset::instanceId(255 | (9u << 16)), 9);
  EXPECT_TRUE(dataset::isGroundClass(40));
  EXPECT_TRUE(dataset::isGroundClass(72));
  EXPECT_FALSE(dataset::isGroundClass(50));
}

TEST(Kitti, LidarPosesAreTrInverseTimesCameraPoseTimesTr)
{
  Folder f("poses");
  writeSequence(f);
  const KittiSequence s(f.dir.string());
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s.labelledFrames(), 2u);
  EXPECT_FALSE(s.hasLabels(2));
  // Camera 0 moving 1 m along its z is the lidar moving 1 m along its x (Tr maps lidar x to camera z).
  for (std::size_t k = 0; k < 3; ++k)
  {
    const Eigen::Isometry3d& p = s.lidarPose(k);
    EXPECT_NEAR(p.translation().x(), static_cast<double>(k), 1e-12);
    EXPECT_NEAR(p.translation().y(), 0.0, 1e-12);
    EXPECT_NEAR(p.translation().z(), 0.0, 1e-12);
    EXPECT_TRUE(p.rotation().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  }
  EXPECT_DOUBLE_EQ(s.time(2), 0.2);
}

TEST(Kitti, AnotherPoseFileReplacesTheFoldersPoses)
{
  Folder f("other_poses");
  writeSequence(f);
  // Camera 0 moving 2 m along its z per frame: the lidar 2 m along its x.
  f.text("poses_other.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 2\n1 0 0 0 0 1 0 0 0 0 1 4\n");
  const KittiSequence s(f.dir.string(), 0, (f.dir / "poses_other.txt").string());
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(s.lidarPose(k).translation().x(), 2.0 * k, 1e-12);
  f.text("poses_short.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  try
  {
    KittiSequence short_poses(f.dir.string(), 0, (f.dir / "poses_short.txt").string());
    FAIL() << "no error";
  }
  catch (const KittiError& e)
  {
    EXPECT_NE(std::string(e.what()).find("poses_short.txt"), std::string::npos) << e.what();
  }
}

TEST(Kitti, ConvertsToABagWithPointsTfAndLabelledPoints)
{
  Folder f("bag");
  writeSequence(f);
  const std::string bag_path = (f.dir / "out.bag").string();
  KittiBagOptions o;
  o.path = bag_path;
  o.start_stamp = 1000.0;
  const KittiBagStats st = writeKittiBag(KittiSequence(f.dir.string()), o);
  EXPECT_EQ(st.scans, 3u);
  EXPECT_EQ(st.labelled_scans, 2u);
  EXPECT_EQ(st.points, 12u);
  EXPECT_EQ(st.moving_points, 2u);
  EXPECT_FALSE(fs::exists(bag_path + ".partial"));

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::size_t clouds = 0, labelled = 0, tf = 0, tf_static = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag))
  {
    if (m.getTopic() == "/points")
    {
      auto c = m.instantiate<sensor_msgs::PointCloud2>();
      ASSERT_TRUE(c);
      EXPECT_EQ(c->header.frame_id, "velodyne");
      EXPECT_EQ(c->width, 4u);
      EXPECT_NEAR(c->header.stamp.toSec(), 1000.0 + 0.1 * clouds, 1e-6);
      ++clouds;
    }
    else if (m.getTopic() == "/ground_truth/points")
    {
      auto c = m.instantiate<sensor_msgs::PointCloud2>();
      ASSERT_TRUE(c);
      const auto pts = KittiConversions::fromLabelledCloud(*c);
      ASSERT_EQ(pts.size(), 4u);
      EXPECT_EQ(pts[0].state, 1);  // road: static
      EXPECT_EQ(pts[2].state, 2);  // moving-car
      EXPECT_EQ(pts[2].label, 252u | (7u << 16));
      EXPECT_EQ(pts[3].state, 0);  // unlabeled
      EXPECT_FLOAT_EQ(pts[3].x, 8.0f);
      ++labelled;
    }
    else if (m.getTopic() == "/tf")
    {
      auto t = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_TRUE(t);
      ASSERT_EQ(t->transforms.size(), 1u);
      EXPECT_EQ(t->transforms[0].header.frame_id, "map");
      EXPECT_EQ(t->transforms[0].child_frame_id, "base_link");
      EXPECT_NEAR(t->transforms[0].transform.translation.x, static_cast<double>(tf), 1e-9);
      EXPECT_NEAR(t->transforms[0].transform.translation.z, 0.0, 1e-9);
      ++tf;
    }
    else if (m.getTopic() == "/tf_static")
    {
      auto t = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_TRUE(t);
      EXPECT_EQ(t->transforms[0].child_frame_id, "velodyne");
      EXPECT_DOUBLE_EQ(t->transforms[0].transform.translation.z, o.lidar_height);
      ++tf_static;
    }
  }
  EXPECT_EQ(clouds, 3u);
  EXPECT_EQ(labelled, 2u);
  EXPECT_EQ(tf, 3u);
  EXPECT_EQ(tf_static, 1u);
}

TEST(Kitti, FaultsNameTheFileAndLineAndLeaveNoBag)
{
  {
    Folder f("gap");
    writeSequence(f);
    fs::remove(f.dir / "velodyne/000001.bin");
    const std::string e = errorOf(f.dir.string());
    EXPECT_NE(e.find("velodyne/000001.bin"), std::string::npos) << e;
    EXPECT_NE(e.find("missing"), std::string::npos) << e;
  }
  {
    // times.txt with one line for three sweeps: an error naming it, also when fewer frames than there are are asked
    // for (the converter's --frames), never a one-scan bag.
    Folder f("short_times");
    writeSequence(f);
    f.text("times.txt", "0.0\n");
    for (const std::size_t frames : { std::size_t{ 0 }, std::size_t{ 2 }, std::size_t{ 10 } })
    {
      std::string e;
      try
      {
        KittiSequence s(f.dir.string(), frames);
      }
      catch (const KittiError& x)
      {
        e = x.what();
      }
      EXPECT_NE(e.find("times.txt is short"), std::string::npos) << "frames " << frames << ": " << e;
    }
  }
  {
    Folder f("short_poses");
    writeSequence(f);
    f.text("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n");
    const std::string e = errorOf(f.dir.string());
    EXPECT_NE(e.find("poses.txt:3"), std::string::npos) << e;
    EXPECT_NE(e.find("2 poses for 3 scans"), std::string::npos) << e;
  }
  {
    Folder f("bad_pose");
    writeSequence(f);
    f.text("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 x 0 0 0 1 1\n1 0 0 0 0 1 0 0 0 0 1 2\n");
    EXPECT_NE(errorOf(f.dir.string()).find("poses.txt:2"), std::string::npos);
  }
  {
    Folder f("labels");
    writeSequence(f);
    f.labels(1, { 40, 40, 40 });
    const std::string e = errorOf(f.dir.string());
    EXPECT_NE(e.find("labels/000001.label"), std::string::npos) << e;
    EXPECT_NE(e.find("3 labels"), std::string::npos) << e;
    // The converter stops at that frame and leaves neither the bag nor a partial file.
    const std::string bag = (f.dir / "out.bag").string();
    const std::string ce = convertError(f, bag);
    EXPECT_NE(ce.find("labels/000001.label"), std::string::npos) << ce;
    EXPECT_FALSE(fs::exists(bag));
    EXPECT_FALSE(fs::exists(bag + ".partial"));
  }
  {
    Folder f("calib");
    writeSequence(f);
    f.text("calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n");
    const std::string e = errorOf(f.dir.string());
    EXPECT_NE(e.find("calib.txt"), std::string::npos) << e;
    EXPECT_NE(e.find("Tr"), std::string::npos) << e;
  }
  {
    Folder f("calib_line");
    writeSequence(f);
    f.text("calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 1 2 3\n");
    EXPECT_NE(errorOf(f.dir.string()).find("calib.txt:2"), std::string::npos);
  }
  {
    Folder f("times");
    writeSequence(f);
    f.text("times.txt", "0.0\n0.1\n");
    const std::string e = errorOf(f.dir.string());
    EXPECT_NE(e.find("times.txt:3"), std::string::npos) << e;
  }
  {
    Folder f("odd_bin");
    writeSequence(f);
    std::ofstream(f.dir / "velodyne/000002.bin", std::ios::binary | std::ios::app) << "abc";
    EXPECT_NE(errorOf(f.dir.string()).find("000002.bin"), std::string::npos);
  }
  EXPECT_NE(errorOf("/nonexistent/kitti").find("not a folder"), std::string::npos);
}

TEST(Kitti, ToolExitsNonZeroWithTheMessage)
{
  Folder f("tool");
  writeSequence(f);
  fs::remove(f.dir / "calib.txt");
  const std::string out = (f.dir / "tool.log").string();
  const std::string cmd = std::string(MAF_KITTI_TO_BAG) + " --sequence " + f.dir.string() + " --out " +
                          (f.dir / "x.bag").string() + " --quiet > " + out + " 2>&1";
  const int rc = std::system(cmd.c_str());
  EXPECT_NE(rc, 0);
  std::ifstream log(out);
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("calib.txt"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(f.dir / "x.bag"));
}

TEST(Kitti, SharedSequenceConvertsWithItsLabels)
{
  const fs::path dir = fs::path(MAF_SHARED_DATA_DIR) / "lidar" / "kitti_00";
  if (!fs::exists(dir / "times.txt"))
  {
    std::printf("SKIPPED: %s is absent\n", dir.string().c_str());
    GTEST_SKIP() << dir << " is absent";
  }
  const KittiSequence s(dir.string());
  std::size_t moving = 0, points = 0, labelled = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    const auto pts = s.readScan(k);
    points += pts.size();
    const auto labels = s.readLabels(k, pts.size());
    labelled += !labels.empty();
    for (std::uint32_t l : labels) moving += dataset::stateOf(l) == dataset::PointState::kMoving;
  }
  ASSERT_GT(points, 0u);
  const fs::path bag = fs::temp_directory_path() / ("maf_kitti_shared_" + std::to_string(::getpid()) + ".bag");
  KittiBagOptions o;
  o.path = bag.string();
  const KittiBagStats st = writeKittiBag(s, o);
  EXPECT_EQ(st.scans, s.size());
  EXPECT_EQ(st.labelled_scans, labelled);
  EXPECT_EQ(st.points, points);
  EXPECT_EQ(st.moving_points, moving);
  EXPECT_GT(moving, 0u) << "the motorcyclist";
  // The car drives forward: the lidar's x grows by about 0.86 m per frame.
  EXPECT_GT(s.lidarPose(s.size() - 1).translation().x(), 0.5 * static_cast<double>(s.size() - 1));
  fs::remove(bag);
}
