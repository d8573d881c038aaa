#include "sunvo/sunfusion/persistence_statistic.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace sunvo::sunfusion {
namespace {

TEST(PersistenceStatisticTest, ChiSquareQuantilesAtNinetyNinePercent) {
  EXPECT_NEAR(chiSquareQuantile(0.99, 1), 6.635, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 2), 9.210, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(0.99, 3), 11.345, 1e-3);
}

TEST(PersistenceStatisticTest, UnobservedDirectionsDropOutOfTheRank) {
  const Eigen::Matrix3d I = Eigen::Vector3d(4.0, 1.0, 0.0).asDiagonal();
  std::size_t rank = 0;
  EXPECT_NEAR(persistenceStatistic(I, Eigen::Vector3d(2.0, 3.0, 5.0), &rank), 1.0 + 9.0, 1e-12);
  EXPECT_EQ(rank, 2u);
}

// An "up" informs the tilt (x, y with up = z); a sun that informs only the heading adds to the
// test of all axes (one more dof and its own noise) but not to the tilt's.
TEST(PersistenceStatisticTest, AHeadingOnlyChannelLeavesTheTiltTestAlone) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d I_up = Eigen::Vector3d(400.0, 100.0, 0.0).asDiagonal();
  const Eigen::Vector3d g_up(60.0, -20.0, 0.0);
  const Eigen::Matrix3d I_sun = Eigen::Vector3d(0.0, 0.0, 0.5).asDiagonal();
  const Eigen::Vector3d g_sun(0.0, 0.0, 0.3);
  std::size_t rank = 0;
  const double T_up = persistenceStatistic(I_up, g_up, &rank);
  EXPECT_NEAR(T_up, 9.0 + 4.0, 1e-9);
  const double T_all = persistenceStatistic(I_up + I_sun, g_up + g_sun, &rank);
  EXPECT_EQ(rank, 3u);
  EXPECT_NEAR(T_all, T_up + 0.18, 1e-9);
  EXPECT_NEAR(tiltPersistenceStatistic(I_up + I_sun, g_up + g_sun, up, &rank), T_up, 1e-9);
  EXPECT_EQ(rank, 2u);
  // The sun alone says nothing of the tilt.
  EXPECT_EQ(tiltPersistenceStatistic(I_sun, g_sun, up, &rank), 0.0);
  EXPECT_EQ(rank, 0u);
}

// With information that couples the axes, the tilt test is the marginal one: the tilt part of
// e = I^-1 g against the tilt block of I^-1. Checked against the dense formula, and its mean over
// noise-only draws is its dof (2).
TEST(PersistenceStatisticTest, TheTiltTestIsTheMarginalChiSquare) {
  const Eigen::Vector3d up = Eigen::Vector3d(0.2, -1.0, 0.1).normalized();
  Eigen::Matrix3d A;
  A << 3.0, 0.4, -0.2, 0.1, 2.0, 0.5, -0.3, 0.2, 1.0;
  const Eigen::Matrix3d I = A.transpose() * A;
  const Eigen::Matrix3d cov = I.inverse();
  const Eigen::Vector3d b1 = up.unitOrthogonal(), b2 = up.cross(b1);
  Eigen::Matrix<double, 3, 2> B;
  B << b1, b2;
  const Eigen::Vector3d g(1.0, -2.0, 0.5);
  const Eigen::Vector2d e_t = B.transpose() * cov * g;
  const double dense = e_t.dot((B.transpose() * cov * B).inverse() * e_t);
  std::size_t rank = 0;
  EXPECT_NEAR(tiltPersistenceStatistic(I, g, up, &rank), dense, 1e-9);
  EXPECT_EQ(rank, 2u);
  // Noise only: g = sum H_i^T r_i with r_i ~ N(0, I) has covariance I, so g = A^T n.
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  double sum = 0.0;
  constexpr int kDraws = 20000;
  for (int i = 0; i < kDraws; ++i) {
    const Eigen::Vector3d n(n01(rng), n01(rng), n01(rng));
    sum += tiltPersistenceStatistic(I, A.transpose() * n, up, &rank);
  }
  EXPECT_NEAR(sum / kDraws, 2.0, 0.06);
}

}  // namespace
}  // namespace sunvo::sunfusion
