// PriorGridParams validation and the published window (cap on the message size).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <vector>
#include <set>
#include <string>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/profiles.hpp"
#include "map_aided_fusion/map_io/prior_grid_params.hpp"
#include "map_aided_fusion/map_io/yaml_params.hpp"

namespace {

using namespace map_aided_fusion;

map_io::PriorGridParams valid()
{
  map_io::PriorGridParams p;
  p.map.file = "town.osm";  // validate() does not open it
  return p;
}

core::GridGeometry extent()
{
  core::GridGeometry g;  // 100 m × 60 m at 0.5 m, from (−30, −20)
  g.resolution = 0.5;
  g.width = 200;
  g.height = 120;
  g.origin_x = -30.0;
  g.origin_y = -20.0;
  return g;
}

std::string offending(const map_io::PriorGridParams& p)
{
  try
  {
    p.validate();
  }
  catch (const core::ParameterError& e)
  {
    return e.parameter();
  }
  return "";
}

TEST(PriorGridParams, ValidationNamesTheParameter)
{
  EXPECT_EQ(offending(valid()), "");
  auto p = valid();
  p.resolution = 0.0;
  EXPECT_EQ(offending(p), "resolution");
  p = valid();
  p.beta.beta_road = 1.5;
  EXPECT_EQ(offending(p), "beta_road");
  p = valid();
  p.publish_size = -1.0;
  EXPECT_EQ(offending(p), "publish_size");
  p = valid();
  p.max_published_cells = 0.0;
  EXPECT_EQ(offending(p), "max_published_cells");
  p = valid();
  p.map.file.clear();
  EXPECT_EQ(offending(p), "map_file");
  p = valid();
  p.frame_id.clear();
  EXPECT_EQ(offending(p), "frame_id");
}

TEST(PriorGridParams, ConfigFileAndCodeNameTheSameKeys)
{
  const YAML::Node yaml = YAML::LoadFile(std::string(MAF_PACKAGE_DIR) + "/config/prior_grid.yaml");
  std::set<std::string> in_yaml, in_code;
  for (const auto& kv : yaml) in_yaml.insert(kv.first.as<std::string>());
  map_io::PriorGridParams p;
  map_io::forEachPriorGridParam(p, [&](const std::string& name, auto& value, const core::ParamDoc&) {
    in_code.insert(name);
    if (const YAML::Node n = yaml[name]) value = n.as<std::remove_reference_t<decltype(value)>>();
  });
  EXPECT_EQ(in_yaml, in_code);
  // The shipped configuration is valid once the launch file sets map_file, and holds the town's origin.
  EXPECT_EQ(p.map.file, "");
  p.map.file = "maps/town.osm";
  EXPECT_NO_THROW(p.validate());
  EXPECT_DOUBLE_EQ(p.map.origin_latitude, 49.4150);
  EXPECT_DOUBLE_EQ(p.resolution, 0.5);
  EXPECT_DOUBLE_EQ(p.max_published_cells, 4.0e6);
  EXPECT_DOUBLE_EQ(p.map.road_class_widths.at("service"), 4.0);
}

TEST(PublishedWindow, WholeExtentByDefault)
{
  bool cropped = true;
  const core::GridGeometry w = map_io::publishedWindow(extent(), valid(), cropped);
  EXPECT_FALSE(cropped);
  EXPECT_EQ(w, extent());
}

TEST(PublishedWindow, BoxAroundTheCentreClippedToTheExtent)
{
  auto p = valid();
  p.publish_size = 20.0;
  p.publish_centre_x = 65.0;  // box x ∈ [55, 75], extent ends at 70
  p.publish_centre_y = 0.0;   // y ∈ [−10, 10]
  bool cropped = true;
  const core::GridGeometry w = map_io::publishedWindow(extent(), p, cropped);
  EXPECT_FALSE(cropped);
  EXPECT_DOUBLE_EQ(w.origin_x, 55.0);
  EXPECT_EQ(w.width, 30);  // [55, 70]
  EXPECT_DOUBLE_EQ(w.origin_y, -10.0);
  EXPECT_EQ(w.height, 40);
  p.publish_centre_x = 500.0;
  EXPECT_THROW(map_io::publishedWindow(extent(), p, cropped), core::ParameterError);
}

TEST(PublishedWindow, CappedToASquareAroundTheCentre)
{
  auto p = valid();
  p.max_published_cells = 1600.0;  // 40 × 40 cells = 20 m × 20 m
  bool cropped = false;
  const core::GridGeometry w = map_io::publishedWindow(extent(), p, cropped);
  EXPECT_TRUE(cropped);
  EXPECT_EQ(w.width, 40);
  EXPECT_EQ(w.height, 40);
  EXPECT_DOUBLE_EQ(w.origin_x, -10.0);  // centred on the origin (0, 0)
  EXPECT_DOUBLE_EQ(w.origin_y, -10.0);
  // Near a corner the square slides inside the extent.
  p.publish_centre_x = 69.0;
  p.publish_centre_y = -19.0;
  const core::GridGeometry c = map_io::publishedWindow(extent(), p, cropped);
  EXPECT_DOUBLE_EQ(c.origin_x, 50.0);
  EXPECT_DOUBLE_EQ(c.origin_y, -20.0);
  EXPECT_LE(c.numCells(), 1600u);
}

}  // namespace

