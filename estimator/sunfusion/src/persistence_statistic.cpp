#include "sunvo/sunfusion/persistence_statistic.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace sunvo::sunfusion {
namespace {
// Chi-square CDF for 1, 2 or 3 degrees of freedom (closed forms).
double chiSquareCdf(double x, int dof) {
  if (x <= 0.0) return 0.0;
  const double e = std::erf(std::sqrt(0.5 * x));
  if (dof == 1) return e;
  if (dof == 2) return 1.0 - std::exp(-0.5 * x);
  return e - std::sqrt(2.0 * x / M_PI) * std::exp(-0.5 * x);
}

}  // namespace

double chiSquareQuantile(double p, int dof) {
  double lo = 0.0, hi = 200.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chiSquareCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double persistenceStatistic(const Eigen::Matrix3d& I, const Eigen::Vector3d& g, std::size_t* rank) {
  // Pseudo-inverse: one sun direction never informs the rotation about itself, and directions
  // with less than 1e-3 of the strongest information count as unobserved (rank drops).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  const double floor = 1e-3 * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  double T = 0.0;
  *rank = 0;
  for (int i = 0; i < 3; ++i) {
    const double l = eig.eigenvalues()(i);
    if (l > floor) {
      const double proj = eig.eigenvectors().col(i).dot(g);
      T += proj * proj / l;
      ++*rank;
    }
  }
  return T;
}

double tiltPersistenceStatistic(const Eigen::Matrix3d& I, const Eigen::Vector3d& g,
                                const Eigen::Vector3d& up, std::size_t* rank) {
  // The least-squares error estimate e = I^+ g has covariance I^+ under noise alone (the
  // pseudo-inverse as in persistenceStatistic). Its tilt part e_t = B^T e (B: two unit vectors
  // normal to up) has covariance C = B^T I^+ B, so T_t = e_t^T C^+ e_t is chi-square with rank(C)
  // dof: the test of a tilt drift alone, which a channel that informs only the heading (an
  // azimuth-only sun of 15 deg beside a 0.1 deg "up") neither dilutes nor raises.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  const double floor = 1e-3 * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  Eigen::Matrix3d I_plus = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const double l = eig.eigenvalues()(i);
    if (l > floor) I_plus += eig.eigenvectors().col(i) * eig.eigenvectors().col(i).transpose() / l;
  }
  const Eigen::Vector3d e = I_plus * g;
  const Eigen::Vector3d b1 = up.unitOrthogonal();
  Eigen::Matrix<double, 3, 2> B;
  B << b1, up.cross(b1).normalized();
  const Eigen::Matrix2d C = B.transpose() * I_plus * B;
  const Eigen::Vector2d e_t = B.transpose() * e;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig_c(C);
  const double c_floor = 1e-9 * std::max(eig_c.eigenvalues().maxCoeff(), 1e-300);
  double T = 0.0;
  *rank = 0;
  for (int i = 0; i < 2; ++i) {
    const double c = eig_c.eigenvalues()(i);
    if (c > c_floor) {
      const double proj = eig_c.eigenvectors().col(i).dot(e_t);
      T += proj * proj / c;
      ++*rank;
    }
  }
  return T;
}

}  // namespace sunvo::sunfusion
