#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>

#include "map_aided_fusion/core/assignment.hpp"

using namespace map_aided_fusion::core;

namespace {

/// The best pairing by exhaustive search: most allowed pairs, then least cost.
std::pair<int, double> bruteForce(const CostMatrix& m)
{
  int best_pairs = 0;
  double best_cost = 0.0;
  std::vector<char> used(m.cols, 0);
  std::function<void(int, int, double)> go = [&](int r, int pairs, double cost) {
    if (r == m.rows)
    {
      if (pairs > best_pairs || (pairs == best_pairs && cost < best_cost))
      {
        best_pairs = pairs;
        best_cost = cost;
      }
      return;
    }
    go(r + 1, pairs, cost);  // row r unpaired
    for (int c = 0; c < m.cols; ++c)
      if (!used[c] && m.allowed(r, c))
      {
        used[c] = 1;
        go(r + 1, pairs + 1, cost + m.at(r, c));
        used[c] = 0;
      }
  };
  go(0, 0, 0.0);
  return { best_pairs, best_cost };
}

void expectValid(const CostMatrix& m, const std::vector<int>& a)
{
  ASSERT_EQ(static_cast<int>(a.size()), m.rows);
  std::vector<char> used(m.cols, 0);
  for (int r = 0; r < m.rows; ++r)
  {
    if (a[r] < 0) continue;
    ASSERT_LT(a[r], m.cols);
    EXPECT_TRUE(m.allowed(r, a[r])) << "row " << r << " paired outside the gate";
    EXPECT_FALSE(used[a[r]]) << "column " << a[r] << " used twice";
    used[a[r]] = 1;
  }
}

}  // namespace

TEST(Assignment, HandSolvedSquareCase)
{
  // Greedy (row 0 takes its cheapest, column 0) gives 1 + 10 = 11; the optimum is 2 + 3 = 5.
  CostMatrix m(2, 2);
  m.at(0, 0) = 1.0;
  m.at(0, 1) = 2.0;
  m.at(1, 0) = 3.0;
  m.at(1, 1) = 10.0;
  const auto a = solveAssignment(m);
  EXPECT_EQ(a, (std::vector<int>{ 1, 0 }));
  EXPECT_DOUBLE_EQ(assignmentCost(m, a), 5.0);
}

TEST(Assignment, MorePairsBeatsLowerCost)
{
  // Row 0 could take column 0 at 0.1, but then row 1 (allowed only on column 0) stays unpaired.
  CostMatrix m(2, 2);
  m.at(0, 0) = 0.1;
  m.at(0, 1) = 5.0;
  m.at(1, 0) = 5.0;
  const auto a = solveAssignment(m);
  EXPECT_EQ(a, (std::vector<int>{ 1, 0 }));
}

TEST(Assignment, ForbiddenPairsAreNeverMadeAndEmptyInputsWork)
{
  CostMatrix all_forbidden(3, 2);
  EXPECT_EQ(solveAssignment(all_forbidden), (std::vector<int>{ -1, -1, -1 }));
  EXPECT_TRUE(solveAssignment(CostMatrix(0, 4)).empty());
  EXPECT_EQ(solveAssignment(CostMatrix(2, 0)), (std::vector<int>{ -1, -1 }));
  CostMatrix inf(1, 1, std::numeric_limits<double>::infinity());
  EXPECT_EQ(solveAssignment(inf), (std::vector<int>{ -1 }));
  CostMatrix nan(1, 1, std::nan(""));
  EXPECT_EQ(solveAssignment(nan), (std::vector<int>{ -1 }));
}

TEST(Assignment, RejectsMalformedInput)
{
  CostMatrix m(2, 2, 1.0);
  m.cost.pop_back();
  EXPECT_THROW(solveAssignment(m), std::invalid_argument);
  CostMatrix negative(1, 1, -1.0);
  EXPECT_THROW(solveAssignment(negative), std::invalid_argument);
}

TEST(Assignment, EqualsBruteForceOnRandomGatedMatrices)
{
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> cost(0.0, 10.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int cases = 0;
  for (int rows = 0; rows <= 6; ++rows)
    for (int cols = 0; cols <= 6; ++cols)
      for (double forbidden_share : { 0.0, 0.3, 0.7 })
        for (int rep = 0; rep < 8; ++rep)
        {
          CostMatrix m(rows, cols);
          for (double& c : m.cost) c = u(rng) < forbidden_share ? kForbidden : std::round(cost(rng) * 4.0) / 4.0;
          const auto a = solveAssignment(m);
          expectValid(m, a);
          const auto [pairs, best] = bruteForce(m);
          const int made = static_cast<int>(std::count_if(a.begin(), a.end(), [](int c) { return c >= 0; }));
          ASSERT_EQ(made, pairs) << rows << "x" << cols << " case " << rep;
          ASSERT_NEAR(assignmentCost(m, a), best, 1e-9) << rows << "x" << cols << " case " << rep;
          ++cases;
        }
  EXPECT_EQ(cases, 7 * 7 * 3 * 8);
}
