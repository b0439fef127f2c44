/**
 * @file assignment.hpp
 * @brief Gated linear assignment (ROS-free): pairs rows with columns so that as many allowed pairs as possible are
 *        made and, among those pairings, the total cost is least. Used by the CLEAR-MOT scoring of tracks
 *        (eval/clear_mot.hpp) and by data association.
 */
#pragma once

#include <cstddef>
#include <vector>

namespace map_aided_fusion {
namespace core {

/// Marks a pair that must not be made (outside the gate).
constexpr double kForbidden = 1e300;

/// A rows × columns cost matrix, row-major; a cost ≥ kForbidden (or not finite) forbids the pair.
struct CostMatrix
{
  int rows = 0;
  int cols = 0;
  std::vector<double> cost;  ///< rows * cols values
  CostMatrix() = default;
  CostMatrix(int r, int c, double fill = kForbidden);
  double& at(int r, int c) { return cost[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + c]; }
  double at(int r, int c) const { return cost[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + c]; }
  bool allowed(int r, int c) const;
};

/**
 * @brief Solves the gated assignment with the Hungarian method (shortest augmenting paths with potentials,
 *        O(n² m) for n ≤ m).
 *
 * Among all pairings (each row and column used at most once, only allowed pairs), it returns one with the largest
 * number of pairs and, among those, the least total cost. Forbidden pairs are replaced by a cost larger than the
 * sum of every allowed cost, so that any pairing with one more allowed pair is cheaper; they are then left out.
 *
 * @return for each row, the column it is paired with, or −1.
 * @throws std::invalid_argument when the matrix's size does not match rows × cols, or an allowed cost is negative.
 */
std::vector<int> solveAssignment(const CostMatrix& m);

/// An allowed pair of a sparse problem: row, column and its cost (≥ 0; ≥ kForbidden or not finite: not allowed).
struct GatedPair
{
  int row = 0;
  int col = 0;
  double cost = 0.0;
};

/// A rows × columns problem given by its allowed pairs only (each pair at most once): what a gate leaves.
struct SparseCosts
{
  int rows = 0;
  int cols = 0;
  std::vector<GatedPair> pairs;
};

/**
 * @brief The same problem as solveAssignment(const CostMatrix&), given by its allowed pairs: the pairing of the
 *        largest number of pairs and, among those, the least total cost; the same result as the dense matrix with
 *        those pairs allowed. Its cost grows with the pairs and the size of the components they link (solved one
 *        by one), not with rows × cols.
 * @param max_exact a component whose smaller side (rows or columns) is larger is solved greedily instead, the
 *        cheapest allowed pairs first (a bound on the cubic cost: clutter where every object gates with its
 *        neighbours), and counted in @p greedy when given. The default: every component exact.
 * @return for each row, the column it is paired with, or −1.
 * @throws std::invalid_argument when a pair lies outside rows × cols or has a negative cost.
 */
std::vector<int> solveAssignment(SparseCosts m, std::size_t max_exact = static_cast<std::size_t>(-1),
                                 std::size_t* greedy = nullptr);

/// Total cost of an assignment returned by solveAssignment() (allowed pairs only).
double assignmentCost(const CostMatrix& m, const std::vector<int>& row_to_col);

}  // namespace core
}  // namespace map_aided_fusion
