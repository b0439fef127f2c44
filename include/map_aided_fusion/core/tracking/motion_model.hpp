/**
 * @file
 * @brief Tracking, part "motion model": a track's state x = (x, y, vx, vy) in the map frame and its covariance P,
 *        under a constant-velocity model with white-noise acceleration, corrected by a measured position.
 *
 * The prediction is the discrete white-noise acceleration model (Bar-Shalom, Li, Kirubarajan, "Estimation with
 * Applications to Tracking and Navigation", § 6.3.3): F = [I, dt·I; 0, I] and Q = σa² [dt⁴/4·I, dt³/2·I; dt³/2·I,
 * dt²·I]. The correction is the Kalman update of a position measurement (H = [I, 0]) with its covariance in Joseph
 * form, which keeps P symmetric and positive semi-definite.
 *
 * For manoeuvres (braking, pulling away, turning), an interacting multiple model of that model and a
 * constant-acceleration one (ImmState).
 */
#pragma once

#include <array>

#include <Eigen/Core>

namespace map_aided_fusion {
namespace core {

/// m/s: a speed below this has no direction (speedSigma()).
constexpr double kDirectionlessSpeed = 1e-6;

/**
 * @brief Moves the state @p x and covariance @p P on by @p dt seconds at constant velocity, with white-noise
 *        acceleration of standard deviation @p acceleration_sigma (m/s²): x ← F x, P ← F P Fᵀ + Q.
 */
void predictConstantVelocity(Eigen::Vector4d& x, Eigen::Matrix4d& P, double dt, double acceleration_sigma);

/**
 * @brief The Kalman update of @p x and @p P with the measured position @p z (m, map frame) of covariance @p r (m²):
 *        K = P Hᵀ (H P Hᵀ + r)⁻¹, x ← x + K (z − H x), P ← (I − K H) P (I − K H)ᵀ + K r Kᵀ.
 */
void correctPosition(Eigen::Vector4d& x, Eigen::Matrix4d& P, const Eigen::Vector2d& z, const Eigen::Matrix2d& r);

/**
 * @brief The standard deviation (m/s) of the velocity of @p P along the unit vector @p direction: √(uᵀ Pv u), Pv the
 *        velocity block (0 when rounding makes it negative).
 */
double velocitySigmaAlong(const Eigen::Matrix4d& P, const Eigen::Vector2d& direction);

/**
 * @brief The standard deviation (m/s) of the speed of @p x: along its velocity; when the speed is below
 *        kDirectionlessSpeed, the largest over all directions (√ of Pv's largest eigenvalue).
 */
double speedSigma(const Eigen::Vector4d& x, const Eigen::Matrix4d& P);

/// State of the IMM's models: (x, y, vx, vy, ax, ay) in the map frame (the constant-velocity model's acceleration is 0).
using ImmVector = Eigen::Matrix<double, 6, 1>;
using ImmMatrix = Eigen::Matrix<double, 6, 6>;

/// The two models of the IMM and how they switch.
struct ManoeuvreModel
{
  double quiet_sigma = 2.0;     ///< m/s², white-noise acceleration of the constant-velocity model
  double jerk_sigma = 4.0;      ///< m/s³, white-noise jerk of the constant-acceleration (manoeuvring) model
  double start_rate = 0.5;      ///< 1/s: quiet → manoeuvring
  double end_rate = 2.0;        ///< 1/s: manoeuvring → quiet
  /// The share of time spent manoeuvring in the long run (the chain's stationary probability), a new track's prior.
  double stationaryManoeuvre() const { return start_rate / (start_rate + end_rate); }
};

/**
 * @brief Moves @p x, @p P on by @p dt s at constant acceleration with continuous white-noise jerk of spectral density
 *        @p jerk_sigma² (Bar-Shalom et al. § 6.2.3): per axis F = [1, dt, dt²/2; 0, 1, dt; 0, 0, 1] and
 *        Q = σj² [dt⁵/20, dt⁴/8, dt³/6; dt⁴/8, dt³/3, dt²/2; dt³/6, dt²/2, dt].
 */
void predictConstantAcceleration(ImmVector& x, ImmMatrix& P, double dt, double jerk_sigma);

/// The Kalman update of a 6-dimensional state with a measured position (H = [I, 0, 0]), in Joseph form.
void correctPosition(ImmVector& x, ImmMatrix& P, const Eigen::Vector2d& z, const Eigen::Matrix2d& r);

/**
 * @brief An interacting multiple model (IMM; Blom and Bar-Shalom 1988; Bar-Shalom et al. § 11.6.6) of a quiet
 *        constant-velocity model and a manoeuvring constant-acceleration one (braking, pulling away, turning),
 *        switching as a Markov chain. Each scan mixes their states, predicts and corrects each, weighs them by the
 *        likelihood of the measurement; the track reports the moment-matched mixture of position and velocity.
 */
struct ImmState
{
  std::array<ImmVector, 2> x{ ImmVector::Zero(), ImmVector::Zero() };  ///< quiet, manoeuvring
  std::array<ImmMatrix, 2> P{ ImmMatrix::Identity(), ImmMatrix::Identity() };
  Eigen::Vector2d mu = Eigen::Vector2d(1.0, 0.0);  ///< the models' probabilities

  /// Both models at @p x0, @p p0 (position and velocity; no acceleration, with variance @p acceleration_variance in
  /// the manoeuvring model); the manoeuvring one with probability @p manoeuvre.
  void reset(const Eigen::Vector4d& x0, const Eigen::Matrix4d& p0, double acceleration_variance, double manoeuvre);
  /// The moment-matched mixture of position and velocity: x = Σ μj xj, P = Σ μj (Pj + (xj − x)(xj − x)ᵀ) (x formed
  /// by differences from the quiet model's state: exact when the models agree).
  void combine(Eigen::Vector4d& x_out, Eigen::Matrix4d& p_out) const;
  /// Moves every model's position by @p d (m): the followed point moved on the object.
  void shiftPosition(const Eigen::Vector2d& d);
};

/// The IMM's interaction and prediction over @p dt s: the models' states mixed by the switching probabilities, each
/// predicted by its own model; mu becomes the predicted probabilities.
void predictImm(ImmState& s, double dt, const ManoeuvreModel& m);

/// Each model corrected with the position @p z of covariance @p r, and the probabilities updated by each model's
/// likelihood of @p z (Gaussian, innovation covariance P + r); left as they were when neither explains it.
void correctImm(ImmState& s, const Eigen::Vector2d& z, const Eigen::Matrix2d& r);

}  // namespace core
}  // namespace map_aided_fusion
