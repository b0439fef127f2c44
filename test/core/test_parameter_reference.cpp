#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "map_aided_fusion/core/parameter_reference.hpp"

namespace map_aided_fusion {
namespace core {
namespace {

/// A struct whose validate() has one bound of every kind the reference writes.
struct Toy
{
  double ratio = 0.5;
  double length = 2.0;
  double offset = 0.0;
  double half_open = 1.0;
  double origin = std::numeric_limits<double>::quiet_NaN();
  int count = 3;
  bool flag = true;
  std::string name = "abc";
  void validate() const
  {
    requireUnit("ratio", ratio);
    requirePositive("length", length);
    if (!(half_open >= -5.0 && half_open < 5.0)) throw ParameterError("half_open", "outside [-5, 5)");
    if (!std::isnan(origin) && (origin < -90.0 || origin > 90.0)) throw ParameterError("origin", "outside");
    if (count < 1 || count > 10) throw ParameterError("count", "outside [1, 10]");
    if (half_open > length + 100.0) throw ParameterError("half_open", "never");
  }
};

template <class Get>
void forEachParam(Toy& p, Get&& get)
{
  get("ratio", p.ratio, { "", "a share" });
  get("length", p.length, { "m", "a length" });
  get("offset", p.offset, { "m", "anything" });
  get("half_open", p.half_open, { "", "half open" });
  get("origin", p.origin, { "deg", "NaN: automatic" });
  get("count", p.count, { "", "an int" });
  get("flag", p.flag, { "", "a flag" });
  get("name", p.name, { "", "a name" });
}

std::vector<ParamInfo> describeToy()
{
  return describeParams(Toy{}, Toy{}, [](Toy& p, auto&& get) { forEachParam(p, get); },
                        [](const Toy& p) { p.validate(); });
}

TEST(ParameterReference, RangesAreWhatValidateAccepts)
{
  const std::vector<ParamInfo> rows = describeToy();
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(rows[0].range, "[0, 1]");
  EXPECT_EQ(rows[1].range, "(0, ∞)");
  EXPECT_EQ(rows[2].range, "(−∞, ∞)");
  EXPECT_EQ(rows[3].range, "[-5, 5)");
  EXPECT_EQ(rows[4].range, "[-90, 90]") << "a NaN default is probed from an accepted anchor";
  EXPECT_EQ(rows[5].range, "[1, 10]");
  EXPECT_EQ(rows[6].range, "") << "flags and names have no range";
  EXPECT_EQ(rows[7].range, "");
}

TEST(ParameterReference, NamesTypesDefaultsAndDocs)
{
  const std::vector<ParamInfo> rows = describeToy();
  EXPECT_EQ(rows[1].name, "length");
  EXPECT_EQ(rows[1].type, "double");
  EXPECT_EQ(rows[1].default_value, "2");
  EXPECT_EQ(rows[1].unit, "m");
  EXPECT_EQ(rows[1].meaning, "a length");
  EXPECT_EQ(rows[4].default_value, ".nan");
  EXPECT_EQ(rows[5].type, "int");
  EXPECT_EQ(rows[6].default_value, "true");
  EXPECT_EQ(rows[7].default_value, "\"abc\"");
  const std::string table = markdownTable(rows);
  EXPECT_NE(table.find("| `half_open` | double | `1` |  | [-5, 5) | half open |"), std::string::npos) << table;
}

TEST(ParameterReference, DoublesInTheirShortestExactSpelling)
{
  EXPECT_EQ(formatDouble(100.0), "100");
  EXPECT_EQ(formatDouble(4.0e6), "4000000");
  EXPECT_EQ(formatDouble(0.1), "0.1");
  EXPECT_EQ(formatDouble(1e-5), "1e-05");
  EXPECT_EQ(formatDouble(-2.5), "-2.5");
  EXPECT_EQ(formatDouble(0.0), "0");
  EXPECT_EQ(std::stod(formatDouble(0.1 + 0.2)), 0.1 + 0.2);
}

TEST(ParameterReference, BisectionFindsTheExactEdge)
{
  const double edge = 0.012206286237412269;
  const ProbedRange r = probeDoubleRange(1.0, [&](double x) { return x >= edge && x <= 7.0; });
  ASSERT_TRUE(r.lowest && r.highest);
  EXPECT_EQ(*r.lowest, edge);
  EXPECT_EQ(*r.highest, 7.0);
  const ProbedRange open = probeDoubleRange(1.0, [](double x) { return x > 0.5; });
  EXPECT_EQ(formatRange(open, false), "(0.5, ∞)");
  const ProbedRange ints = probeIntRange(0, [](int x) { return x >= -3; });
  EXPECT_EQ(formatRange(ints, true), "[-3, ∞)");
}

}  // namespace
}  // namespace core
}  // namespace map_aided_fusion
