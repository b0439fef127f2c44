#include "map_aided_fusion/replay/offline_replay.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>
#include <tf2/utils.h>
#include <tf2_msgs/TFMessage.h>
#include <yaml-cpp/yaml.h>

#include "map_aided_fusion/GroundTruthObjectArray.h"
#include "map_aided_fusion/TrackedObjectArray.h"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/core/track_evidence.hpp"
#include "map_aided_fusion/eval/metrics.hpp"
#include "map_aided_fusion/eval/movers.hpp"
#include "map_aided_fusion/eval/point_labels.hpp"
#include "map_aided_fusion/eval/scan_evidence.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/map_io/yaml_params.hpp"
#include "map_aided_fusion/replay/labelled_sweeps.hpp"
#include "map_aided_fusion/replay/npy.hpp"
#include "map_aided_fusion/replay/report.hpp"
#include "map_aided_fusion/replay/variants.hpp"
#include "map_aided_fusion/ros/cloud_deskew.hpp"
#include "map_aided_fusion/ros/eval_conversions.hpp"
#include "map_aided_fusion/ros/kitti_bag.hpp"
#include "map_aided_fusion/ros/point_cloud_view.hpp"

namespace map_aided_fusion {
namespace replay {

namespace fs = std::filesystem;
using core::CellClass;

namespace {

constexpr double kStampMatchTolerance = 0.05;  // s between a scan and its ground truth
constexpr int kProgressWidth = 40;

// ---- configuration files (the nodelets' YAML files, read without a ROS master) -------------------------

core::MapGridParams fusionParams(const YAML::Node& n)
{
  core::MapGridParams p;
  core::forEachParam(p, map_io::yamlReader(n));
  p.validate();
  return p;
}

core::ScanGridParams scanGridParams(const YAML::Node& n)
{
  core::ScanGridParams p;
  core::forEachParam(p, map_io::yamlReader(n));
  p.validate();
  return p;
}

/// The PriorGrid parameters of the prior config (map, β, cell test, accuracies), β and options validated.
map_io::PriorGridParams priorGridParams(const YAML::Node& n)
{
  map_io::PriorGridParams p;
  map_io::forEachPriorGridParam(p, map_io::yamlReader(n));
  p.beta.validate();
  p.options.validate();
  return p;
}

// ---- ground truth ----------------------------------------------------------------------------------------

std::int64_t key(const ros::Time& t) { return static_cast<std::int64_t>(t.toNSec()); }

template <typename V>
const V* nearest(const std::map<std::int64_t, V>& m, const ros::Time& t)
{
  if (m.empty()) return nullptr;
  const std::int64_t k = key(t);
  auto it = m.lower_bound(k);
  const V* best = nullptr;
  double best_dt = kStampMatchTolerance;
  auto consider = [&](typename std::map<std::int64_t, V>::const_iterator i) {
    const double dt = std::abs(static_cast<double>(i->first - k)) * 1e-9;
    if (dt <= best_dt)
    {
      best_dt = dt;
      best = &i->second;
    }
  };
  if (it != m.end()) consider(it);
  if (it != m.begin()) consider(std::prev(it));
  return best;
}

// ---- pipeline variants -----------------------------------------------------------------------------------

struct Variant
{
  eval::VariantScores scores;
  core::MapGrid grid;
  core::ScanGridParams scan_params;
  core::ScanGridBuilder builder;
  bool builder_ready = false;
  core::ScanMassGrid scan;
  bool use_prior;
  core::PriorGridOptions prior_options;
  core::PriorSoftener softener;
  const core::PriorWindow* last_prior = nullptr;  // the softener's prior given to the last update
  eval::ClassGrid decision;
  eval::PointLabelScorer points;
  std::optional<core::Tracker> tracker;  ///< when the profile enables it
  std::vector<std::uint8_t> background;  ///< per obstacle return: on static background (the tracker's input)
  Variant(const std::string& name, const std::string& description, const core::Profile& profile, bool prior,
          double match_radius)
    : grid(profile.map_grid)
    , scan_params(profile.scan_grid)
    , use_prior(prior)
    , prior_options(profile.prior)
    , points(match_radius)
  {
    if (profile.tracker.enabled) tracker.emplace(profile.tracker);
    scores.name = name;
    scores.description = description;
  }
};

/// A progress bar rewritten in place, only on a terminal (logs get no carriage returns).
void progress(bool quiet, std::size_t done, std::size_t total, const char* what)
{
  static const bool terminal = ::isatty(STDERR_FILENO);
  if (quiet || total == 0 || !terminal) return;
  const int filled = static_cast<int>(kProgressWidth * done / total);
  std::fprintf(stderr, "\r%-10s [%s%s] %zu/%zu", what, std::string(filled, '#').c_str(),
               std::string(kProgressWidth - filled, ' ').c_str(), done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

/// The map and the PriorGrid parameters of the prior config (β, resolution), or nothing without a map.
struct MapSource
{
  map_io::PriorGridParams params;
  core::VectorMap map;
};

std::optional<MapSource> loadMap(const ReplayOptions& o, const map_io::PriorGridParams& params, std::string& summary)
{
  MapSource src;
  src.params = params;
  map_io::PriorGridParams& pp = src.params;
  if (!o.map.empty()) pp.map.file = o.map;
  if (pp.map.file.empty())
  {
    summary = "none (no --map and no map_file in the prior config)";
    return std::nullopt;
  }
  if (o.origin)
  {
    pp.map.origin_latitude = (*o.origin)[0];
    pp.map.origin_longitude = (*o.origin)[1];
    pp.map.origin_altitude = (*o.origin)[2];
  }
  map_io::MapLoadReport report;
  src.map = map_io::loadVectorMap(pp.map, &report);
  summary = pp.map.file + ": " + std::to_string(src.map.buildings.size()) + " buildings, " +
            std::to_string(src.map.road_areas.size()) + " road surfaces";
  return src;
}

/// The prior masses of the whole map for one way of making the PriorGrid (cell test, map accuracy).
std::shared_ptr<const core::PriorWindow> makePrior(const MapSource& src, const core::PriorGridOptions& options,
                                                   double resolution)
{
  const core::PriorGrid grid = core::PriorGrid::fromVectorMap(src.map, resolution, 0.0, nullptr, options.cell_test);
  auto window = std::make_shared<core::PriorWindow>();
  core::mapPrior(grid, grid.geometry(), src.params.beta, options, *window);
  return window;
}

/// The labelled points of one sweep in the map frame, flagged as obstacles the way the sensor model would.
std::vector<eval::LabelledPoint> toLabelledPoints(const sensor_msgs::PointCloud2& msg, tf2::BufferCore& tf,
                                                  const ReplayOptions& o, const core::ScanGridParams& sg)
{
  return KittiConversions::toScoredPoints(
      msg, KittiConversions::toIsometry(tf.lookupTransform(o.map_frame, msg.header.frame_id, msg.header.stamp)),
      KittiConversions::toIsometry(tf.lookupTransform(o.base_frame, msg.header.frame_id, msg.header.stamp)),
      sg.ground_height + sg.obstacle_min_height, sg.ground_height + sg.obstacle_max_height);
}

void writeSnapshotNpy(const fs::path& dir, const std::string& stem, const eval::ClassGrid& g)
{
  writeNpy(dir / (stem + "_decision.npy"), g.cells.data(),
           { static_cast<std::size_t>(g.geometry.height), static_cast<std::size_t>(g.geometry.width) }, "|i1");
}

}  // namespace

ReplayConfiguration loadReplayConfiguration(const ReplayOptions& opt)
{
  const YAML::Node fusion_cfg = map_io::loadYamlFile(opt.fusion_config);
  const YAML::Node scan_cfg = map_io::loadYamlFile(opt.scan_grid_config);
  const YAML::Node prior_cfg = map_io::loadYamlFile(opt.prior_config);
  ReplayConfiguration c;
  c.configured.map_grid = fusionParams(fusion_cfg);
  c.configured.scan_grid = scanGridParams(scan_cfg);
  core::forEachParam(c.configured.tracker, map_io::yamlReader(fusion_cfg));
  c.configured.tracker.validate();
  c.prior = priorGridParams(prior_cfg);
  c.configured.prior = c.prior.options;
  if (fusion_cfg["pose_covariance_topic"]) c.covariance_topic = fusion_cfg["pose_covariance_topic"].as<std::string>();
  if (fusion_cfg["pose_covariance_type"]) c.covariance_type = fusion_cfg["pose_covariance_type"].as<std::string>();
  if (opt.pose_covariance_topic) c.covariance_topic = *opt.pose_covariance_topic;
  return c;
}

ReplayReport runOfflineReplay(const ReplayOptions& opt)
{
  const ReplayConfiguration cfg = loadReplayConfiguration(opt);
  core::Profile configured = cfg.configured;
  std::string prior_summary;
  const std::optional<MapSource> map_source = loadMap(opt, cfg.prior, prior_summary);
  if (map_source) configured.prior = map_source->params.options;
  const bool prior = map_source.has_value();
  const std::string& covariance_topic = cfg.covariance_topic;
  const std::string& covariance_type = cfg.covariance_type;
  std::map<std::int64_t, double> covariance_sigma;
  std::size_t covariance_rejected = 0;

  // Pass 1: tf, ground truth.
  rosbag::Bag bag;
  bag.open(opt.bag, rosbag::bagmode::Read);
  tf2::BufferCore tf(ros::Duration(1e6));
  std::map<std::int64_t, eval::ClassGrid> truth;
  std::map<std::int64_t, std::vector<eval::TruthObject>> truth_objects;
  std::map<std::int64_t, eval::ClassGrid> valid_masks;
  std::set<std::int64_t> labelled_stamps;
  std::size_t clouds = 0;
  {
    rosbag::View view(bag);
    for (const rosbag::MessageInstance& m : view)
    {
      const std::string& topic = m.getTopic();
      if (topic == "/tf" || topic == "/tf_static")
      {
        if (auto msg = m.instantiate<tf2_msgs::TFMessage>())
          for (const auto& t : msg->transforms) tf.setTransform(t, "bag", topic == "/tf_static");
      }
      else if (topic == "/ground_truth/classes")
      {
        if (auto msg = m.instantiate<nav_msgs::OccupancyGrid>()) truth[key(msg->header.stamp)] = toClassGrid(*msg);
      }
      else if (topic == "/ground_truth/objects")
      {
        if (auto msg = m.instantiate<GroundTruthObjectArray>())
          truth_objects[key(msg->header.stamp)] = toTruthObjects(*msg);
      }
      else if (topic == "/ground_truth/valid")
      {
        if (auto msg = m.instantiate<nav_msgs::OccupancyGrid>()) valid_masks[key(msg->header.stamp)] = toClassGrid(*msg);
      }
      else if (topic == "/ground_truth/points")
      {
        if (auto msg = m.instantiate<sensor_msgs::PointCloud2>()) labelled_stamps.insert(key(msg->header.stamp));
      }
      else if (topic == "/points")
      {
        ++clouds;
      }
      else if (!covariance_topic.empty() && topic == covariance_topic)
      {
        std::array<double, 36> c{};
        ros::Time stamp;
        if (auto msg = m.instantiate<geometry_msgs::PoseWithCovarianceStamped>(); msg && covariance_type == "pose")
        {
          std::copy(msg->pose.covariance.begin(), msg->pose.covariance.end(), c.begin());
          stamp = msg->header.stamp;
        }
        else if (auto od = m.instantiate<nav_msgs::Odometry>(); od && covariance_type == "odometry")
        {
          std::copy(od->pose.covariance.begin(), od->pose.covariance.end(), c.begin());
          stamp = od->header.stamp;
        }
        else
          continue;
        double sigma = 0.0;
        if (core::positionSigma(c, sigma) == core::CovarianceFault::kNone)
          covariance_sigma[key(stamp)] = std::min(sigma, core::kMaxPositionSigma);
        else
          ++covariance_rejected;
      }
    }
  }
  if (clouds == 0) throw std::runtime_error(opt.bag + " has no /points");
  // Ground truth: simulator cells, labelled points (SemanticKITTI) or labelled boxes (KITTI tracking).
  const bool object_mode = truth.empty() && !truth_objects.empty();
  const bool point_mode = truth.empty() && !object_mode;
  const bool objects_missing = !truth.empty() && truth_objects.empty();
  if (objects_missing)
    std::cerr << "evaluate: " << opt.bag << " has /ground_truth/classes but no /ground_truth/objects: cells are "
              << "scored, objects, movers and tracks are not (their columns read 0/0)\n";
  if (point_mode && labelled_stamps.empty())
    throw std::runtime_error(opt.bag + " has neither /ground_truth/classes (simulator), /ground_truth/points "
                                       "(labelled real points, kitti_to_bag) nor /ground_truth/objects (labelled "
                                       "boxes, kitti_to_bag on KITTI tracking)");
  const eval::ReturnsInBoxes in_boxes{ configured.scan_grid.ground_height + configured.scan_grid.obstacle_min_height,
                                       configured.scan_grid.ground_height + configured.scan_grid.obstacle_max_height };
  // Labelled boxes: each sweep's obstacle returns in each box (map frame), for the offline and the live scores.
  std::map<std::int64_t, std::vector<eval::ObjectReturns>> object_returns;
  // Adds the scan to @p movers; returns its sightings (CLEAR-MOT judges the movers seen in them).
  auto scoreMovers = [&](eval::MoverScorer& movers, double t, const ros::Time& stamp, const eval::ClassGrid& decision,
                         const std::vector<eval::TruthObject>* objects, const eval::ClassGrid* gt) {
    const std::vector<eval::TruthObject> none;
    const auto& objs = objects ? *objects : none;
    std::vector<eval::ObjectSighting> sightings;
    if (object_mode)
    {
      const auto r = object_returns.find(key(stamp));
      const eval::ClassGrid* valid = nearest(valid_masks, stamp);
      eval::ClassGrid nothing_valid;
      if (r != object_returns.end()) sightings = eval::sightingsFromReturns(r->second, decision);
      movers.add(t, sightings, eval::countFalseV(decision, valid ? valid : &nothing_valid, objs, opt.match_radius));
    }
    else if (gt)
    {
      sightings = eval::sightingsFromClassGrid(*gt, objs, decision);
      movers.add(t, sightings, eval::countFalseV(decision, nullptr, objs, opt.match_radius));
    }
    return sightings;
  };

  std::vector<std::unique_ptr<Variant>> variants;
  std::vector<std::pair<core::PriorGridOptions, std::shared_ptr<const core::PriorWindow>>> priors;
  auto priorFor = [&](const core::PriorGridOptions& o) {
    for (const auto& [k, w] : priors)
      if (k.cell_test == o.cell_test && k.building_accuracy == o.building_accuracy && k.road_accuracy == o.road_accuracy)
        return w;
    priors.emplace_back(o, makePrior(*map_source, o, configured.map_grid.resolution));
    return priors.back().second;
  };
  for (const VariantSpec& spec : variantSpecs(configured, prior, opt.ablations, opt.only))
  {
    variants.push_back(std::make_unique<Variant>(spec.name, spec.description, spec.profile, spec.use_prior,
                                                 opt.match_radius));
    if (spec.use_prior) variants.back()->softener.setPrior(priorFor(spec.profile.prior));
  }

  if (variants.empty())
  {
    std::string names;
    for (const auto& n : opt.only) names += (names.empty() ? "" : ",") + n;
    throw std::runtime_error("--only " + names + ": no such variant for this bag (default, paper, ...; the prior "
                                                 "variants need a map)");
  }
  fs::create_directories(fs::path(opt.out) / "snapshots");
  std::ofstream csv(fs::path(opt.out) / "scores.csv");
  if (point_mode)
    csv << "time_s,variant,labelled,v_cells,false_v,v_on_static,mover_cells,mover_v_cells\n";
  else if (object_mode)
    csv << "time_s,variant,labelled_objects,movers_seen,movers_v\n";
  else
  {
    csv << "time_s,variant,scan_compared_cells";
    for (const auto& n : core::kCellClassLongNames) csv << "," << n << "_recall";
    csv << ",accuracy\n";
  }

  // Pass 2: scans (and, for labelled real data, the sweep's labelled points).
  std::optional<double> t0;
  std::size_t done = 0, no_truth = 0, no_pose = 0;
  CloudDeskewer deskewer;
  std::map<std::string, std::size_t> deskew_status;
  double snapshot_at = -1.0, next_sheet = 0.0;
  int sheet_frame = 0;
  const double duration_guess = [&] {
    rosbag::View v(bag, rosbag::TopicQuery(std::vector<std::string>{ "/points" }));
    return (v.getEndTime() - v.getBeginTime()).toSec();
  }();
  const double snapshot_time = opt.snapshot_time >= 0.0 ? opt.snapshot_time : 0.7 * duration_guess;
  // Labelled sweeps: what each variant made of the cloud waits for the sweep's points (or the points for it).
  LabelledSweeps labelled_sweeps;
  auto scorePending = [&](std::int64_t k) {
    std::optional<LabelledSweep> sweep = labelled_sweeps.take(k);
    if (!sweep) return;
    const double t = static_cast<double>(k) * 1e-9;
    for (std::size_t v = 0; v < variants.size(); ++v)
    {
      scoreSweep(t, sweep->variants[v], sweep->points, variants[v]->points);
      const auto& s = variants[v]->points.sweeps().back();
      csv << (t - *t0) << "," << variants[v]->scores.name << ",1," << s.v_cells << "," << s.false_v << ","
          << s.v_on_static << "," << s.mover_cells << "," << s.mover_v_cells << "\n";
    }
  };
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{ "/points", "/ground_truth/points" }));
  for (const rosbag::MessageInstance& m : view)
  {
    auto cloud = m.instantiate<sensor_msgs::PointCloud2>();
    if (!cloud) continue;
    if (m.getTopic() == "/ground_truth/points")
    {
      if (!point_mode) continue;
      try
      {
        labelled_sweeps.addPoints(key(cloud->header.stamp), toLabelledPoints(*cloud, tf, opt, configured.scan_grid));
      }
      catch (const tf2::TransformException&)
      {
        continue;
      }
      if (t0) scorePending(key(cloud->header.stamp));
      continue;
    }
    progress(opt.quiet, ++done, clouds, "scans");
    geometry_msgs::TransformStamped base, sensor;
    try
    {
      base = tf.lookupTransform(opt.map_frame, opt.base_frame, cloud->header.stamp);
      sensor = tf.lookupTransform(opt.base_frame, cloud->header.frame_id, cloud->header.stamp);
    }
    catch (const tf2::TransformException&)
    {
      ++no_pose;
      continue;
    }
    core::PointCloudView pv;
    std::string detail;
    if (makePointCloudView(*cloud, pv, &detail) != CloudRejection::kNone)
      throw std::runtime_error("unreadable cloud in " + opt.bag + ": " + detail);
    core::PointCloudView deskewed;
    const DeskewResult deskew =
        deskewer.apply(*cloud, pv, true, "auto", configured.scan_grid.deskew_max_sweep_duration, tf, opt.map_frame,
                       deskewed);
    ++deskew_status[deskew.status];
    const double t = cloud->header.stamp.toSec();
    if (!t0) t0 = t;
    const core::Pose2 pose{ base.transform.translation.x, base.transform.translation.y,
                            tf2::getYaw(base.transform.rotation) };
    const eval::ClassGrid* gt = point_mode || object_mode ? nullptr : nearest(truth, cloud->header.stamp);
    const auto* objects = point_mode ? nullptr : nearest(truth_objects, cloud->header.stamp);
    if (!gt && !point_mode && !object_mode) ++no_truth;
    if (object_mode && !objects) ++no_truth;
    if (object_mode && objects)
      object_returns[key(cloud->header.stamp)] = eval::collectObjectReturns(
          pv, KittiConversions::toIsometry(base) * KittiConversions::toIsometry(sensor),
          KittiConversions::toIsometry(sensor), *objects, in_boxes);
    const bool snapshot = snapshot_at < 0.0 && t - *t0 >= snapshot_time;
    const bool sheet = t - *t0 >= next_sheet;
    const std::int64_t k = key(cloud->header.stamp);
    const bool labelled = point_mode && labelled_stamps.count(k);
    for (auto& v : variants)
    {
      if (!v->builder_ready)
      {
        v->builder.configure(v->scan_params, KittiConversions::toIsometry(sensor));
        v->builder.recordReturnClasses(point_mode);
        v->builder_ready = true;
      }
      else
        v->builder.setSensorPose(KittiConversions::toIsometry(sensor));
      v->builder.build(v->scan_params.deskew ? deskewed : pv, v->scan);
      const core::ObstaclePoints obstacles = v->builder.obstaclePoints();
      double sigma = v->grid.params().position_sigma;
      if (auto c = covariance_sigma.upper_bound(k); c != covariance_sigma.begin()) sigma = std::prev(c)->second;
      const core::PriorWindow* pw = v->use_prior ? v->softener.softened(sigma) : nullptr;
      v->grid.update(v->scan, pose, t, pw, nullptr, &obstacles);
      if (v->tracker) core::trackScan(*v->tracker, v->grid, t, pose, obstacles, v->background, &v->scan, pw);
      auto scoreTracks = [&](const std::vector<eval::ObjectSighting>& sightings) {
        if (!v->tracker || !objects || point_mode) return;
        // Labelled boxes: only tracks where the labels are valid can be judged.
        const eval::ClassGrid* valid = object_mode ? nearest(valid_masks, cloud->header.stamp) : nullptr;
        std::vector<eval::MotHypothesis> hypotheses;
        for (const core::Track& tr : v->tracker->tracks())
        {
          if (!tr.reported() || tr.motion != core::TrackMotion::kMoving) continue;
          const core::Point2 centre = core::reportedBox(tr, *v->tracker).centre;
          if (!object_mode || (valid && valid->at(centre) > 0))
            hypotheses.push_back(eval::MotHypothesis{ tr.id, centre, true, tr.velocity() });
        }
        v->scores.tracks.addFrame(eval::motObjects(*objects, sightings, v->scores.movers), hypotheses);
      };
      v->last_prior = pw;
      v->decision.geometry = v->grid.geometry();
      v->decision.cells = v->grid.decisions();
      if (point_mode)
      {
        if (labelled)
        {
          labelled_sweeps.addVariant(k, VariantSweep{ v->decision, v->builder.returnClasses(),
                                                      eval::scanEvidence(v->scan, pose, v->grid, &obstacles) });
        }
        else
        {
          v->points.add(t, v->decision, {}, false);
          csv << (t - *t0) << "," << v->scores.name << ",0," << v->points.sweeps().back().v_cells << ",,,,\n";
        }
        ++v->scores.scans;
        continue;
      }
      if (object_mode)
      {
        scoreTracks(scoreMovers(v->scores.movers, t, cloud->header.stamp, v->decision, objects, nullptr));
        int seen = 0, as_v = 0;
        for (const auto& [id, r] : v->scores.movers.records())
          if (!r.timeline.empty() && r.timeline.back().first + 1 == v->scores.movers.stamps().size())
          {
            seen += r.timeline.back().second != eval::SightingState::kUnseen;
            as_v += r.timeline.back().second == eval::SightingState::kV;
          }
        csv << (t - *t0) << "," << v->scores.name << "," << (objects ? objects->size() : 0) << "," << seen << ","
            << as_v << "\n";
        ++v->scores.scans;
        continue;
      }
      if (!gt) continue;
      eval::ConfusionMatrix scan_confusion;
      const auto compared = eval::accumulate(*gt, v->decision, scan_confusion);
      v->scores.confusion.add(scan_confusion);
      v->scores.objects.add(t, *gt, objects ? *objects : std::vector<eval::TruthObject>{}, v->decision);
      scoreTracks(scoreMovers(v->scores.movers, t, cloud->header.stamp, v->decision, objects, gt));
      ++v->scores.scans;
      csv << (t - *t0) << "," << v->scores.name << "," << compared;
      for (int c = 0; c < core::kNumCellClasses; ++c)
        csv << "," << (scan_confusion.support(c) ? std::to_string(scan_confusion.recall(c)) : "");
      csv << "," << scan_confusion.accuracy() << "\n";
    }
    if (labelled) scorePending(k);
    if (object_mode) continue;
    if (point_mode)
    {
      // Snapshots of every sweep's decisions for the figures (small runs; long sequences: every sheet period).
      if (sheet)
      {
        const fs::path dir = fs::path(opt.out) / "snapshots";
        const std::string stem = "sweep_" + std::to_string(sheet_frame++);
        for (const auto& v : variants)
        {
          writeSnapshotNpy(dir, stem + "_" + v->scores.name, v->decision);
          // What the ScanGrid made of each point (core::ReturnClass codes, in the cloud's order), for the figures.
          const auto& classes = v->builder.returnClasses();
          if (v->scores.name == "default" || v->scores.name == "paper")
            writeNpy(dir / (stem + "_" + v->scores.name + "_returns.npy"), classes.data(), { classes.size() }, "|u1");
        }
        std::ofstream meta(dir / (stem + ".json"));
        const auto& g = variants[0]->grid.geometry();
        meta << "{\"time_s\": " << (t - *t0) << ", \"ego\": {\"x\": " << pose.x << ", \"y\": " << pose.y
             << ", \"yaw\": " << pose.yaw << "}, \"grid\": {\"resolution\": " << g.resolution << ", \"width\": "
             << g.width << ", \"height\": " << g.height << ", \"origin_x\": " << g.origin_x
             << ", \"origin_y\": " << g.origin_y << "}}\n";
        next_sheet += opt.sheet_period;
      }
      continue;
    }
    if ((snapshot || sheet) && gt)
    {
      const fs::path dir = fs::path(opt.out) / "snapshots";
      auto geometryJson = [](const core::GridGeometry& g) {
        std::ostringstream s;
        s << "{\"resolution\": " << g.resolution << ", \"width\": " << g.width << ", \"height\": " << g.height
          << ", \"origin_x\": " << g.origin_x << ", \"origin_y\": " << g.origin_y << "}";
        return s.str();
      };
      const std::string stem = snapshot ? "figure" : "sheet_" + std::to_string(sheet_frame);
      writeSnapshotNpy(dir, stem + "_with_prior", variants[0]->decision);
      writeNpy(dir / (stem + "_truth.npy"), gt->cells.data(),
               { static_cast<std::size_t>(gt->geometry.height), static_cast<std::size_t>(gt->geometry.width) }, "|i1");
      std::ofstream meta(dir / (stem + ".json"));
      meta << "{\"time_s\": " << (t - *t0) << ", \"ego\": {\"x\": " << pose.x << ", \"y\": " << pose.y
           << ", \"yaw\": " << pose.yaw << "}, \"grid\": " << geometryJson(variants[0]->grid.geometry())
           << ", \"truth_grid\": " << geometryJson(gt->geometry) << ", \"objects\": [";
      if (objects)
        for (std::size_t j = 0; j < objects->size(); ++j)
        {
          const auto& o = (*objects)[j];
          meta << (j ? ", " : "") << "{\"id\": " << o.id << ", \"class\": " << static_cast<int>(o.cell_class)
               << ", \"kind\": \"" << o.kind << "\", \"x\": " << o.centre.x << ", \"y\": " << o.centre.y
               << ", \"yaw\": " << o.yaw << ", \"length\": " << o.length << ", \"width\": " << o.width
               << ", \"speed\": " << o.speed << "}";
        }
      meta << "]}\n";
      if (snapshot)
      {
        snapshot_at = t - *t0;
        for (const auto& v : variants)
        {
          if (v->scores.name != "default" && v->scores.name != "default_no_prior" && v->scores.name != "paper")
            continue;
          const auto& g = v->grid.geometry();
          std::vector<float> planes;
          for (int e = 0; e < core::FrameMG::kSize; ++e)
            planes.insert(planes.end(), v->grid.pignistic()[e].begin(), v->grid.pignistic()[e].end());
          writeNpy(dir / ("figure_" + v->scores.name + "_betp.npy"), planes.data(),
                   { 5, static_cast<std::size_t>(g.height), static_cast<std::size_t>(g.width) }, "<f4");
          writeSnapshotNpy(dir, "figure_" + v->scores.name, v->decision);
        }
        if (prior)
        {
          const auto& g = variants[0]->grid.geometry();
          core::PriorWindow w;
          variants[0]->grid.priorWindow(variants[0]->last_prior, w);
          std::vector<std::int8_t> labels(g.numCells());
          for (std::size_t i = 0; i < labels.size(); ++i)
          {
            const float b = w.building[i] + w.wall[i];
            labels[i] = b > 0.0f && b >= w.road[i] && b >= w.other[i] ? 1
                        : w.road[i] > 0.0f && w.road[i] >= w.other[i] ? 2
                        : w.other[i] > 0.0f                           ? 3
                                                                      : 0;
          }
          writeNpy(dir / "figure_prior.npy", labels.data(),
                   { static_cast<std::size_t>(g.height), static_cast<std::size_t>(g.width) }, "|i1");
        }
      }
      if (sheet)
      {
        ++sheet_frame;
        next_sheet += opt.sheet_period;
      }
    }
  }

