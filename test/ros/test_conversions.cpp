// Round trips between core grids and ROS messages, without a ROS master.
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/ros/conversions.hpp"
#include "../core/test_util.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::core;

namespace {

std_msgs::Header header()
{
  std_msgs::Header h;
  h.frame_id = "map";
  h.stamp.sec = 12;
  h.stamp.nsec = 345;
  return h;
}

MapMassGrid randomGrid(std::mt19937& rng)
{
  MapMassGrid g(GridGeometry{ 0.2, 13, 9, 10.0, -4.0 });
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    g.setCell(i, maf_test::randomMass<FrameMG>(rng, 4, false, true));
    g.zeta(i) = static_cast<float>(i) / g.numCells();
  }
  return g;
}

}  // namespace

TEST(Conversions, MapMetaDataRoundTrip)
{
  const GridGeometry g{ 0.2, 13, 9, 10.0, -4.0 };
  nav_msgs::MapMetaData info;
  GridConversions::toMapMetaData(g, info);
  EXPECT_EQ(info.width, 13u);
  EXPECT_EQ(info.height, 9u);
  EXPECT_DOUBLE_EQ(info.origin.orientation.w, 1.0);
  const auto back = GridConversions::fromMapMetaData(info);
  EXPECT_NEAR(back.resolution, 0.2, 1e-7);
  EXPECT_EQ(back.width, 13);
  EXPECT_EQ(back.height, 9);
  EXPECT_DOUBLE_EQ(back.origin_x, 10.0);
  EXPECT_DOUBLE_EQ(back.origin_y, -4.0);
  info.origin.orientation.z = 0.7;
  EXPECT_THROW(GridConversions::fromMapMetaData(info), ConversionError);
}

TEST(Conversions, EvidentialGridRoundTripIsExact)
{
  std::mt19937 rng(3);
  const auto grid = randomGrid(rng);
  for (auto sel : { PlaneSelection::kNonZero, PlaneSelection::kAll })
  {
    EvidentialGrid msg;
    GridConversions::toMessage(grid, header(), msg, sel, true);
    EXPECT_EQ(msg.header.frame_id, "map");
    ASSERT_EQ(msg.classes.size(), 5u);
    EXPECT_EQ(msg.classes[3], "S");
    if (sel == PlaneSelection::kAll) { EXPECT_EQ(msg.focal_sets.size(), 29u) << "the focal sets a MapGrid stores"; }
    EXPECT_EQ(msg.masses.size(), msg.focal_sets.size() * grid.numCells());
    MapMassGrid back;
    back.reset(GridGeometry{ 0.2, 13, 9, 10.0, -4.0 });
    GridConversions::fromMessage(msg, back);
    EXPECT_NEAR(back.geometry().resolution, 0.2, 1e-7);
    for (std::size_t i = 0; i < grid.numCells(); ++i)
    {
      for (int a = 0; a < 32; ++a)
        if (MapMassGrid::stored(static_cast<Subset>(a)))
        {
          ASSERT_EQ(back.at(static_cast<Subset>(a), i), grid.at(static_cast<Subset>(a), i));
        }
      ASSERT_EQ(back.zeta(i), grid.zeta(i));
    }
  }
}

TEST(Conversions, ScanGridRoundTrip)
{
  std::mt19937 rng(4);
  ScanMassGrid grid(GridGeometry{ 0.5, 8, 6, -2.0, -1.5 });
  for (std::size_t i = 0; i < grid.numCells(); ++i) grid.setCell(i, maf_test::randomMass<FrameSG>(rng, 3));
  EvidentialGrid msg;
  GridConversions::toMessage(grid, header(), msg);
  EXPECT_EQ(msg.classes, (std::vector<std::string>{ "F", "O" }));
  EXPECT_TRUE(msg.counter.empty());
  ScanMassGrid back;
  GridConversions::fromMessage(msg, back);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
    for (int a = 0; a < 4; ++a) ASSERT_EQ(back.at(static_cast<Subset>(a), i), grid.at(static_cast<Subset>(a), i));
}

