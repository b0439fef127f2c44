#include "map_aided_fusion/core/assignment.hpp"

#include <algorithm>
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

/// The gated problem on the rows and columns of one connected component of @p m (indices into it): a dense matrix
/// of the component's allowed costs, @p big elsewhere, solved by hungarian(); writes @p out. @p row_begin indexes
/// m.pairs by row; @p col_local is scratch of m.cols entries, all −1, left so.
void solveComponent(const SparseCosts& m, const std::vector<std::size_t>& row_begin, const std::vector<int>& rows,
                    const std::vector<int>& cols, double big, std::vector<int>& col_local, std::vector<int>& out)
{
  const bool transpose = rows.size() > cols.size();
  const int n = static_cast<int>(transpose ? cols.size() : rows.size());
  const int k = static_cast<int>(transpose ? rows.size() : cols.size());
  for (std::size_t j = 0; j < cols.size(); ++j) col_local[cols[j]] = static_cast<int>(j);
  std::vector<double> a(static_cast<std::size_t>(n) * k, big);
  std::vector<char> allowed(a.size(), 0);
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t e = row_begin[rows[i]]; e < row_begin[rows[i] + 1]; ++e)
    {
      const std::size_t j = static_cast<std::size_t>(col_local[m.pairs[e].col]);
      const std::size_t at = transpose ? j * k + i : i * k + j;
      a[at] = m.pairs[e].cost;
      allowed[at] = 1;
    }
  for (const int c : cols) col_local[c] = -1;
  const std::vector<int> small_to_large = hungarian(a, n, k);
  for (int i = 0; i < n; ++i)
  {
    const int j = small_to_large[i];
    if (j < 0 || !allowed[static_cast<std::size_t>(i) * k + j]) continue;
    const int r = transpose ? rows[j] : rows[i], c = transpose ? cols[i] : cols[j];
    out[r] = c;
  }
}

}  // namespace

std::vector<int> solveAssignment(const CostMatrix& m)
{
  if (m.rows < 0 || m.cols < 0 ||
      m.cost.size() != static_cast<std::size_t>(m.rows) * static_cast<std::size_t>(m.cols))
    throw std::invalid_argument("solveAssignment: the cost matrix does not hold rows x cols values");
  SparseCosts sparse;
  sparse.rows = m.rows;
  sparse.cols = m.cols;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (m.allowed(r, c)) sparse.pairs.push_back(GatedPair{ r, c, m.at(r, c) });
  return solveAssignment(std::move(sparse));
}

std::vector<int> solveAssignment(SparseCosts m, std::size_t max_exact, std::size_t* greedy)
{
  if (m.rows < 0 || m.cols < 0) throw std::invalid_argument("solveAssignment: negative size");
  std::vector<int> out(m.rows, -1);
  for (const GatedPair& e : m.pairs)
  {
    if (e.row < 0 || e.row >= m.rows || e.col < 0 || e.col >= m.cols)
      throw std::invalid_argument("solveAssignment: a pair outside rows x cols");
    if (e.cost < 0.0) throw std::invalid_argument("solveAssignment: negative cost");
  }
  // Forbidden pairs are no pairs; the order of a dense matrix's (row-major) fixes the sum below to the last bit.
  m.pairs.erase(std::remove_if(m.pairs.begin(), m.pairs.end(),
                               [](const GatedPair& e) { return !(std::isfinite(e.cost) && e.cost < kForbidden); }),
                m.pairs.end());
  std::sort(m.pairs.begin(), m.pairs.end(),
            [](const GatedPair& a, const GatedPair& b) { return a.row != b.row ? a.row < b.row : a.col < b.col; });
  if (m.pairs.empty()) return out;
  // Rows and columns linked by allowed pairs form independent problems: solved one by one, the result is that of
  // the whole matrix (a pairing is the union of its components' pairings), at a cost that grows with the size of
  // the components, not with rows × cols.
  std::vector<int> parent(static_cast<std::size_t>(m.rows + m.cols));
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  double allowed_sum = 0.0;
  std::vector<std::size_t> row_begin(static_cast<std::size_t>(m.rows) + 1, 0);
  for (const GatedPair& e : m.pairs)
  {
    allowed_sum += e.cost;
    ++row_begin[static_cast<std::size_t>(e.row) + 1];
    const int a = root(e.row), b = root(m.rows + e.col);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  for (std::size_t r = 0; r < static_cast<std::size_t>(m.rows); ++r) row_begin[r + 1] += row_begin[r];
  // Larger than any pairing's allowed cost: one more allowed pair always lowers the total.
  const double big = 2.0 * allowed_sum + 1.0;
  std::vector<std::vector<int>> comp_rows(parent.size()), comp_cols(parent.size());
  for (int r = 0; r < m.rows; ++r) comp_rows[root(r)].push_back(r);
  for (int c = 0; c < m.cols; ++c) comp_cols[root(m.rows + c)].push_back(c);
  std::vector<int> col_local(static_cast<std::size_t>(m.cols), -1);
  std::vector<char> col_taken;
  for (std::size_t k = 0; k < parent.size(); ++k)
  {
    if (comp_rows[k].empty() || comp_cols[k].empty()) continue;
    if (std::min(comp_rows[k].size(), comp_cols[k].size()) <= max_exact)
    {
      solveComponent(m, row_begin, comp_rows[k], comp_cols[k], big, col_local, out);
      continue;
    }
    // Too large for the cubic method: the cheapest pairs first (the order of the pairs breaks ties).
    if (greedy) ++*greedy;
    col_taken.assign(static_cast<std::size_t>(m.cols), 0);
    std::vector<std::size_t> edges;
    for (const int r : comp_rows[k])
      for (std::size_t e = row_begin[r]; e < row_begin[r + 1]; ++e) edges.push_back(e);
    std::stable_sort(edges.begin(), edges.end(),
                     [&](std::size_t a, std::size_t b) { return m.pairs[a].cost < m.pairs[b].cost; });
    for (const std::size_t e : edges)
    {
      const GatedPair& p = m.pairs[e];
      if (out[p.row] >= 0 || col_taken[p.col]) continue;
      out[p.row] = p.col;
      col_taken[p.col] = 1;
    }
  }
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