namespace {

/// name → value of every parameter of @p p (numbers and bools printed, strings as they are), through the shared
/// parameter list.
template <class Params>
std::map<std::string, std::string> valuesOf(Params p)
{
  std::map<std::string, std::string> out;
  core::forEachParam(p, [&](const std::string& name, auto& v, const core::ParamDoc&) {
    using T = std::decay_t<decltype(v)>;
    if constexpr (std::is_same_v<T, std::string>)
      out[name] = v;
    else if constexpr (std::is_same_v<T, std::vector<std::string>>)
      for (const std::string& x : v) out[name] += x + ";";
    else
      out[name] = std::to_string(static_cast<double>(v));
  });
  return out;
}

/// @p Params loaded from the YAML file @p path (every key of the parameter list must be in the file).
template <class Params>
Params loadFile(const std::string& path)
{
  const YAML::Node yaml = YAML::LoadFile(path);
  Params p;
  core::forEachParam(p, [&](const std::string& name, auto& value, const core::ParamDoc&) {
    const YAML::Node n = yaml[name];
    EXPECT_TRUE(n) << path << " lacks " << name;
    if (n) value = n.as<std::remove_reference_t<decltype(value)>>();
  });
  return p;
}

}  // namespace

TEST(Profiles, ConfigFilesHoldTheDefaultAndThePaperProfiles)
{
  const std::string dir = std::string(MAF_PACKAGE_DIR) + "/config/";
  const core::Profile def = core::defaultProfile(), paper = core::paperProfile();
  EXPECT_EQ(valuesOf(loadFile<core::MapGridParams>(dir + "fusion.yaml")), valuesOf(def.map_grid));
  EXPECT_EQ(valuesOf(loadFile<core::ScanGridParams>(dir + "scan_grid.yaml")), valuesOf(def.scan_grid));
  EXPECT_EQ(valuesOf(loadFile<core::MapGridParams>(dir + "paper/fusion.yaml")), valuesOf(paper.map_grid));
  EXPECT_EQ(valuesOf(loadFile<core::ScanGridParams>(dir + "paper/scan_grid.yaml")), valuesOf(paper.scan_grid));
  EXPECT_NE(valuesOf(paper.map_grid), valuesOf(def.map_grid));
  EXPECT_EQ(valuesOf(loadFile<core::TrackerParams>(dir + "fusion.yaml")), valuesOf(def.tracker));
  EXPECT_EQ(valuesOf(loadFile<core::TrackerParams>(dir + "paper/fusion.yaml")), valuesOf(paper.tracker));
  EXPECT_TRUE(def.tracker.enabled);
  EXPECT_FALSE(paper.tracker.enabled);
  // The PriorGrid: the profiles' options (cell test, map accuracy); every other key the same in both files.
  const YAML::Node a = YAML::LoadFile(dir + "prior_grid.yaml"), b = YAML::LoadFile(dir + "paper/prior_grid.yaml");
  map_io::PriorGridParams pa, pb;
  map_io::forEachPriorGridParam(pa, map_io::yamlReader(a));
  map_io::forEachPriorGridParam(pb, map_io::yamlReader(b));
  for (const auto& [file, want] : { std::make_pair(pa.options, def.prior), std::make_pair(pb.options, paper.prior) })
  {
    EXPECT_EQ(file.cell_test, want.cell_test);
    EXPECT_EQ(file.building_accuracy, want.building_accuracy);
    EXPECT_EQ(file.road_accuracy, want.road_accuracy);
  }
  EXPECT_EQ(paper.prior.cell_test, core::PriorCellTest::kCentre);
  const std::set<std::string> options{ "cell_test", "building_accuracy", "road_accuracy" };
  for (const auto& kv : a)
  {
    if (options.count(kv.first.as<std::string>())) continue;
    EXPECT_EQ(YAML::Dump(kv.second), YAML::Dump(b[kv.first.as<std::string>()])) << kv.first;
  }
}