TEST(Conversions, ScanFromMessageCopiesAsFromMessageAndNamesTheFirstCellThatIsNoMassFunction)
{
  // More cells than one chunk of the check, so that a bad cell in a later chunk is found there.
  std::mt19937 rng(9);
  const int width = 150, height = 130;
  ASSERT_GT(static_cast<std::size_t>(width * height), GridConversions::kScanCheckChunk);
  ScanMassGrid grid(GridGeometry{ 0.5, width, height, -2.0, -1.5 });
  for (std::size_t i = 0; i < grid.numCells(); ++i) grid.setCell(i, maf_test::randomMass<FrameSG>(rng, 3));
  EvidentialGrid msg;
  GridConversions::toMessage(grid, header(), msg, PlaneSelection::kAll);
  ScanMassGrid back, checked;
  GridConversions::fromMessage(msg, back);
  // A grid holding an earlier scan, and something in its counter, is overwritten.
  checked = ScanMassGrid(grid.geometry());
  for (std::size_t i = 0; i < checked.numCells(); ++i)
  {
    checked.setCell(i, MassSG{ { FrameSG::kO, 1.0 } });
    checked.zeta(i) = 7.0f;
  }
  GridConversions::scanFromMessage(msg, checked);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    for (int a = 0; a < 4; ++a) ASSERT_EQ(checked.at(static_cast<Subset>(a), i), back.at(static_cast<Subset>(a), i));
    ASSERT_EQ(checked.zeta(i), 0.0f);
  }
  EXPECT_EQ(checked.geometry(), grid.geometry());

  // Each kind of bad cell, in the second chunk: the error names the first one.
  const std::size_t n = grid.numCells(), bad = GridConversions::kScanCheckChunk + 17;
  auto plane = [&](EvidentialGrid& m, Subset a) {
    for (std::size_t k = 0; k < m.focal_sets.size(); ++k)
      if (m.focal_sets[k] == a) return m.masses.data() + k * n;
    return static_cast<float*>(nullptr);
  };
  auto expectRejected = [&](const std::function<void(EvidentialGrid&)>& spoil, const char* what) {
    EvidentialGrid m = msg;
    spoil(m);
    try
    {
      GridConversions::scanFromMessage(m, checked);
      ADD_FAILURE() << what << ": accepted";
    }
    catch (const ConversionError& e)
    {
      EXPECT_NE(std::string(e.what()).find("cell " + std::to_string(bad) + " is not a mass function"), std::string::npos)
          << what << ": " << e.what();
    }
  };
  expectRejected([&](EvidentialGrid& m) { plane(m, FrameSG::kF)[bad] += 0.01f; }, "sum 1.01");
  expectRejected([&](EvidentialGrid& m) { plane(m, FrameSG::kOmega)[bad] = std::nanf(""); }, "NaN");
  expectRejected(
      [&](EvidentialGrid& m) {
        plane(m, FrameSG::kO)[bad] -= 0.5f;
        plane(m, FrameSG::kEmpty)[bad] -= 0.5f;
        plane(m, FrameSG::kOmega)[bad] += 1.0f;
      },
      "a negative mass");
  expectRejected(
      [&](EvidentialGrid& m) {
        plane(m, FrameSG::kF)[bad] += 0.5f;
        plane(m, FrameSG::kOmega)[n - 1] = -1.0f;
      },
      "two bad cells");
  // Rounding within the tolerance passes.
  EvidentialGrid close = msg;
  plane(close, FrameSG::kOmega)[bad] += 0.5f * GridConversions::kScanMassTolerance;
  EXPECT_NO_THROW(GridConversions::scanFromMessage(close, checked));
  // And the message checks of fromMessage() still come first.
  EvidentialGrid repeated = msg;
  repeated.focal_sets[1] = repeated.focal_sets[0];
  EXPECT_THROW(GridConversions::scanFromMessage(repeated, checked), ConversionError);
}

