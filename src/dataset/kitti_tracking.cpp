#include "map_aided_fusion/dataset/kitti_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace map_aided_fusion {
namespace dataset {

namespace {

constexpr const char* kP2Key = "P2:";
constexpr int kProjectionValues = 12;
constexpr std::size_t kLabelFields = 17;
constexpr std::size_t kLabelFieldsWithScore = 18;
constexpr double kMinDepth = 0.1;  // m in front of the camera
constexpr double kFitSlack = 1e-6;  // s, times are given to the microsecond
/// Heights above the ground under the lidar sampled for a cell's column (valid mask), m.
constexpr double kColumnHeights[] = { 0.25, 1.0, 1.75 };

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& what)
{
  throw KittiError(path + (line ? ":" + std::to_string(line) : std::string()) + ": " + what);
}

bool number(const std::string& s, double& v)
{
  try
  {
    std::size_t used = 0;
    v = std::stod(s, &used);
    return used == s.size() && std::isfinite(v);
  }
  catch (const std::exception&)
  {
    return false;
  }
}

bool wholeNumber(const std::string& s, long long& v)
{
  double d = 0.0;
  if (!number(s, d) || d != std::floor(d) || std::abs(d) > 1e12) return false;
  v = static_cast<long long>(d);
  return true;
}

}  // namespace

bool CameraModel::project(const Eigen::Vector3d& c, Eigen::Vector2d& pixel) const
{
  if (c.z() <= kMinDepth) return false;
  const Eigen::Vector3d h = P2 * c.homogeneous();
  if (!(h.z() > 0.0)) return false;
  pixel = h.head<2>() / h.z();
  return true;
}

bool CameraModel::inImage(const Eigen::Vector2d& p) const
{
  return p.x() >= 0.0 && p.y() >= 0.0 && p.x() < width && p.y() < height;
}

Eigen::Matrix<double, 3, 4> readCalibrationP2(const std::string& path)
{
  std::ifstream f(path);
  if (!f) fail(path, 0, "cannot open (is this a KITTI tracking folder?)");
  std::string line;
  for (std::size_t n = 1; std::getline(f, line); ++n)
  {
    if (line.rfind(kP2Key, 0) != 0) continue;
    std::istringstream s(line.substr(std::char_traits<char>::length(kP2Key)));
    Eigen::Matrix<double, 3, 4> p;
    for (int k = 0; k < kProjectionValues; ++k)
    {
      std::string field;
      double v = 0.0;
      if (!(s >> field) || !number(field, v)) fail(path, n, "the P2 line needs 12 finite numbers (3x4, row-major)");
      p(k / 4, k % 4) = v;
    }
    std::string rest;
    if (s >> rest) fail(path, n, "the P2 line needs 12 finite numbers (3x4, row-major), it has more");
    if (!(p(2, 2) != 0.0)) fail(path, n, "P2 is not a projection (its third row has no depth term)");
    return p;
  }
  fail(path, 0, "no 'P2:' line (the left colour camera's projection, which the tracking labels need)");
}

