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

namespace {

/// The allowed pairs of @p m, in an order other than row-major (the sparse solver must not depend on it).
SparseCosts sparseOf(const CostMatrix& m, std::mt19937& rng)
{
  SparseCosts s;
  s.rows = m.rows;
  s.cols = m.cols;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (m.allowed(r, c)) s.pairs.push_back(GatedPair{ r, c, m.at(r, c) });
  std::shuffle(s.pairs.begin(), s.pairs.end(), rng);
  return s;
}

}  // namespace

TEST(Assignment, SparsePairsGiveTheDenseMatrixsPairing)
{
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> cost(0.0, 10.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int cases = 0;
  for (int rows = 0; rows <= 12; rows += 3)
    for (int cols = 0; cols <= 12; cols += 4)
      for (double forbidden_share : { 0.0, 0.5, 0.9 })
      {
        CostMatrix m(rows, cols);
        for (double& c : m.cost) c = u(rng) < forbidden_share ? kForbidden : cost(rng);
        EXPECT_EQ(solveAssignment(sparseOf(m, rng)), solveAssignment(m)) << rows << "x" << cols;
        ++cases;
      }
  EXPECT_EQ(cases, 5 * 4 * 3);
  SparseCosts bad;
  bad.rows = bad.cols = 2;
  bad.pairs = { GatedPair{ 0, 2, 1.0 } };
  EXPECT_THROW(solveAssignment(bad), std::invalid_argument);
  bad.pairs = { GatedPair{ 1, 1, -0.5 } };
  EXPECT_THROW(solveAssignment(bad), std::invalid_argument);
  bad.pairs = { GatedPair{ 1, 1, kForbidden } };
  EXPECT_EQ(solveAssignment(bad), (std::vector<int>{ -1, -1 }));
}

TEST(Assignment, ComponentsAboveTheExactBoundAreSolvedGreedilyAndCounted)
{
  // Two components: {rows 0, 1; columns 0, 1} (where greedy and the optimum differ, HandSolvedSquareCase) and
  // {row 2; column 2}. With max_exact 1 the first is greedy: row 0 takes its cheapest column 0 (1), row 1 column 1
  // (10); the single pair stays exact.
  SparseCosts s;
  s.rows = s.cols = 3;
  s.pairs = { { 0, 0, 1.0 }, { 0, 1, 2.0 }, { 1, 0, 3.0 }, { 1, 1, 10.0 }, { 2, 2, 4.0 } };
  std::size_t greedy = 0;
  EXPECT_EQ(solveAssignment(s), (std::vector<int>{ 1, 0, 2 }));
  EXPECT_EQ(solveAssignment(s, 1, &greedy), (std::vector<int>{ 0, 1, 2 }));
  EXPECT_EQ(greedy, 1u);
  greedy = 0;
  EXPECT_EQ(solveAssignment(s, 2, &greedy), (std::vector<int>{ 1, 0, 2 }));
  EXPECT_EQ(greedy, 0u);
}
