#include "sunvo/sunvision/sky_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace sunvo::sunvision {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

TEST(SkyModel, ScatteringTableMatchesTheFormula) {
  const PerezParameters p = clearSkyLuminanceParameters(2.5);
  ScatteringTable table;
  table.build(p);
  double worst = 0.0;
  for (double g = 0.0; g <= 180.0; g += 0.37) {
    const double exact = perezScattering(p, g * kDeg);
    worst = std::max(worst, std::abs(table(std::cos(g * kDeg)) - exact) / exact);
  }
  EXPECT_LT(worst, 1e-3);
}

TEST(SkyModel, BrighterTowardTheSunAndTowardTheHorizon) {
  const PerezParameters p = clearSkyLuminanceParameters(2.5);
  EXPECT_GT(perezScattering(p, 5.0 * kDeg), 3.0 * perezScattering(p, 90.0 * kDeg));
  EXPECT_GT(perezGradation(p, std::cos(80.0 * kDeg)), perezGradation(p, 1.0));
  EXPECT_TRUE(std::isfinite(perezGradation(p, -0.5)));  // below the horizon: clamped, finite
}

TEST(SkyModel, HorizonFrameRoundTrip) {
  // A camera pitched down 10 deg and rolled 5 deg: up is not -y.
  const Eigen::Vector3d up_c = Eigen::Vector3d(0.087, -0.97, 0.17).normalized();
  Expected<HorizonFrame> h = HorizonFrame::fromUp(up_c);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->forward_c.dot(h->up_c), 0.0, 1e-12);
  EXPECT_NEAR(h->right_c.dot(h->up_c), 0.0, 1e-12);
  EXPECT_GT(h->right_c.x(), 0.9);  // right stays the camera's x
  for (double az : {-170.0, -90.0, 0.0, 33.0, 179.0}) {
    for (double zen : {1.0, 45.0, 89.0}) {
      const Eigen::Vector3d v = h->direction(az * kDeg, zen * kDeg);
      EXPECT_NEAR(v.norm(), 1.0, 1e-12);
      EXPECT_NEAR(h->azimuthRad(v) / kDeg, az, 1e-9);
      EXPECT_NEAR(h->zenithRad(v) / kDeg, zen, 1e-9);
    }
  }
}

TEST(SkyModel, HorizonFrameRejectsBadUp) {
  EXPECT_FALSE(HorizonFrame::fromUp(Eigen::Vector3d::Zero()));
  EXPECT_FALSE(HorizonFrame::fromUp(Eigen::Vector3d(0.0, 0.0, 1.0)));  // looking straight up
  EXPECT_FALSE(HorizonFrame::fromUp(Eigen::Vector3d(std::nan(""), 1.0, 0.0)));
}

TEST(SkyModel, Wrap) {
  EXPECT_NEAR(wrapPi(3.0 * std::numbers::pi), std::numbers::pi, 1e-12);
  EXPECT_NEAR(wrapPi(-std::numbers::pi), std::numbers::pi, 1e-12);
  EXPECT_NEAR(wrapPi(0.5), 0.5, 1e-15);
}

}  // namespace
}  // namespace sunvo::sunvision
