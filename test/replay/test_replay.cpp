// The offline replay behind `evaluate`, piece by piece (no ROS master): options, variants, the .npy writer, the
// configuration files, the report's pieces, and a whole replay of a short simulated drive.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <ros/time.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/replay/labelled_sweeps.hpp"
#include "map_aided_fusion/replay/npy.hpp"
#include "map_aided_fusion/replay/offline_replay.hpp"
#include "map_aided_fusion/replay/report.hpp"
#include "map_aided_fusion/replay/variants.hpp"
#include "map_aided_fusion/ros/sim_bag.hpp"
#include "map_aided_fusion/sim/scenario.hpp"
#include "map_aided_fusion/sim/simulator.hpp"

namespace map_aided_fusion {
namespace replay {
namespace {

namespace fs = std::filesystem;

const std::string kPackage = MAF_PACKAGE_DIR;

ReplayOptions parse(std::vector<std::string> args) { return parseReplayOptions(args); }

TEST(ReplayOptions, OutputBagsAreNamedOrLive)
{
  const ReplayOptions o = parse({ "--bag", "a.bag", "--output-bag", "live_paper=/tmp/x.bag", "--output-bag",
                                  "/data/run=2/live.bag", "--output-bag", "rec.bag" });
  ASSERT_EQ(o.output_bags.size(), 3u);
  EXPECT_EQ(o.output_bags[0], std::make_pair(std::string("live_paper"), std::string("/tmp/x.bag")));
  EXPECT_EQ(o.output_bags[1].first, "live") << "an '=' inside a directory name is part of the path";
  EXPECT_EQ(o.output_bags[1].second, "/data/run=2/live.bag");
  EXPECT_EQ(o.output_bags[2].first, "live");
}

TEST(ReplayOptions, NumbersOriginAndVariantList)
{
  const ReplayOptions o = parse({ "--bag", "a.bag", "--origin", "48.5,2.25", "--match-radius", "2.5", "--only",
                                  "default,paper", "--no-ablations", "--quiet" });
  ASSERT_TRUE(o.origin);
  EXPECT_EQ((*o.origin)[0], 48.5);
  EXPECT_EQ((*o.origin)[1], 2.25);
  EXPECT_EQ((*o.origin)[2], 0.0);
  EXPECT_EQ(o.match_radius, 2.5);
  EXPECT_EQ(o.only, (std::set<std::string>{ "default", "paper" }));
  EXPECT_FALSE(o.ablations);
  EXPECT_TRUE(o.quiet);
}

TEST(ReplayOptions, MistakesNameTheArgument)
{
  auto message = [](std::vector<std::string> args) {
    try
    {
      parseReplayOptions(args);
    }
    catch (const std::runtime_error& e)
    {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({ "--out", "x" }), "--bag is required");
  EXPECT_EQ(message({ "--bag" }), "--bag needs a value");
  EXPECT_EQ(message({ "--bag", "a", "--colour" }), "unknown argument --colour");
  EXPECT_EQ(message({ "--bag", "a", "--match-radius", "1m" }), "--match-radius: not a number: 1m");
  EXPECT_EQ(message({ "--bag", "a", "--match-radius", "11" }), "--match-radius must be in [0, 10] m");
  EXPECT_EQ(message({ "--bag", "a", "--origin", "48.5" }), "--origin needs LAT,LON[,ALT]");
  EXPECT_EQ(message({ "--bag", "a", "--only", "," }), "--only needs at least one variant name");
  EXPECT_EQ(message({ "--check-config" }), "accepted") << "checking the configuration needs no bag";
  EXPECT_TRUE(parse({ "--help" }).help);
}

TEST(ReplayVariants, TheConfiguredThePaperTheirAblationsAndOneRowPerAddedStep)
{
  const core::Profile configured;
  const std::vector<VariantSpec> all = variantSpecs(configured, true, true);
  std::vector<std::string> names;
  for (const auto& v : all) names.push_back(v.name);
  std::vector<std::string> expected{ "default", "paper", "default_no_prior", "paper_no_prior", "dempster", "yager",
                                     "single_rate", "no_counter" };
  for (const core::AddedStep& step : core::addedSteps())
    if (step.enabled(configured)) expected.push_back("default_without_" + std::string(step.name));
  expected.push_back("default_with_motion_spreading");   // the steps off by default
  expected.push_back("default_with_ground_cells_free");
  expected.push_back("default_with_ground_zones");       // the ground model that is not the default's
  EXPECT_EQ(names, expected);
  const VariantSpec& spreading = all[all.size() - 3];
  EXPECT_EQ(spreading.profile.map_grid.motion_share, core::kMotionSpreadingShare);
  EXPECT_EQ(configured.map_grid.motion_share, 0.0) << "off by default";
  const VariantSpec& ground_cells = all[all.size() - 2];
  EXPECT_TRUE(ground_cells.profile.scan_grid.ground_cells_free);
  EXPECT_FALSE(configured.scan_grid.ground_cells_free) << "off by default";
  EXPECT_EQ(all.back().profile.scan_grid.groundModel(), core::GroundModel::kZones);
  core::Profile zones = configured;
  zones.scan_grid.ground_model = "zones";
  zones.scan_grid.validate();
  EXPECT_EQ(all.back().profile.scan_grid.groundModelParams().zones_max_slope_deg,
            zones.scan_grid.groundModelParams().zones_max_slope_deg) << "only the model differs";
  EXPECT_TRUE(all[0].use_prior);
  EXPECT_FALSE(all[2].use_prior);
  for (const core::AddedStep& step : core::addedSteps())
    EXPECT_FALSE(step.enabled(all[1].profile)) << "the paper runs without " << step.name;
  EXPECT_EQ(all[4].profile.map_grid.fusion.rule, core::CombinationRule::kDempster);
  for (const auto& v : all)
    if (v.name.rfind("default_without_", 0) == 0)
    {
      const std::string step = v.name.substr(std::string("default_without_").size());
      for (const core::AddedStep& s : core::addedSteps())
        EXPECT_EQ(s.enabled(v.profile), s.enabled(configured) && s.name != step) << v.name << " and " << s.name;
    }
}

TEST(ReplayVariants, WithoutPriorOrAblationsAndOnly)
{
  const core::Profile configured;
  const auto plain = variantSpecs(configured, false, false);
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_FALSE(plain[0].use_prior);
  EXPECT_EQ(plain[1].name, "paper");
  const auto only = variantSpecs(configured, true, true, { "default_without_motion_margin" });
  ASSERT_EQ(only.size(), 1u);
  EXPECT_EQ(only[0].profile.map_grid.motion_margin, 0.0);
  EXPECT_TRUE(variantSpecs(configured, true, true, { "murphy" }).empty());
}

TEST(ReplayNpy, HeaderIsNumPyFormatOneAndDataFollowsAt64Bytes)
{
  const fs::path path = fs::temp_directory_path() / "maf_replay_test.npy";
  const std::int8_t data[6] = { 0, 1, 2, -1, 4, 5 };
  writeNpy(path, data, { 2, 3 }, "|i1");
  std::ifstream f(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_EQ(bytes.size() % 64, 6u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t header_len = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  const std::string dict = bytes.substr(10, header_len);
  EXPECT_NE(dict.find("'descr': '|i1', 'fortran_order': False, 'shape': (2, 3, ), }"), std::string::npos) << dict;
  EXPECT_EQ(dict.back(), '\n');
  EXPECT_EQ(bytes.substr(10 + header_len), std::string(reinterpret_cast<const char*>(data), 6));
  fs::remove(path);
}

TEST(ReplayConfiguration, TheShippedProfilesLoadAsTheirStructsSay)
{
  ReplayOptions o;
  o.fusion_config = kPackage + "/config/paper/fusion.yaml";
  o.scan_grid_config = kPackage + "/config/paper/scan_grid.yaml";
  o.prior_config = kPackage + "/config/paper/prior_grid.yaml";
  const ReplayConfiguration paper = loadReplayConfiguration(o);
  for (const core::AddedStep& step : core::addedSteps())
    EXPECT_FALSE(step.enabled(paper.configured)) << "config/paper enables " << step.name;
  o.fusion_config = kPackage + "/config/fusion.yaml";
  o.pose_covariance_topic = "/localisation/pose";
  const ReplayConfiguration c = loadReplayConfiguration(o);
  EXPECT_EQ(c.covariance_topic, "/localisation/pose") << "the option replaces the file's";
  EXPECT_EQ(c.covariance_type, "pose");
}

TEST(ReplayConfiguration, AnOutOfRangeValueIsNamed)
{
  const fs::path path = fs::temp_directory_path() / "maf_replay_bad_fusion.yaml";
  std::ofstream(path) << "alpha_static: 2.0\n";
  ReplayOptions o;
  o.fusion_config = path.string();
  try
  {
    loadReplayConfiguration(o);
    FAIL() << "alpha_static 2 accepted";
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "alpha_static");
  }
  fs::remove(path);
}

TEST(ReplayReport, DeskewSummaryListsEachStatus)
{
  EXPECT_EQ(deskewSummary({}), "none");
  EXPECT_EQ(deskewSummary({ { "applied", 580 }, { "time_out_of_sweep", 20 } }), "applied 580, time_out_of_sweep 20");
  EXPECT_EQ(moversSection({}, false), "");
  EXPECT_EQ(tracksSection({}), "");
}

TEST(OfflineReplay, AMissingBagIsAnErrorNamingIt)
{
  ReplayOptions o;
  o.bag = "/nonexistent/drive.bag";
  o.out = (fs::temp_directory_path() / "maf_replay_missing").string();
  try
  {
    runOfflineReplay(o);
    FAIL() << "no error";
  }
  catch (const std::exception& e)
  {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/drive.bag"), std::string::npos) << e.what();
  }
}

/// A 2 s drive of the bundled scenario, simulated once for the tests below.
const fs::path& shortDrive()
{
  static const fs::path bag = [] {
    const fs::path path = fs::temp_directory_path() / "maf_replay_short.bag";
    sim::Scenario sc = sim::loadScenario(kPackage + "/scenarios/default.yaml");
    sc.duration = 2.0;
    map_io::MapLoadParams mp;
    mp.file = sc.map_file;
    mp.origin_latitude = sc.map_origin_latitude;
    mp.origin_longitude = sc.map_origin_longitude;
    mp.origin_altitude = sc.map_origin_altitude;
    ros::Time::init();
    sim::Simulator simulator(sc, map_io::loadVectorMap(mp, nullptr));
    SimBagOptions options;
    options.path = path.string();
    writeSimulationBag(simulator, options);
    return path;
  }();
  return bag;
}

TEST(OfflineReplay, AShortDriveIsScoredPerCellWithTheConfiguredAndThePaperProfiles)
{
  ReplayOptions o;
  o.bag = shortDrive().string();
  o.out = (fs::temp_directory_path() / "maf_replay_out").string();
  o.fusion_config = kPackage + "/config/fusion.yaml";
  o.scan_grid_config = kPackage + "/config/scan_grid.yaml";
  o.prior_config = kPackage + "/config/prior_grid.yaml";
  o.map = kPackage + "/maps/town.osm";
  o.ablations = false;
  o.quiet = true;
  fs::remove_all(o.out);
  const ReplayReport report = runOfflineReplay(o);
  EXPECT_EQ(report.ground_truth, "simulator cells");
  EXPECT_EQ(report.scans, 20u) << "2 s at 10 Hz";
  EXPECT_EQ(report.variants, (std::vector<std::string>{ "default", "paper", "default_no_prior", "paper_no_prior" }));
  for (const char* file : { "metrics.json", "metrics.md", "scores.csv" })
    EXPECT_TRUE(fs::is_regular_file(fs::path(o.out) / file)) << file;
  std::ifstream md(fs::path(o.out) / "metrics.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("20 scans"), std::string::npos);
  EXPECT_NE(text.find(report.markdown), std::string::npos) << "metrics.md holds the report";
  // --only: the same default row, alone.
  ReplayOptions only = o;
  only.only = { "default" };
  only.out = o.out + "_only";
  const ReplayReport alone = runOfflineReplay(only);
  EXPECT_EQ(alone.variants, (std::vector<std::string>{ "default" }));
  std::ifstream a(fs::path(o.out) / "scores.csv"), b(fs::path(only.out) / "scores.csv");
  std::string line_a, line_b, header;
  std::getline(a, header);
  std::getline(b, line_b);
  std::getline(b, line_b);
  std::getline(a, line_a);
  EXPECT_EQ(line_a, line_b) << "a variant's scores do not depend on the others run beside it";
}

TEST(LabelledSweeps, ASweepIsScoredOnceBothHalvesArrivedInEitherOrder)
{
  // One cell of 1 m, decided F, holding a ground point and a point in the height gap.
  eval::ClassGrid decision;
  decision.geometry.resolution = 1.0;
  decision.geometry.width = decision.geometry.height = 1;
  decision.cells = { static_cast<std::int8_t>(core::CellClass::kUnknown) };
  eval::LabelledPoint ground;
  ground.p = core::Point2{ 0.5, 0.5 };
  ground.state = eval::LabelState::kStatic;
  ground.ground = true;
  const std::vector<eval::LabelledPoint> points{ ground, ground };
  const VariantSweep half{ decision,
                           { core::ReturnClass::kGround, core::ReturnClass::kHeightGap },
                           eval::EvidenceGrid{ decision.geometry, { eval::ScanEvidence::kUnreached } } };

  LabelledSweeps sweeps;
  sweeps.addPoints(1, points);  // the points first
  EXPECT_FALSE(sweeps.take(1).has_value());
  sweeps.addVariant(1, half);
  sweeps.addVariant(1, half);
  sweeps.addVariant(2, half);  // the decisions first
  EXPECT_EQ(sweeps.waiting(), 2u);
  std::optional<LabelledSweep> one = sweeps.take(1);
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->variants.size(), 2u);
  EXPECT_EQ(one->points.size(), 2u);
  EXPECT_FALSE(sweeps.take(1).has_value()) << "taken once";
  EXPECT_EQ(sweeps.waiting(), 1u);
  sweeps.addPoints(2, points);
  EXPECT_TRUE(sweeps.take(2).has_value());
  EXPECT_EQ(sweeps.waiting(), 0u);

  // Scoring one half: the gap return makes the unreached cell ambiguous, and the segmentation is counted.
  eval::PointLabelScorer scorer(1.0);
  scoreSweep(0.0, one->variants[0], one->points, scorer);
  EXPECT_EQ(one->variants[0].evidence.cells[0], eval::ScanEvidence::kAmbiguous);
  const auto m = scorer.summary();
  EXPECT_DOUBLE_EQ(m.at("ground_cells_not_f.ambiguous"), 1.0);
  EXPECT_DOUBLE_EQ(m.at("counts.segmentation_tp"), 1.0);
  EXPECT_DOUBLE_EQ(m.at("counts.segmentation_fn"), 1.0);
  VariantSweep mismatched = half;
  mismatched.classes.pop_back();
  EXPECT_THROW(scoreSweep(0.0, mismatched, points, scorer), std::invalid_argument);
}

}  // namespace
}  // namespace replay
}  // namespace map_aided_fusion