std::vector<TrackingLabel> readTrackingLabels(const std::string& path, std::size_t frames, bool strict)
{
  std::ifstream f(path);
  if (!f) fail(path, 0, "cannot open");
  std::vector<TrackingLabel> out;
  std::string line;
  for (std::size_t n = 1; std::getline(f, line); ++n)
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream s(line);
    std::vector<std::string> fields;
    for (std::string field; s >> field;) fields.push_back(field);
    if (fields.size() != kLabelFields && fields.size() != kLabelFieldsWithScore)
      fail(path, n, std::to_string(fields.size()) + " fields; a KITTI tracking label has 17 (frame, track id, type, "
                                                     "truncated, occluded, alpha, 4 box, 3 dimensions, 3 location, "
                                                     "rotation_y), or 18 with a score");
    TrackingLabel l;
    l.line = n;
    long long frame = 0, track = 0;
    if (!wholeNumber(fields[0], frame) || frame < 0) fail(path, n, "frame '" + fields[0] + "' is not a frame number");
    if (!wholeNumber(fields[1], track) || track < -1) fail(path, n, "track id '" + fields[1] + "' is not an id >= -1");
    l.frame = static_cast<std::size_t>(frame);
    l.track_id = static_cast<int>(track);
    l.type = fields[2];
    double v[14];
    for (int k = 0; k < 14; ++k)
      if (!number(fields[3 + k], v[k])) fail(path, n, "field " + std::to_string(4 + k) + " '" + fields[3 + k] + "' is not a finite number");
    l.left = v[3];
    l.top = v[4];
    l.right = v[5];
    l.bottom = v[6];
    l.height = v[7];
    l.width = v[8];
    l.length = v[9];
    l.location = Eigen::Vector3d(v[10], v[11], v[12]);
    l.rotation_y = v[13];
    if (l.dontCare())
    {
      if (!(l.right >= l.left && l.bottom >= l.top)) fail(path, n, "a DontCare region needs left <= right, top <= bottom");
    }
    else
    {
      if (l.track_id < 0) fail(path, n, "an object of type " + l.type + " needs a track id >= 0");
      if (!(l.height > 0.0 && l.width > 0.0 && l.length > 0.0))
        fail(path, n, "an object needs height, width and length > 0 m");
    }
    if (l.frame >= frames)
    {
      if (strict)
        fail(path, n, "frame " + std::to_string(l.frame) + " is beyond the sequence's " + std::to_string(frames) +
                          " sweeps");
      continue;
    }
    out.push_back(l);
  }
  return out;
}

bool KittiTracking::present(const std::string& folder)
{
  return fs::is_regular_file(fs::path(folder) / "label_02.txt");
}

KittiTracking::KittiTracking(const KittiSequence& sequence, double lidar_height, const MotionThresholds& thresholds,
                             bool strict)
  : lidar_height_(lidar_height)
{
  const std::string folder = sequence.folder();
  camera_.P2 = readCalibrationP2((fs::path(folder) / "calib.txt").string());
  labels_ = readTrackingLabels((fs::path(folder) / "label_02.txt").string(), sequence.size(), strict);
  Eigen::Isometry3d lift = Eigen::Isometry3d::Identity();
  lift.translation().z() = lidar_height;
  const Eigen::Isometry3d camera_to_lidar = sequence.velodyneToCamera().inverse();
  map_from_camera_.reserve(sequence.size());
  for (std::size_t k = 0; k < sequence.size(); ++k)
  {
    map_from_camera_.push_back(lift * sequence.lidarPose(k) * camera_to_lidar);
    lidar_z_.push_back((lift * sequence.lidarPose(k)).translation().z());
  }

  std::map<int, std::vector<std::size_t>> tracks;  // track id → indices in boxes_
  for (const TrackingLabel& l : labels_)
  {
    if (l.dontCare()) continue;
    const Eigen::Isometry3d& t = map_from_camera_[l.frame];
    TrackedBox b;
    b.frame = l.frame;
    b.track_id = l.track_id;
    b.type = l.type;
    // Camera y points down: the box centre is half its height above the bottom centre.
    b.centre = t * (l.location - Eigen::Vector3d(0.0, 0.5 * l.height, 0.0));
    const Eigen::Vector3d heading = t.linear() * Eigen::Vector3d(std::cos(l.rotation_y), 0.0, -std::sin(l.rotation_y));
    b.yaw = std::atan2(heading.y(), heading.x());
    b.length = l.length;
    b.width = l.width;
    b.height = l.height;
    tracks[l.track_id].push_back(boxes_.size());
    boxes_.push_back(b);
  }
  for (auto& [id, members] : tracks)
  {
    for (std::size_t i : members)
    {
      TrackedBox& b = boxes_[i];
      const double tk = sequence.time(b.frame);
      double st = 0.0, n = 0.0;
      Eigen::Vector2d sc = Eigen::Vector2d::Zero();
      for (std::size_t j : members)
        if (std::abs(sequence.time(boxes_[j].frame) - tk) <= thresholds.half_window + kFitSlack)
        {
          st += sequence.time(boxes_[j].frame);
          sc += boxes_[j].centre.head<2>();
          n += 1.0;
        }
      if (n < 2.0) continue;
      const double tm = st / n;
      const Eigen::Vector2d cm = sc / n;
      double stt = 0.0;
      Eigen::Vector2d stc = Eigen::Vector2d::Zero();
      for (std::size_t j : members)
      {
        const double t = sequence.time(boxes_[j].frame);
        if (std::abs(t - tk) > thresholds.half_window + kFitSlack) continue;
        stt += (t - tm) * (t - tm);
        stc += (t - tm) * (boxes_[j].centre.head<2>() - cm);
      }
      if (!(stt > 0.0)) continue;
      b.velocity = stc / stt;
      b.velocity_known = true;
    }
    for (std::size_t i : members)
    {
      TrackedBox& b = boxes_[i];
      if (!b.velocity_known) continue;
      const double speed = b.velocity.norm();
      b.motion = speed > thresholds.moving_speed   ? BoxMotion::kMoving
                 : speed < thresholds.parked_speed ? BoxMotion::kParked
                                                   : BoxMotion::kAmbiguous;
    }
    // Runs of consecutive moving boxes (members are in label order: by frame) too short to be motion.
    for (std::size_t a = 0; a < members.size();)
    {
      if (boxes_[members[a]].motion != BoxMotion::kMoving)
      {
        ++a;
        continue;
      }
      std::size_t e = a;
      while (e + 1 < members.size() && boxes_[members[e + 1]].motion == BoxMotion::kMoving &&
             boxes_[members[e + 1]].frame == boxes_[members[e]].frame + 1)
        ++e;
      const double span = sequence.time(boxes_[members[e]].frame) - sequence.time(boxes_[members[a]].frame);
      if (span < thresholds.min_moving_span - kFitSlack)
        for (std::size_t j = a; j <= e; ++j) boxes_[members[j]].motion = BoxMotion::kAmbiguous;
      a = e + 1;
    }
  }
  std::stable_sort(boxes_.begin(), boxes_.end(), [](const TrackedBox& a, const TrackedBox& b) {
    return a.frame != b.frame ? a.frame < b.frame : a.track_id < b.track_id;
  });
}

