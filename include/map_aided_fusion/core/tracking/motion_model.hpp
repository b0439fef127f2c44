/**
 * @file
 * @brief Tracking, part "motion model": a track's state x = (x, y, vx, vy) in the map frame and its covariance P,
 *        under a constant-velocity model with white-noise acceleration, corrected by a measured position.
 *
 * The prediction is the discrete white-noise acceleration model (Bar-Shalom, Li, Kirubarajan, "Estimation with
 * Applications to Tracking and Navigation", § 6.3.3): F = [I, dt·I; 0, I] and Q = σa² [dt⁴/4·I, dt³/2·I; dt³/2·I,
 * dt²·I]. The correction is the Kalman update of a position measurement (H = [I, 0]) with its covariance in Joseph
 * form, which keeps P symmetric and positive semi-definite.
 */
#pragma once

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

}  // namespace core
}  // namespace map_aided_fusion
