#include "sunvo/core/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sunvo/core/camera.hpp"

namespace sunvo {
namespace {

TEST(RotationAngle, MatchesConstructedAngleOverFullRange) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double angle = M_PI * (0.5 * (u(rng) + 1.0));
    const Eigen::Matrix3d C = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_NEAR(rotationAngle(C), angle, 1e-12);
  }
}

TEST(RotationAngle, AccurateForTinyAngles) {
  // arccos((tr - 1) / 2) returns 0 or ~1e-8 garbage here; the atan2 form keeps full precision.
  const double angle = 1e-9;
  const Eigen::Matrix3d C = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(rotationAngle(C) / angle, 1.0, 1e-9);
}

TEST(AngleBetween, FullRangeAndZeroVector) {
  EXPECT_NEAR(angleBetween(Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX()), M_PI, 1e-12);
  EXPECT_EQ(angleBetween(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()), 0.0);
}

TEST(Orthonormalize, ReturnsNearestRotation) {
  const Eigen::Matrix3d C =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix3d noisy = C;
  noisy(0, 1) += 1e-5;  // a 3x4 file printed with few digits is not exactly orthonormal
  const Eigen::Matrix3d R = orthonormalize(noisy);
  EXPECT_NEAR((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-14);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  EXPECT_LT((R - C).norm(), 1e-5);
}

TEST(SO3, ExpLogRoundTrip) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d phi(u(rng), u(rng), u(rng));
    EXPECT_LT((logSO3(expSO3(phi)) - phi).norm(), 1e-10);
  }
}

TEST(StereoCamera, ProjectTriangulateRoundTrip) {
  const StereoCamera cam{718.856, 718.856, 607.1928, 185.2157, 0.5372, 1241, 376};
  ASSERT_TRUE(cam.validate().isOk());
  const Eigen::Vector3d p(1.5, -0.7, 12.0);
  const Eigen::Vector3d y = cam.project(p);
  EXPECT_NEAR(y.z(), 718.856 * 0.5372 / 12.0, 1e-12);
  EXPECT_LT((cam.triangulate(y.x(), y.y(), y.z()) - p).norm(), 1e-12);
}

TEST(StereoCamera, ValidateNamesTheBadField) {
  StereoCamera cam{718.0, 718.0, 600.0, 180.0, 0.0, 1241, 376};
  const Status s = cam.validate();
  EXPECT_FALSE(s.isOk());
  EXPECT_NE(s.message().find("baseline_m"), std::string::npos);
}

}  // namespace
}  // namespace sunvo