TEST(Profiles, FusionFilesStateTheBytesPerCellTheCodeUses)
{
  const std::string want = "(" + std::to_string(core::MapGridParams::bytesPerCell()) + " bytes per cell)";
  for (const char* f : { "fusion.yaml", "paper/fusion.yaml", "learned/fusion.yaml" })
  {
    std::ifstream in(std::string(MAF_PACKAGE_DIR) + "/config/" + f);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(want), std::string::npos) << f << " does not say " << want;
  }
}

TEST(Profiles, IbeoScanGridDiffersFromTheDefaultOnlyWhereTheSensorNeedsIt)
{
  const std::string dir = std::string(MAF_PACKAGE_DIR) + "/config/";
  const core::ScanGridParams ibeo = loadFile<core::ScanGridParams>(dir + "ibeo/scan_grid.yaml");
  EXPECT_NO_THROW(ibeo.validate());
  const auto a = valuesOf(ibeo), b = valuesOf(core::defaultProfile().scan_grid);
  std::set<std::string> differ;
  for (const auto& kv : a)
    if (b.at(kv.first) != kv.second) differ.insert(kv.first);
  // The self box too: a sensor on the front bumper sees none of its vehicle; and the paper's 100 m grid.
  EXPECT_EQ(differ, (std::set<std::string>{ "azimuth_resolution_deg", "grid_size_x", "grid_size_y", "ground_model",
                                            "relative_height_limit", "self_box_max_x", "self_box_max_y",
                                            "self_box_min_x", "self_box_min_y" }));
  EXPECT_EQ(ibeo.groundModel(), core::GroundModel::kFlat);
  EXPECT_EQ(ibeo.grid_resolution, 0.5) << "the paper's cells";
  EXPECT_EQ(ibeo.grid_size_x, 100.0) << "the paper's window";
}

namespace {

/// The parameters whose values differ between @p x and @p y.
template <class Params>
std::set<std::string> differing(const Params& x, const Params& y)
{
  const auto a = valuesOf(x), b = valuesOf(y);
  std::set<std::string> out;
  for (const auto& kv : a)
    if (b.at(kv.first) != kv.second) out.insert(kv.first);
  return out;
}

}  // namespace

// config/ibeo/fusion.yaml is config/fusion.yaml but for the tracker's smallest cluster: four layers give an object a
// few returns per column.
TEST(Profiles, IbeoFusionDiffersFromTheDefaultOnlyInTheSmallestCluster)
{
  const std::string dir = std::string(MAF_PACKAGE_DIR) + "/config/";
  const core::Profile def = core::defaultProfile();
  const core::MapGridParams grid = loadFile<core::MapGridParams>(dir + "ibeo/fusion.yaml");
  const core::TrackerParams tracker = loadFile<core::TrackerParams>(dir + "ibeo/fusion.yaml");
  EXPECT_NO_THROW(grid.validate());
  EXPECT_NO_THROW(tracker.validate());
  EXPECT_TRUE(differing(grid, def.map_grid).empty());
  EXPECT_EQ(differing(tracker, def.tracker), (std::set<std::string>{ "tracker_min_cluster_points" }));
  EXPECT_EQ(tracker.min_cluster_points, 4);
  const YAML::Node base = YAML::LoadFile(dir + "fusion.yaml"), ibeo = YAML::LoadFile(dir + "ibeo/fusion.yaml");
  EXPECT_EQ(base.size(), ibeo.size()) << "every key of config/fusion.yaml, and no other";
  for (const auto& kv : base) EXPECT_TRUE(ibeo[kv.first.as<std::string>()].IsDefined()) << kv.first.as<std::string>();
}

