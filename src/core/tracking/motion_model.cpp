#include "map_aided_fusion/core/tracking/motion_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace map_aided_fusion {
namespace core {

namespace {

/// The Kalman update of an N-dimensional state whose first two components are the position, measured as @p z with
/// covariance @p r (H = [I, 0]), in Joseph form (it stays symmetric and positive semi-definite).
template <int N>
void correctPositionOf(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P, const Eigen::Vector2d& z,
                       const Eigen::Matrix2d& r)
{
  const Eigen::Matrix2d s = P.template topLeftCorner<2, 2>() + r;
  const Eigen::Matrix<double, N, 2> k = P.template leftCols<2>() * s.inverse();
  const Eigen::Vector2d y(z.x() - x(0), z.y() - x(1));
  x += k * y;
  Eigen::Matrix<double, 2, N> h = Eigen::Matrix<double, 2, N>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  const Eigen::Matrix<double, N, N> ikh = Eigen::Matrix<double, N, N>::Identity() - k * h;
  P = ikh * P * ikh.transpose() + k * r * k.transpose();
}

}  // namespace

void predictConstantVelocity(Eigen::Vector4d& x, Eigen::Matrix4d& P, double dt, double acceleration_sigma)
{
  Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
  f(0, 2) = f(1, 3) = dt;
  const double q = acceleration_sigma * acceleration_sigma;
  const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt;
  Eigen::Matrix4d qm = Eigen::Matrix4d::Zero();
  qm(0, 0) = qm(1, 1) = 0.25 * dt4 * q;
  qm(0, 2) = qm(2, 0) = qm(1, 3) = qm(3, 1) = 0.5 * dt3 * q;
  qm(2, 2) = qm(3, 3) = dt2 * q;
  x = f * x;
  P = f * P * f.transpose() + qm;
}

void correctPosition(Eigen::Vector4d& x, Eigen::Matrix4d& P, const Eigen::Vector2d& z, const Eigen::Matrix2d& r)
{
  correctPositionOf<4>(x, P, z, r);
}

double velocitySigmaAlong(const Eigen::Matrix4d& P, const Eigen::Vector2d& direction)
{
  return std::sqrt(std::max(0.0, direction.dot(P.bottomRightCorner<2, 2>() * direction)));
}

double speedSigma(const Eigen::Vector4d& x, const Eigen::Matrix4d& P)
{
  const Eigen::Vector2d v = x.tail<2>();
  const double s = v.norm();
  if (s < kDirectionlessSpeed)
  {
    const Eigen::Matrix2d pv = P.bottomRightCorner<2, 2>();
    return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(pv).eigenvalues()(1)));
  }
  return velocitySigmaAlong(P, v / s);
}

namespace {

/// The constant-velocity model on the IMM's state: position and velocity as predictConstantVelocity(), the
/// acceleration dropped (0, no variance).
void predictQuiet(ImmVector& x, ImmMatrix& P, double dt, double acceleration_sigma)
{
  Eigen::Vector4d x4 = x.head<4>();
  Eigen::Matrix4d p4 = P.topLeftCorner<4, 4>();
  predictConstantVelocity(x4, p4, dt, acceleration_sigma);
  x.setZero();
  x.head<4>() = x4;
  P.setZero();
  P.topLeftCorner<4, 4>() = p4;
}

}  // namespace

void predictConstantAcceleration(ImmVector& x, ImmMatrix& P, double dt, double jerk_sigma)
{
  ImmMatrix f = ImmMatrix::Identity();
  const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt, dt5 = dt4 * dt;
  for (int a = 0; a < 2; ++a)
  {
    f(a, 2 + a) = dt;
    f(a, 4 + a) = 0.5 * dt2;
    f(2 + a, 4 + a) = dt;
  }
  const double q = jerk_sigma * jerk_sigma;
  const double block[3][3] = { { dt5 / 20.0, dt4 / 8.0, dt3 / 6.0 },
                               { dt4 / 8.0, dt3 / 3.0, dt2 / 2.0 },
                               { dt3 / 6.0, dt2 / 2.0, dt } };
  ImmMatrix qm = ImmMatrix::Zero();
  for (int a = 0; a < 2; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) qm(2 * i + a, 2 * j + a) = q * block[i][j];
  x = f * x;
  P = f * P * f.transpose() + qm;
}