  std::vector<eval::VariantScores> scores;
  for (const auto& v : variants) scores.push_back(v->scores);

  // The live nodelets' decisions, when recorded.
  std::vector<std::unique_ptr<eval::PointLabelScorer>> live_points;
  for (const auto& [live_name, live_path] : opt.output_bags)
  {
    live_points.push_back(std::make_unique<eval::PointLabelScorer>(opt.match_radius));
    rosbag::Bag live;
    live.open(live_path, rosbag::bagmode::Read);
    eval::VariantScores s;
    s.name = live_name;
    s.description = "the three nodelets running on the replayed bag (rosbag play --clock), decisions recorded from " +
                    opt.live_topic;
    // The live tracks, when recorded, for CLEAR-MOT.
    std::map<std::int64_t, std::vector<eval::MotHypothesis>> live_tracks;
    for (const rosbag::MessageInstance& m :
         rosbag::View(live, rosbag::TopicQuery(std::vector<std::string>{ opt.live_tracks_topic })))
      if (auto a = m.instantiate<TrackedObjectArray>())
      {
        auto& h = live_tracks[key(a->header.stamp)];
        const eval::ClassGrid* valid = object_mode ? nearest(valid_masks, a->header.stamp) : nullptr;
        for (const auto& o : a->objects)
        {
          const core::Point2 p{ o.pose.position.x, o.pose.position.y };
          if (o.cell_class == TrackedObject::MOVING && (!object_mode || (valid && valid->at(p) > 0)))
            h.push_back(eval::MotHypothesis{ o.id, p, true, core::Point2{ o.velocity.x, o.velocity.y } });
        }
      }
    auto scoreLiveTracks = [&](const ros::Time& stamp, const std::vector<eval::TruthObject>* objects,
                               const std::vector<eval::ObjectSighting>& sightings) {
      const auto h = live_tracks.find(key(stamp));
      if (h == live_tracks.end() || !objects) return;
      s.tracks.addFrame(eval::motObjects(*objects, sightings, s.movers), h->second);
    };
    rosbag::View lv(live, rosbag::TopicQuery(std::vector<std::string>{ opt.live_topic }));
    const std::size_t total = lv.size();
    std::size_t k = 0;
    for (const rosbag::MessageInstance& m : lv)
    {
      progress(opt.quiet, ++k, total, "live");
      auto d = m.instantiate<nav_msgs::OccupancyGrid>();
      if (!d) continue;
      const eval::ClassGrid decision = toClassGrid(*d);
      if (point_mode)
      {
        std::vector<eval::LabelledPoint> points;
        const bool labelled = labelled_stamps.count(key(d->header.stamp)) > 0;
        if (labelled)
        {
          rosbag::View pv(bag, rosbag::TopicQuery(std::vector<std::string>{ "/ground_truth/points" }),
                          d->header.stamp, d->header.stamp);
          for (const rosbag::MessageInstance& pm : pv)
            if (auto c = pm.instantiate<sensor_msgs::PointCloud2>())
              if (c->header.stamp == d->header.stamp) points = toLabelledPoints(*c, tf, opt, configured.scan_grid);
        }
        live_points.back()->add(d->header.stamp.toSec(), decision, points, labelled);
        ++s.scans;
        continue;
      }
      if (object_mode)
      {
        const auto* objects = nearest(truth_objects, d->header.stamp);
        scoreLiveTracks(d->header.stamp, objects,
                        scoreMovers(s.movers, d->header.stamp.toSec(), d->header.stamp, decision, objects, nullptr));
        ++s.scans;
        continue;
      }
      const eval::ClassGrid* gt = nearest(truth, d->header.stamp);
      if (!gt) continue;
      eval::accumulate(*gt, decision, s.confusion);
      const auto* objects = nearest(truth_objects, d->header.stamp);
      s.objects.add(d->header.stamp.toSec(), *gt, objects ? *objects : std::vector<eval::TruthObject>{}, decision);
      scoreLiveTracks(d->header.stamp, objects,
                      scoreMovers(s.movers, d->header.stamp.toSec(), d->header.stamp, decision, objects, gt));
      ++s.scans;
    }
    if (s.scans == 0) std::cerr << "evaluate: no decision of " << live_path << " matches the bag's stamps\n";
    scores.push_back(s);
  }
  bag.close();

