/**
 * @file assignment.hpp
 * @brief Gated linear assignment (ROS-free): pairs rows with columns so that as many allowed pairs as possible are
 *        made and, among those pairings, the total cost is least. Used by the CLEAR-MOT scoring of tracks
 *        (eval/clear_mot.hpp) and by data association.
 */
#pragma once

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

/// Total cost of an assignment returned by solveAssignment() (allowed pairs only).
double assignmentCost(const CostMatrix& m, const std::vector<int>& row_to_col);

}  // namespace core
}  // namespace map_aided_fusion
