#include "map_aided_fusion/core/tracking/motion_model.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace map_aided_fusion {
namespace core {

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
  const Eigen::Matrix2d s = P.topLeftCorner<2, 2>() + r;
  const Eigen::Matrix<double, 4, 2> k = P.leftCols<2>() * s.inverse();
  const Eigen::Vector2d y(z.x() - x(0), z.y() - x(1));
  x += k * y;
  Eigen::Matrix<double, 2, 4> h = Eigen::Matrix<double, 2, 4>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  const Eigen::Matrix4d ikh = Eigen::Matrix4d::Identity() - k * h;
  P = ikh * P * ikh.transpose() + k * r * k.transpose();
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

}  // namespace core
}  // namespace map_aided_fusion
