#include "map_aided_fusion/core/prior_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

/// Kernel half-width in standard deviations.
constexpr double kKernelSigmas = 3.0;
/// Below this pooled non-outline share a cell is all outline.
constexpr float kShareEpsilon = 1e-6f;

/// Gaussian taps g(k) = exp(−(k·res)²/2σ²), k in [−r, r]; empty when σ is 0.
std::vector<float> taps(double sigma, double resolution)
{
  if (!(sigma > 0.0)) return {};
  const int r = std::max(1, static_cast<int>(std::ceil(kKernelSigmas * sigma / resolution)));
  std::vector<float> g(static_cast<std::size_t>(2 * r + 1));
  for (int k = -r; k <= r; ++k)
    g[static_cast<std::size_t>(k + r)] = static_cast<float>(std::exp(-0.5 * std::pow(k * resolution / sigma, 2)));
  return g;
}

/// One pass along x (step 1) or y (step width) of a weighted sum (normalised taps) or a weighted max.
template <bool kMax>
void pass(const float* in, float* out, int width, int height, bool along_x, const std::vector<float>& g)
{
  const int r = static_cast<int>(g.size() / 2);
  float norm = 0.0f;
  for (float v : g) norm += v;
  const float scale = kMax ? 1.0f : 1.0f / norm;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
    {
      float acc = 0.0f;
      for (int k = -r; k <= r; ++k)
      {
        const int xx = along_x ? x + k : x, yy = along_x ? y : y + k;
        if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
        const float v = g[static_cast<std::size_t>(k + r)] * in[static_cast<std::size_t>(yy) * width + xx];
        acc = kMax ? std::max(acc, v) : acc + v;
      }
      out[static_cast<std::size_t>(y) * width + x] = acc * scale;
    }
}

template <bool kMax>
void filter(const AlignedVector<float>& in, AlignedVector<float>& out, const GridGeometry& g,
            const std::vector<float>& t, std::vector<float>& tmp)
{
  out.resize(in.size());
  if (t.empty())
  {
    std::copy(in.begin(), in.end(), out.begin());
    return;
  }
  tmp.resize(in.size());
  pass<kMax>(in.data(), tmp.data(), g.width, g.height, true, t);
  pass<kMax>(tmp.data(), out.data(), g.width, g.height, false, t);
}

}  // namespace

void softenPrior(const PriorWindow& in, double sigma_building, double sigma_road, PriorWindow& out)
{
  requireInRange("sigma_building", sigma_building, 0.0, kMaxPositionSigma);
  requireInRange("sigma_road", sigma_road, 0.0, kMaxPositionSigma);
  const GridGeometry& g = in.geometry;
  out.geometry = g;
  const std::vector<float> tb = taps(sigma_building, g.resolution), tr = taps(sigma_road, g.resolution);
  std::vector<float> tmp;
  AlignedVector<float> wall_pooled;
  filter<false>(in.building, out.building, g, tb, tmp);
  filter<false>(in.road, out.road, g, tr, tmp);
  filter<false>(in.other, out.other, g, tr, tmp);
  filter<false>(in.wall, wall_pooled, g, tb, tmp);
  filter<true>(in.wall, out.wall, g, tb, tmp);
  for (std::size_t i = 0; i < out.wall.size(); ++i)
  {
    const float w = std::max(out.wall[i], wall_pooled[i]);
    out.wall[i] = w;
    const float rest = out.building[i] + out.road[i] + out.other[i];
    const float pooled_share = 1.0f - wall_pooled[i];
    float s = pooled_share > kShareEpsilon ? (1.0f - w) / pooled_share : 0.0f;
    if (rest * s > 1.0f - w) s = rest > 0.0f ? (1.0f - w) / rest : 0.0f;
    out.building[i] *= s;
    out.road[i] *= s;
    out.other[i] *= s;
  }
}

const char* toString(CovarianceFault f)
{
  switch (f)
  {
    case CovarianceFault::kNonFinite: return "a non-finite entry";
    case CovarianceFault::kNegativeVariance: return "a negative variance";
    case CovarianceFault::kAsymmetric: return "an asymmetric matrix";
    case CovarianceFault::kIndefinite: return "an indefinite x-y block (a negative eigenvalue)";
    case CovarianceFault::kNone: break;
  }
  return "none";
}

CovarianceFault positionSigma(const std::array<double, 36>& c, double& sigma)
{
  constexpr double kSymmetryTolerance = 1e-6;
  for (double v : c)
    if (!std::isfinite(v)) return CovarianceFault::kNonFinite;
  for (int i = 0; i < 6; ++i)
    if (c[i * 6 + i] < 0.0) return CovarianceFault::kNegativeVariance;
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j)
    {
      const double a = c[i * 6 + j], b = c[j * 6 + i];
      if (std::abs(a - b) > kSymmetryTolerance * std::max({ 1.0, std::abs(a), std::abs(b) }))
        return CovarianceFault::kAsymmetric;
    }
  const double xx = c[0], yy = c[7], xy = 0.5 * (c[1] + c[6]);
  if (xx * yy - xy * xy < -kSymmetryTolerance * std::max(1.0, xx * yy)) return CovarianceFault::kIndefinite;
  const double mean = 0.5 * (xx + yy), dev = std::sqrt(0.25 * (xx - yy) * (xx - yy) + xy * xy);
  sigma = std::sqrt(std::max(0.0, mean + dev));
  return CovarianceFault::kNone;
}

void PriorGridOptions::validate() const
{
  requireInRange("building_accuracy", building_accuracy, 0.0, kMaxPositionSigma);
  requireInRange("road_accuracy", road_accuracy, 0.0, kMaxPositionSigma);
}

void mapPrior(const PriorGrid& grid, const GridGeometry& window, const PriorConfidence& beta,
              const PriorGridOptions& options, PriorWindow& out)
{
  options.validate();
  beta.validate();
  PriorWindow raw;
  grid.fillWindow(window, beta, raw);
  softenPrior(raw, options.building_accuracy, options.road_accuracy, out);
}

void PriorSoftener::setPrior(std::shared_ptr<const PriorWindow> prior)
{
  raw_ = std::move(prior);
  dirty_ = true;
}

const PriorWindow* PriorSoftener::softened(double sigma, bool* recomputed)
{
  if (recomputed) *recomputed = false;
  if (!raw_) return nullptr;
  if (std::isnan(sigma)) sigma = sigma_;
  sigma = std::clamp(sigma, 0.0, kMaxPositionSigma);
  if (!dirty_ && std::abs(sigma - sigma_) <= tolerance_) return &soft_;
  softenPrior(*raw_, sigma, sigma, soft_);
  sigma_ = sigma;
  dirty_ = false;
  if (recomputed) *recomputed = true;
  return &soft_;
}

}  // namespace core
}  // namespace map_aided_fusion
