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

// v^T A^+ v: the sum of (w^T v)^2 / l over A's eigen-pairs (l, w) with l above rel_floor times the
// largest (the others count as unobserved); *rank: how many were kept; A^+ of those when asked.
template <int N>
double pseudoInverseForm(const Eigen::Matrix<double, N, N>& A, const Eigen::Matrix<double, N, 1>& v,
                         double rel_floor, std::size_t* rank,
                         Eigen::Matrix<double, N, N>* A_plus = nullptr) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(A);
  const double floor = rel_floor * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  if (A_plus != nullptr) A_plus->setZero();
  double T = 0.0;
  *rank = 0;
  for (int i = 0; i < N; ++i) {
    const double l = eig.eigenvalues()(i);
    if (l > floor) {
      const double proj = eig.eigenvectors().col(i).dot(v);
      T += proj * proj / l;
      ++*rank;
      if (A_plus != nullptr) {
        *A_plus += eig.eigenvectors().col(i) * eig.eigenvectors().col(i).transpose() / l;
      }
    }
  }
  return T;
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
  // One sun direction never informs the rotation about itself, and directions with less than
  // 1e-3 of the strongest information count as unobserved (rank drops).
  return pseudoInverseForm<3>(I, g, 1e-3, rank);
}

double tiltPersistenceStatistic(const Eigen::Matrix3d& I, const Eigen::Vector3d& g,
                                const Eigen::Vector3d& up, std::size_t* rank) {
  // e = I^+ g has covariance I^+ under noise alone (I^+ as in persistenceStatistic); its tilt part
  // e_t = B^T e (B: two unit vectors normal to up) has covariance C = B^T I^+ B, and
  // T_t = e_t^T C^+ e_t is chi-square with rank(C) dof.
  Eigen::Matrix3d I_plus;
  std::size_t rank_I = 0;
  pseudoInverseForm<3>(I, g, 1e-3, &rank_I, &I_plus);
  const Eigen::Vector3d b1 = up.unitOrthogonal();
  Eigen::Matrix<double, 3, 2> B;
  B << b1, up.cross(b1).normalized();
  const Eigen::Matrix2d C = B.transpose() * I_plus * B;
  const Eigen::Vector2d e_t = B.transpose() * (I_plus * g);
  return pseudoInverseForm<2>(C, e_t, 1e-9, rank);
}

}  // namespace sunvo::sunfusion