TEST(Profiles, LearnedProfileIsCompleteValidAndKeepsTheIbeoSensorLines)
{
  // config/learned/ is written by `learning/tune --report`: every key of config/, validated, and its IBEO ScanGrid
  // and fusion differ from its ScanGrid and fusion only where the sensor needs it.
  const std::string dir = std::string(MAF_PACKAGE_DIR) + "/config/learned/";
  const core::MapGridParams fusion = loadFile<core::MapGridParams>(dir + "fusion.yaml");
  EXPECT_NO_THROW(fusion.validate());
  const core::ScanGridParams scan = loadFile<core::ScanGridParams>(dir + "scan_grid.yaml");
  const core::ScanGridParams ibeo = loadFile<core::ScanGridParams>(dir + "ibeo/scan_grid.yaml");
  EXPECT_NO_THROW(scan.validate());
  EXPECT_NO_THROW(ibeo.validate());
  // Where config/ibeo/ differs from config/ (the sensor's lines), and nowhere else.
  const std::string config = std::string(MAF_PACKAGE_DIR) + "/config/";
  const std::set<std::string> sensor = differing(loadFile<core::ScanGridParams>(config + "ibeo/scan_grid.yaml"),
                                                 loadFile<core::ScanGridParams>(config + "scan_grid.yaml"));
  EXPECT_TRUE(sensor.count("ground_model") && sensor.count("azimuth_resolution_deg"));
  EXPECT_EQ(differing(ibeo, scan), sensor);
  const core::MapGridParams ibeo_fusion = loadFile<core::MapGridParams>(dir + "ibeo/fusion.yaml");
  const core::TrackerParams tracker = loadFile<core::TrackerParams>(dir + "fusion.yaml");
  const core::TrackerParams ibeo_tracker = loadFile<core::TrackerParams>(dir + "ibeo/fusion.yaml");
  EXPECT_NO_THROW(ibeo_fusion.validate());
  EXPECT_NO_THROW(ibeo_tracker.validate());
  EXPECT_TRUE(differing(ibeo_fusion, fusion).empty()) << "the learned fusion values in the IBEO file too";
  EXPECT_EQ(differing(ibeo_tracker, tracker),
            differing(loadFile<core::TrackerParams>(config + "ibeo/fusion.yaml"),
                      loadFile<core::TrackerParams>(config + "fusion.yaml")));
  // Every key of config/ (`learning/tune --refresh-profile` re-renders a profile when config/ gains keys).
  for (const char* f : { "fusion.yaml", "scan_grid.yaml", "prior_grid.yaml", "ibeo/scan_grid.yaml", "ibeo/fusion.yaml" })
  {
    const YAML::Node base = YAML::LoadFile(config + f), learned = YAML::LoadFile(dir + f);
    for (const auto& kv : base)
      EXPECT_TRUE(learned[kv.first.as<std::string>()].IsDefined()) << f << ": " << kv.first.as<std::string>();
  }
  map_io::PriorGridParams prior;
  map_io::forEachPriorGridParam(prior, map_io::yamlReader(YAML::LoadFile(dir + "prior_grid.yaml")));
  EXPECT_NO_THROW(prior.beta.validate());
  EXPECT_NO_THROW(prior.options.validate());
  EXPECT_NE(valuesOf(fusion), valuesOf(core::defaultProfile().map_grid)) << "learned values, not a copy of config/";
}
