/**
 * @file prior_uncertainty.hpp
 * @brief The PriorGrid softened by position uncertainty (not in the paper; doc/steps.md, "The map is not exact,
 *        nor is the pose"): of the map (its positional accuracy per layer) and of the vehicle (σ of its pose).
 *
 * With a Gaussian position error of standard deviation σ (metres, isotropic), a cell's prior is the linear pool
 * of the cells around it: m(B), m(R), m(T) are blurred by the normalised Gaussian kernel. The outline mass
 * m(W = {F, C}) is not averaged away but spread as a possibility, m_W'(x) = max_y m_W(y)·exp(−|x − y|²/2σ²):
 * occupied evidence that close to a mapped wall is the wall. The other masses are then scaled by
 * (1 − m_W')/(1 − m̄_W), m̄_W the pooled outline mass, so that every cell stays a mass function. σ = 0 is the
 * identity. Softening twice (map, then pose) widens the outline band by σ_map + σ_pose, a conservative sum.
 * Reference: Yu, Cherfaoui, Bonnifait, Sensors 20(2):352, 2020.
 */
#pragma once

#include <array>
#include <memory>

#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"

namespace map_aided_fusion {
namespace core {

/// Largest σ accepted, metres; larger values are clamped to it (PriorSoftener) or refused (parameters).
constexpr double kMaxPositionSigma = 5.0;

/// Why a pose covariance was refused.
enum class CovarianceFault
{
  kNone,
  kNonFinite,         ///< a NaN or infinite entry
  kNegativeVariance,  ///< a negative diagonal entry
  kAsymmetric,        ///< C(i, j) ≠ C(j, i) beyond a relative 1e-6
  kIndefinite,        ///< the x-y block has a negative eigenvalue (its determinant < 0): no covariance
};

/// Short text of a fault, for warnings.
const char* toString(CovarianceFault f);

/**
 * @brief The isotropic position σ, metres, of a 6 × 6 row-major pose covariance (x, y, z, roll, pitch, yaw), as in
 *        geometry_msgs/PoseWithCovariance: the square root of the largest eigenvalue of its x-y block. The whole
 *        matrix is checked. The yaw variance is not used. @p sigma is left unchanged on a fault.
 */
CovarianceFault positionSigma(const std::array<double, 36>& covariance, double& sigma);

/**
 * @brief @p out ← @p in softened by σ_building (B and W) and σ_road (R and T), metres in [0, kMaxPositionSigma].
 *        Cells outside @p in count as vacuous. @p out is reset to @p in's geometry.
 * @throws ParameterError naming sigma_building or sigma_road when out of range.
 */
void softenPrior(const PriorWindow& in, double sigma_building, double sigma_road, PriorWindow& out);

/**
 * @brief The prior masses of @p window from @p grid (PriorGrid::fillWindow()), softened by the map's accuracy of
 *        @p options. @throws ParameterError for invalid options or β.
 */
void mapPrior(const PriorGrid& grid, const GridGeometry& window, const PriorConfidence& beta,
              const PriorGridOptions& options, PriorWindow& out);

/**
 * @brief Keeps a prior and its softened copy for the σ in force: recomputed only when the prior changes or σ moves
 *        by more than the tolerance, never per scan.
 */
class PriorSoftener
{
public:
  /// @param tolerance metres: a new σ within this of the one in force does not recompute.
  explicit PriorSoftener(double tolerance = 0.05) : tolerance_(tolerance) {}

  /// A new raw prior (nullptr: none). The next softened() recomputes.
  void setPrior(std::shared_ptr<const PriorWindow> prior);
  /// The prior softened by @p sigma (clamped to [0, kMaxPositionSigma]; NaN keeps the one in force); nullptr
  /// without a prior. @p recomputed, when given, tells whether this call recomputed it.
  const PriorWindow* softened(double sigma, bool* recomputed = nullptr);
  /// σ of the softened prior in force, metres.
  double sigmaInForce() const { return sigma_; }
  const std::shared_ptr<const PriorWindow>& raw() const { return raw_; }

private:
  double tolerance_;
  double sigma_ = 0.0;
  bool dirty_ = true;
  std::shared_ptr<const PriorWindow> raw_;
  PriorWindow soft_;
};

}  // namespace core
}  // namespace map_aided_fusion
