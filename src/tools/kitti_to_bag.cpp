// kitti_to_bag: a KITTI odometry / SemanticKITTI / KITTI tracking sequence folder → a bag with /points, /tf,
// /tf_static and the ground truth (/ground_truth/points per point; /ground_truth/objects and /ground_truth/valid
// per tracking sweep), for the live nodelets (rosbag play --clock) and evaluate.
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>

#include "map_aided_fusion/ros/kitti_bag.hpp"

using namespace map_aided_fusion;

namespace {

void usage()
{
  std::cerr << "usage: kitti_to_bag --sequence DIR --out BAG [--frames N] [--start-stamp S] [--lidar-height M]\n"
               "                    [--poses FILE] [--quiet]\n"
               "  DIR is one KITTI odometry / SemanticKITTI sequence: velodyne/*.bin, labels/*.label (optional,\n"
               "  per frame), poses.txt, calib.txt (Tr), times.txt; or a KITTI tracking sequence in that layout with\n"
               "  label_02.txt and a P2 line in calib.txt (boxes with track ids: ground-truth objects with velocity\n"
               "  and motion state, and where the labels are valid). Writes BAG.partial and renames it to BAG when\n"
               "  every frame is written. --frames: the first N frames only. --start-stamp: ROS time of the\n"
               "  sequence's time 0 (default 1317376800). --lidar-height: the velodyne above the ground (1.73 m).\n"
               "  --poses: camera-0 poses to use instead of DIR/poses.txt (same format; e.g. SemanticKITTI's\n"
               "  poses of KITTI 00, lidar/kitti_00/poses_semantic_kitti.txt).\n";
}

double number(const std::string& name, const std::string& v)
{
  try
  {
    std::size_t used = 0;
    const double d = std::stod(v, &used);
    if (used == v.size()) return d;
  }
  catch (const std::exception&)
  {
  }
  throw std::runtime_error(name + ": not a number: " + v);
}

}  // namespace

int main(int argc, char** argv)
{
  std::string folder;
  KittiBagOptions options;
  std::size_t frames = 0;
  std::string poses;
  bool quiet = false;
  try
  {
    for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--sequence") folder = value();
      else if (a == "--out") options.path = value();
      else if (a == "--frames")
      {
        const double n = number(a, value());
        if (!(n >= 1.0 && n <= 1e9) || n != static_cast<double>(static_cast<std::size_t>(n)))
          throw std::runtime_error("--frames must be a whole number >= 1");
        frames = static_cast<std::size_t>(n);
        options.strict_labels = false;
      }
      else if (a == "--start-stamp") options.start_stamp = number(a, value());
      else if (a == "--lidar-height") options.lidar_height = number(a, value());
      else if (a == "--poses") poses = value();
      else if (a == "--quiet") quiet = true;
      else if (a == "-h" || a == "--help")
      {
        usage();
        return 0;
      }
      else
        throw std::runtime_error("unknown argument " + a);
    }
    if (folder.empty() || options.path.empty()) throw std::runtime_error("--sequence and --out are required");
    if (!(options.start_stamp > 0.0 && options.start_stamp < 4e9))
      throw std::runtime_error("--start-stamp must be in (0, 4e9) s");
    if (!(options.lidar_height >= 0.0 && options.lidar_height <= 10.0))
      throw std::runtime_error("--lidar-height must be in [0, 10] m");
  }
  catch (const std::exception& e)
  {
    std::cerr << "kitti_to_bag: " << e.what() << "\n";
    usage();
    return 2;
  }
  try
  {
    const dataset::KittiSequence sequence(folder, frames, poses);
    if (!quiet && ::isatty(STDERR_FILENO))
      options.progress = [](std::size_t done, std::size_t total) {
        std::fprintf(stderr, "\rkitti_to_bag: %zu/%zu frames", done, total);
        if (done == total) std::fprintf(stderr, "\n");
      };
    const KittiBagStats s = writeKittiBag(sequence, options);
    std::cout << "wrote " << options.path << ": " << s.scans << " scans (" << s.labelled_scans << " labelled), "
              << s.points << " points, " << s.moving_points << " moving points";
    if (s.object_boxes)
      std::cout << ", " << s.object_boxes << " tracking boxes (" << s.moving_tracks << " moving tracks, "
                << s.parked_tracks << " parked)";
    std::cout << "\n";
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "kitti_to_bag: " << e.what() << "\n";
    return 1;
  }
}