TEST(Conversions, MalformedMessagesAreRejectedWithReasons)
{
  std::mt19937 rng(5);
  const auto grid = randomGrid(rng);
  EvidentialGrid msg;
  GridConversions::toMessage(grid, header(), msg);
  MapMassGrid back;

  auto wrong_classes = msg;
  wrong_classes.classes = { "F", "O" };
  EXPECT_THROW(GridConversions::fromMessage(wrong_classes, back), ConversionError);
  ScanMassGrid scan;
  EXPECT_THROW(GridConversions::fromMessage(msg, scan), ConversionError);

  auto short_masses = msg;
  short_masses.masses.pop_back();
  try
  {
    GridConversions::fromMessage(short_masses, back);
    FAIL();
  }
  catch (const ConversionError& e)
  {
    EXPECT_NE(std::string(e.what()).find("masses"), std::string::npos);
  }
  auto bad_set = msg;
  bad_set.focal_sets[0] = 40;
  EXPECT_THROW(GridConversions::fromMessage(bad_set, back), ConversionError);
  auto repeated = msg;
  repeated.focal_sets[1] = repeated.focal_sets[0];
  EXPECT_THROW(GridConversions::fromMessage(repeated, back), ConversionError);
  auto bad_counter = msg;
  bad_counter.counter.assign(3, 0.0f);
  EXPECT_THROW(GridConversions::fromMessage(bad_counter, back), ConversionError);
  // A focal set the MapGrid never holds ({C, V}): zero planes of it are accepted, mass on it is refused by name.
  auto unreachable = msg;
  unreachable.focal_sets.push_back(FrameMG::kC | FrameMG::kV);
  unreachable.masses.resize(unreachable.masses.size() + grid.numCells(), 0.0f);
  EXPECT_NO_THROW(GridConversions::fromMessage(unreachable, back));
  unreachable.masses.back() = 0.25f;
  try
  {
    GridConversions::fromMessage(unreachable, back);
    FAIL() << "mass on {C, V} was accepted";
  }
  catch (const ConversionError& e)
  {
    EXPECT_NE(std::string(e.what()).find("CV"), std::string::npos) << e.what();
  }
}

TEST(Conversions, PriorWindowRoundTrip)
{
  const GridGeometry g{ 0.5, 4, 3, 0.0, 0.0 };
  PriorWindow p(g);
  const PriorConfidence beta{ 0.9, 0.8, 0.7 };
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    const auto m = priorMass(static_cast<PriorClass>(i % 4), beta);
    p.building[i] = m[FrameMG::kBuilding];
    p.road[i] = m[FrameMG::kRoad];
    p.other[i] = m[FrameMG::kOther];
  }
  EvidentialGrid msg;
  GridConversions::toMessage(p, header(), msg);
  EXPECT_EQ(msg.focal_sets, (std::vector<std::uint8_t>{ FrameMG::kC, FrameMG::kRoad, FrameMG::kOther, FrameMG::kOmega }));
  PriorWindow back;
  GridConversions::fromMessage(msg, back);
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    EXPECT_EQ(back.building[i], p.building[i]);
    EXPECT_EQ(back.road[i], p.road[i]);
    EXPECT_EQ(back.other[i], p.other[i]);
    EXPECT_NEAR(msg.masses[3 * g.numCells() + i], 1.0f - p.building[i] - p.road[i] - p.other[i], 1e-7);
  }
  // A MapGrid is not a prior.
  std::mt19937 rng(6);
  EvidentialGrid map_msg;
  GridConversions::toMessage(randomGrid(rng), header(), map_msg);
  EXPECT_THROW(GridConversions::fromMessage(map_msg, back), ConversionError);
}

TEST(Conversions, PignisticOccupancyScalesAndMarksUnknown)
{
  MapMassGrid grid(GridGeometry{ 1.0, 3, 1, 0.0, 0.0 });
  grid.setCell(0, MassMG{ { FrameMG::kF, 0.5 }, { FrameMG::kS | FrameMG::kV, 0.3 }, { FrameMG::kOmega, 0.2 } });
  grid.setCell(1, MassMG{ { FrameMG::kV, 1.0 } });
  // cell 2 stays vacuous
  PignisticPlanes betp;
  pignisticGrid(grid, betp);
  nav_msgs::OccupancyGrid occ;
  GridConversions::pignisticToOccupancy(grid, betp, 0, header(), occ);
  EXPECT_EQ(occ.data, (std::vector<std::int8_t>{ 54, 0, -1 }));
  GridConversions::pignisticToOccupancy(grid, betp, 4, header(), occ);
  EXPECT_EQ(occ.data, (std::vector<std::int8_t>{ 19, 100, -1 }));
  EXPECT_EQ(occ.header.frame_id, "map");
  EXPECT_EQ(occ.info.width, 3u);
  EXPECT_THROW(GridConversions::pignisticToOccupancy(grid, betp, 5, header(), occ), ConversionError);
}

TEST(Conversions, ScanOccupancy)
{
  ScanMassGrid grid(GridGeometry{ 1.0, 3, 1, 0.0, 0.0 });
  grid.setCell(0, MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } });
  grid.setCell(1, MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } });
  nav_msgs::OccupancyGrid occ;
  GridConversions::scanToOccupancy(grid, header(), occ);
  EXPECT_EQ(occ.data, (std::vector<std::int8_t>{ 15, 90, -1 }));
}
