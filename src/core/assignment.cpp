#include "map_aided_fusion/core/assignment.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace map_aided_fusion {
namespace core {

CostMatrix::CostMatrix(int r, int c, double fill)
  : rows(r), cols(c), cost(static_cast<std::size_t>(r) * static_cast<std::size_t>(c), fill)
{
}

bool CostMatrix::allowed(int r, int c) const
{
  const double v = at(r, c);
  return std::isfinite(v) && v < kForbidden;
}

namespace {

/// Min-cost assignment of every row of an n × m matrix (n ≤ m, all costs finite): the classic potentials method.
std::vector<int> hungarian(const std::vector<double>& a, int n, int m)
{
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  auto cost = [&](int i, int j) { return a[static_cast<std::size_t>(i - 1) * m + (j - 1)]; };
  for (int i = 1; i <= n; ++i)
  {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do
    {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j)
      {
        if (used[j]) continue;
        const double cur = cost(i0, j) - u[i0] - v[j];
        if (cur < minv[j])
        {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta)
        {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j)
      {
        if (used[j])
        {
          u[p[j]] += delta;
          v[j] -= delta;
        }
        else
          minv[j] -= delta;
      }
      j0 = j1;
    } while (p[j0] != 0);
    do
    {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  return row_to_col;
}

}  // namespace

namespace {

/// The gated problem on the rows and columns of one connected component (indices into @p m); writes @p out.
void solveComponent(const CostMatrix& m, const std::vector<int>& rows, const std::vector<int>& cols, double big,
                    std::vector<int>& out)
{
  const bool transpose = rows.size() > cols.size();
  const int n = static_cast<int>(transpose ? cols.size() : rows.size());
  const int k = static_cast<int>(transpose ? rows.size() : cols.size());
  std::vector<double> a(static_cast<std::size_t>(n) * k);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
    {
      const int r = transpose ? rows[j] : rows[i], c = transpose ? cols[i] : cols[j];
      a[static_cast<std::size_t>(i) * k + j] = m.allowed(r, c) ? m.at(r, c) : big;
    }
  const std::vector<int> small_to_large = hungarian(a, n, k);
  for (int i = 0; i < n; ++i)
  {
    const int j = small_to_large[i];
    if (j < 0) continue;
    const int r = transpose ? rows[j] : rows[i], c = transpose ? cols[i] : cols[j];
    if (m.allowed(r, c)) out[r] = c;
  }
}

}  // namespace

std::vector<int> solveAssignment(const CostMatrix& m)
{
  if (m.rows < 0 || m.cols < 0 ||
      m.cost.size() != static_cast<std::size_t>(m.rows) * static_cast<std::size_t>(m.cols))
    throw std::invalid_argument("solveAssignment: the cost matrix does not hold rows x cols values");
  std::vector<int> out(m.rows, -1);
  if (m.rows == 0 || m.cols == 0) return out;
  // Rows and columns linked by allowed pairs form independent problems: solved one by one, the result is that of
  // the whole matrix (a pairing is the union of its components' pairings), at a fraction of the cost when the gate
  // leaves the matrix sparse.
  std::vector<int> parent(static_cast<std::size_t>(m.rows + m.cols));
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  double allowed_sum = 0.0;
  bool any = false;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (m.allowed(r, c))
      {
        if (m.at(r, c) < 0.0) throw std::invalid_argument("solveAssignment: negative cost");
        allowed_sum += m.at(r, c);
        any = true;
        const int a = root(r), b = root(m.rows + c);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
  if (!any) return out;
  // Larger than any pairing's allowed cost: one more allowed pair always lowers the total.
  const double big = 2.0 * allowed_sum + 1.0;
  std::vector<std::vector<int>> comp_rows(parent.size()), comp_cols(parent.size());
  for (int r = 0; r < m.rows; ++r) comp_rows[root(r)].push_back(r);
  for (int c = 0; c < m.cols; ++c) comp_cols[root(m.rows + c)].push_back(c);
  for (std::size_t k = 0; k < parent.size(); ++k)
    if (!comp_rows[k].empty() && !comp_cols[k].empty()) solveComponent(m, comp_rows[k], comp_cols[k], big, out);
  return out;
}

double assignmentCost(const CostMatrix& m, const std::vector<int>& row_to_col)
{
  double s = 0.0;
  for (int r = 0; r < static_cast<int>(row_to_col.size()); ++r)
    if (row_to_col[r] >= 0) s += m.at(r, row_to_col[r]);
  return s;
}

}  // namespace core
}  // namespace map_aided_fusion
