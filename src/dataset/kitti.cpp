#include "map_aided_fusion/dataset/kitti.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace map_aided_fusion {
namespace dataset {

namespace {

constexpr int kPoseValues = 12;
constexpr std::size_t kPointBytes = sizeof(KittiPoint);
constexpr std::size_t kLabelBytes = sizeof(std::uint32_t);
constexpr const char* kCalibKey = "Tr:";

std::string frameName(std::size_t frame, const char* ext)
{
  char name[32];
  std::snprintf(name, sizeof name, "%06zu%s", frame, ext);
  return name;
}

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& what)
{
  throw KittiError(path + (line ? ":" + std::to_string(line) : std::string()) + ": " + what);
}

/// Reads exactly @p n finite numbers from @p text. Returns false on a malformed line.
bool parseNumbers(const std::string& text, int n, double* out)
{
  std::istringstream s(text);
  for (int k = 0; k < n; ++k)
    if (!(s >> out[k]) || !std::isfinite(out[k])) return false;
  std::string rest;
  return !(s >> rest);
}

Eigen::Isometry3d fromRowMajor(const double* v)
{
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = v[r * 4 + c];
  Eigen::Isometry3d t;
  t.matrix() = m;
  return t;
}

std::ifstream openText(const std::string& path)
{
  std::ifstream f(path);
  if (!f) fail(path, 0, "cannot open (is this a KITTI sequence folder?)");
  return f;
}

std::uintmax_t fileSize(const std::string& path)
{
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) fail(path, 0, "cannot read: " + ec.message());
  return size;
}

}  // namespace

PointState stateOf(std::uint32_t label)
{
  const std::uint16_t c = semanticClass(label);
  if (c == kClassUnlabeled || c == kClassOutlier) return PointState::kUnlabelled;
  if (c >= kFirstMovingClass && c <= kLastMovingClass) return PointState::kMoving;
  return PointState::kStatic;
}

bool isGroundClass(std::uint16_t c)
{
  return c == 40 || c == 44 || c == 48 || c == 49 || c == 60 || c == 72;
}

Eigen::Isometry3d readCalibrationTr(const std::string& path)
{
  std::ifstream f = openText(path);
  std::string line;
  for (std::size_t n = 1; std::getline(f, line); ++n)
  {
    if (line.rfind(kCalibKey, 0) != 0) continue;
    double v[kPoseValues];
    if (!parseNumbers(line.substr(std::char_traits<char>::length(kCalibKey)), kPoseValues, v))
      fail(path, n, "the Tr line needs 12 finite numbers");
    return fromRowMajor(v);
  }
  fail(path, 0, "no 'Tr:' line (velodyne -> camera 0 calibration)");
}

std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> readPoses(const std::string& path)
{
  std::ifstream f = openText(path);
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> poses;
  std::string line;
  for (std::size_t n = 1; std::getline(f, line); ++n)
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double v[kPoseValues];
    if (!parseNumbers(line, kPoseValues, v)) fail(path, n, "a pose needs 12 finite numbers (3x4, row-major)");
    poses.push_back(fromRowMajor(v));
  }
  return poses;
}

std::vector<double> readTimes(const std::string& path)
{
  std::ifstream f = openText(path);
  std::vector<double> times;
  std::string line;
  for (std::size_t n = 1; std::getline(f, line); ++n)
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double t = 0.0;
    if (!parseNumbers(line, 1, &t) || t < 0.0) fail(path, n, "a time needs one finite number of seconds >= 0");
    if (!times.empty() && t <= times.back()) fail(path, n, "times must increase");
    times.push_back(t);
  }
  if (times.empty()) fail(path, 0, "no time");
  return times;
}

KittiSequence::KittiSequence(const std::string& folder, std::size_t max_frames, const std::string& poses_file)
  : folder_(folder)
{
  if (!fs::is_directory(folder)) throw KittiError(folder + ": not a folder");
  const std::string times_path = (fs::path(folder) / "times.txt").string();
  const std::string poses_path = poses_file.empty() ? (fs::path(folder) / "poses.txt").string() : poses_file;
  const std::string calib_path = (fs::path(folder) / "calib.txt").string();
  times_ = readTimes(times_path);
  if (max_frames > 0 && times_.size() > max_frames) times_.resize(max_frames);
  const std::size_t n = times_.size();
  tr_ = readCalibrationTr(calib_path);
  const auto poses = readPoses(poses_path);
  if (poses.size() < n)
    fail(poses_path, poses.size() + 1,
         std::to_string(poses.size()) + " poses for " + std::to_string(n) + " scans (times.txt): pose missing");
  const Eigen::Isometry3d tr_inv = tr_.inverse();
  lidar_poses_.reserve(n);
  for (std::size_t k = 0; k < n; ++k) lidar_poses_.push_back(tr_inv * poses[k] * tr_);
  labelled_.assign(n, false);
  for (std::size_t k = 0; k < n; ++k)
  {
    if (!fs::is_regular_file(scanPath(k)))
      fail(scanPath(k), 0, "missing: times.txt lists " + std::to_string(n) + " scans, frames must be numbered 0.." +
                               std::to_string(n - 1) + " without a gap");
    labelled_[k] = fs::is_regular_file(labelPath(k));
  }
  if ((max_frames == 0 || n < max_frames) && fs::is_regular_file(scanPath(n)))
    fail(times_path, n + 1, "velodyne/" + frameName(n, ".bin") + " exists but has no time: times.txt is short");
}

std::string KittiSequence::scanPath(std::size_t frame) const
{
  return (fs::path(folder_) / "velodyne" / frameName(frame, ".bin")).string();
}

std::string KittiSequence::labelPath(std::size_t frame) const
{
  return (fs::path(folder_) / "labels" / frameName(frame, ".label")).string();
}

bool KittiSequence::hasLabels(std::size_t frame) const { return labelled_.at(frame); }

std::size_t KittiSequence::labelledFrames() const
{
  std::size_t n = 0;
  for (bool b : labelled_) n += b;
  return n;
}

std::vector<KittiPoint> KittiSequence::readScan(std::size_t frame) const
{
  const std::string path = scanPath(frame);
  const auto bytes = fileSize(path);
  if (bytes % kPointBytes != 0)
    fail(path, 0, std::to_string(bytes) + " bytes is not a whole number of points (16 bytes: x, y, z, remission)");
  std::vector<KittiPoint> points(bytes / kPointBytes);
  std::ifstream f(path, std::ios::binary);
  if (!f.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(bytes)))
    fail(path, 0, "short read");
  return points;
}

std::vector<std::uint32_t> KittiSequence::readLabels(std::size_t frame, std::size_t points) const
{
  if (!hasLabels(frame)) return {};
  const std::string path = labelPath(frame);
  const auto bytes = fileSize(path);
  if (bytes != points * kLabelBytes)
    fail(path, 0, std::to_string(bytes / kLabelBytes) + " labels (" + std::to_string(bytes) + " bytes) for " +
                      std::to_string(points) + " points in " + scanPath(frame));
  std::vector<std::uint32_t> labels(points);
  std::ifstream f(path, std::ios::binary);
  if (!f.read(reinterpret_cast<char*>(labels.data()), static_cast<std::streamsize>(bytes))) fail(path, 0, "short read");
  return labels;
}

}  // namespace dataset
}  // namespace map_aided_fusion