void correctPosition(ImmVector& x, ImmMatrix& P, const Eigen::Vector2d& z, const Eigen::Matrix2d& r)
{
  correctPositionOf<6>(x, P, z, r);
}

void ImmState::reset(const Eigen::Vector4d& x0, const Eigen::Matrix4d& p0, double acceleration_variance,
                     double manoeuvre)
{
  for (int j = 0; j < 2; ++j)
  {
    x[j].setZero();
    x[j].head<4>() = x0;
    P[j].setZero();
    P[j].topLeftCorner<4, 4>() = p0;
  }
  P[1](4, 4) = P[1](5, 5) = acceleration_variance;
  mu = Eigen::Vector2d(1.0 - manoeuvre, manoeuvre);
}

void ImmState::combine(Eigen::Vector4d& x_out, Eigen::Matrix4d& p_out) const
{
  // From the quiet model's state, by differences: exact when the models agree, and no rounding of large coordinates.
  x_out = x[0].head<4>() + mu(1) * (x[1].head<4>() - x[0].head<4>());
  p_out.setZero();
  for (int j = 0; j < 2; ++j)
  {
    const Eigen::Vector4d d = x[j].head<4>() - x_out;
    p_out += mu(j) * (P[j].topLeftCorner<4, 4>() + d * d.transpose());
  }
}

void ImmState::shiftPosition(const Eigen::Vector2d& d)
{
  for (ImmVector& xj : x) xj.head<2>() += d;
}

void predictImm(ImmState& s, double dt, const ManoeuvreModel& m)
{
  // The chain's transition probabilities over dt: Π(i, j) = P(model j now | model i before).
  const double start = 1.0 - std::exp(-m.start_rate * dt), end = 1.0 - std::exp(-m.end_rate * dt);
  Eigen::Matrix2d pi;
  pi << 1.0 - start, start, end, 1.0 - end;
  const Eigen::Vector2d c = pi.transpose() * s.mu;  // predicted probabilities
  std::array<ImmVector, 2> x0;
  std::array<ImmMatrix, 2> p0;
  for (int j = 0; j < 2; ++j)
  {
    // Mixing weights μ(i | j) = Π(i, j) μi / cj; a model no state can reach keeps its own.
    Eigen::Vector2d w(pi(0, j) * s.mu(0), pi(1, j) * s.mu(1));
    if (c(j) > 0.0)
      w /= c(j);
    else
      w = j == 0 ? Eigen::Vector2d(1.0, 0.0) : Eigen::Vector2d(0.0, 1.0);
    const int other = 1 - j;
    x0[j] = s.x[j] + w(other) * (s.x[other] - s.x[j]);
    p0[j].setZero();
    for (int i = 0; i < 2; ++i)
    {
      const ImmVector d = s.x[i] - x0[j];
      p0[j] += w(i) * (s.P[i] + d * d.transpose());
    }
  }
  s.x = x0;
  s.P = p0;
  predictQuiet(s.x[0], s.P[0], dt, m.quiet_sigma);
  predictConstantAcceleration(s.x[1], s.P[1], dt, m.jerk_sigma);
  s.mu = c;
}

void correctImm(ImmState& s, const Eigen::Vector2d& z, const Eigen::Matrix2d& r)
{
  // Log-likelihoods, so that far innovations do not underflow both to zero.
  double log_l[2];
  for (int j = 0; j < 2; ++j)
  {
    const Eigen::Matrix2d sj = s.P[j].topLeftCorner<2, 2>() + r;
    const Eigen::Vector2d y = z - s.x[j].head<2>();
    const double det = sj.determinant();
    log_l[j] = det > 0.0 ? -0.5 * (y.dot(sj.inverse() * y) + std::log(det)) : -std::numeric_limits<double>::infinity();
    correctPosition(s.x[j], s.P[j], z, r);
  }
  const double top = std::max(log_l[0], log_l[1]);
  if (!std::isfinite(top)) return;
  Eigen::Vector2d w(s.mu(0) * std::exp(log_l[0] - top), s.mu(1) * std::exp(log_l[1] - top));
  const double total = w.sum();
  if (total > 0.0 && std::isfinite(total)) s.mu = w / total;
}

}  // namespace core
}  // namespace map_aided_fusion