  std::map<std::string, std::string> meta{ { "bag", opt.bag },
                                           { "ground_truth", point_mode    ? "labelled points"
                                                             : object_mode ? "labelled boxes"
                                                                           : "simulator cells" },
                                           { "prior", prior_summary },
                                           { "pose_covariances", std::to_string(covariance_sigma.size()) + " on '" +
                                                                     covariance_topic + "', " +
                                                                     std::to_string(covariance_rejected) + " rejected" },
                                           { "scans", std::to_string(done) },
                                           { "scans_without_pose", std::to_string(no_pose) },
                                           { "deskew", deskewSummary(deskew_status) },
                                           { "scans_without_ground_truth", std::to_string(no_truth) },
                                           { "labelled_scans", std::to_string(labelled_stamps.size()) },
                                           { "figure_time_s", std::to_string(snapshot_at) } };
  std::string markdown;
  if (point_mode)
  {
    std::vector<std::pair<std::string, const eval::PointLabelScorer*>> rows;
    for (const auto& v : variants) rows.emplace_back(v->scores.name, &v->points);
    for (std::size_t l = 0; l < opt.output_bags.size(); ++l)
      rows.emplace_back(opt.output_bags[l].first, live_points[l].get());
    markdown = eval::pointLabelMarkdown(rows);
    std::ofstream json(fs::path(opt.out) / "metrics.json");
    json << "{\n  \"meta\": {";
    bool first = true;
    for (const auto& [k, v] : meta)
    {
      json << (first ? "" : ", ") << "\"" << k << "\": \"" << v << "\"";
      first = false;
    }
    json << "},\n  \"match_radius_m\": " << opt.match_radius << ",\n  \"variants\": {";
    for (std::size_t r = 0; r < rows.size(); ++r)
    {
      json << (r ? "," : "") << "\n    \"" << rows[r].first << "\": {";
      bool f = true;
      for (const auto& [k, x] : rows[r].second->summary())
      {
        json << (f ? "" : ", ") << "\"" << k << "\": " << (std::isfinite(x) ? x : 0.0);
        f = false;
      }
      json << ", \"per_sweep\": [";
      const auto& sw = rows[r].second->sweeps();
      for (std::size_t j = 0; j < sw.size(); ++j)
        json << (j ? ", " : "") << "{\"labelled\": " << (sw[j].labelled ? "true" : "false")
             << ", \"v_cells\": " << sw[j].v_cells << ", \"false_v\": " << sw[j].false_v
             << ", \"mover_cells\": " << sw[j].mover_cells << ", \"mover_v_cells\": " << sw[j].mover_v_cells << "}";
      json << "]}";
    }
    json << "\n  }\n}\n";
  }
  else if (object_mode)
  {
    meta["valid_masks"] = std::to_string(valid_masks.size());
    std::ofstream(fs::path(opt.out) / "metrics.json") << eval::moversJson(scores, meta);
    markdown = moversSection(scores, true) + tracksSection(scores);
  }
  else
  {
    if (objects_missing) meta["objects_scored"] = "false: the bag has no /ground_truth/objects";
    std::ofstream(fs::path(opt.out) / "metrics.json") << eval::toJson(scores, meta);
    markdown = (objects_missing ? std::string("**Objects not scored**: the bag has no `/ground_truth/objects`; the "
                                              "object, mover and track figures below read 0/0.\n\n") :
                                  std::string()) +
               eval::toMarkdown(scores) + "\n" + moversSection(scores, false) + tracksSection(scores);
  }
  std::ofstream(fs::path(opt.out) / "metrics.md") << "# map_aided_fusion evaluation\n\nBag: `" << opt.bag << "`, "
                                                   << done << " scans"
                                                   << (point_mode    ? " (labelled real data)"
                                                       : object_mode ? " (labelled real objects)"
                                                                     : "")
                                                   << ".\n\n"
                                                   << markdown;
  ReplayReport report;
  report.markdown = markdown;
  report.scans = done;
  for (const auto& s : scores) report.variants.push_back(s.name);
  report.ground_truth = meta["ground_truth"];
  return report;
}

}  // namespace replay
}  // namespace map_aided_fusion