std::vector<TrackedBox> KittiTracking::boxes(std::size_t frame) const
{
  std::vector<TrackedBox> out;
  for (const TrackedBox& b : boxes_)
    if (b.frame == frame) out.push_back(b);
  return out;
}

Eigen::Isometry3d KittiTracking::mapFromCamera(std::size_t frame) const { return map_from_camera_.at(frame); }

std::vector<std::int8_t> KittiTracking::validMask(std::size_t frame, double resolution, int width, int height,
                                                  double origin_x, double origin_y) const
{
  std::vector<std::int8_t> mask(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  const Eigen::Isometry3d camera_from_map = map_from_camera_.at(frame).inverse();
  std::vector<const TrackingLabel*> dont_care;
  for (const TrackingLabel& l : labels_)
    if (l.frame == frame && l.dontCare()) dont_care.push_back(&l);
  // The ground under the lidar at this frame: the lidar's map height minus its mount height.
  const double ground = lidar_z_.at(frame) - lidar_height_;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
    {
      const double mx = origin_x + (x + 0.5) * resolution, my = origin_y + (y + 0.5) * resolution;
      bool in_view = false, in_dont_care = false;
      for (double h : kColumnHeights)
      {
        Eigen::Vector2d px;
        if (!camera_.project(camera_from_map * Eigen::Vector3d(mx, my, ground + h), px) || !camera_.inImage(px))
          continue;
        in_view = true;
        for (const TrackingLabel* d : dont_care)
          if (px.x() >= d->left && px.x() <= d->right && px.y() >= d->top && px.y() <= d->bottom) in_dont_care = true;
      }
      mask[static_cast<std::size_t>(y) * width + x] = in_view && !in_dont_care;
    }
  return mask;
}

}  // namespace dataset
}  // namespace map_aided_fusion
