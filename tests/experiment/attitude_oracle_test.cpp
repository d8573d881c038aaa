#include "sunvo/experiment/attitude_oracle.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace sunvo::experiment {
namespace {

const Eigen::Vector3d kUp(0.0, -1.0, 0.0);  // KITTI's first camera: -y is up

// A true drive in the first camera's world: forward along z with a slow turn about the up and a
// small pitch oscillation, 1 m per frame.
std::vector<Isometry3> trueDrive(int n) {
  std::vector<Isometry3> T(static_cast<std::size_t>(n), Isometry3::Identity());
  for (int k = 1; k < n; ++k) {
    const Isometry3& prev = T[static_cast<std::size_t>(k - 1)];
    Isometry3& cur = T[static_cast<std::size_t>(k)];
    cur.translation() = prev.translation() + prev.linear() * Eigen::Vector3d(0.0, 0.0, 1.0);
    cur.linear() = expSO3(0.01 * kUp) * expSO3(Eigen::Vector3d(0.002 * std::sin(0.3 * k), 0, 0)) *
                   prev.linear();
  }
  return T;
}

// VO that measures every step exactly in its camera but whose world attitude is off by
// Exp(-k * rate_w) (a steady drift about the world axis rate_w), its steps laid in that attitude.
std::vector<Isometry3> driftingVo(const std::vector<Isometry3>& gt, const Eigen::Vector3d& rate_w) {
  std::vector<Isometry3> vo(gt.size(), Isometry3::Identity());
  vo[0] = gt[0];
  for (std::size_t k = 1; k < gt.size(); ++k) {
    const Eigen::Vector3d t_prev =
        gt[k - 1].linear().transpose() * (gt[k].translation() - gt[k - 1].translation());
    vo[k].translation() = vo[k - 1].translation() + vo[k - 1].linear() * t_prev;
    vo[k].linear() = expSO3(-static_cast<double>(k) * rate_w) * gt[k].linear();
  }
  return vo;
}

double worstPositionError(const std::vector<Isometry3>& a, const std::vector<Isometry3>& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    worst = std::max(worst, (a[k].translation() - b[k].translation()).norm());
  return worst;
}

double worstAngleError(const std::vector<Isometry3>& a, const std::vector<Isometry3>& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    worst = std::max(worst, logSO3(a[k].linear() * b[k].linear().transpose()).norm());
  return worst;
}

TEST(AttitudeOracle, AHeadingDriftIsTakenOutByTheTrueHeadingNotByTheTilt) {
  const auto gt = trueDrive(200);
  const auto vo = driftingVo(gt, 2e-4 * kUp);  // 2.3 deg of heading over the drive
  ASSERT_GT(worstPositionError(vo, gt), 3.0);
  auto all = withTrueAttitude(vo, gt, 3.0 * kUp, AttitudeOracle::kTrueAttitude);
  auto heading = withTrueAttitude(vo, gt, kUp, AttitudeOracle::kTrueHeading);
  auto tilt = withTrueAttitude(vo, gt, kUp, AttitudeOracle::kTrueTilt);
  ASSERT_TRUE(all && heading && tilt);
  EXPECT_LT(worstPositionError(*all, gt), 1e-9);
  EXPECT_LT(worstAngleError(*all, gt), 1e-9);
  EXPECT_LT(worstPositionError(*heading, gt), 1e-9);
  EXPECT_LT(worstAngleError(*heading, gt), 1e-9);
  // The tilt oracle has nothing to take out: VO as it was.
  EXPECT_LT(worstPositionError(*tilt, vo), 1e-9);
  EXPECT_LT(worstAngleError(*tilt, vo), 1e-9);
}

TEST(AttitudeOracle, ATiltDriftIsTakenOutByTheTrueTilt) {
  const auto gt = trueDrive(200);
  const auto vo = driftingVo(gt, Eigen::Vector3d(1.5e-4, 0.0, 0.0));  // pitch across the up
  ASSERT_GT(worstPositionError(vo, gt), 0.5);
  auto tilt = withTrueAttitude(vo, gt, kUp, AttitudeOracle::kTrueTilt);
  auto heading = withTrueAttitude(vo, gt, kUp, AttitudeOracle::kTrueHeading);
  ASSERT_TRUE(tilt && heading);
  EXPECT_LT(worstPositionError(*tilt, gt), 1e-9);
  EXPECT_LT(worstAngleError(*tilt, gt), 1e-9);
  EXPECT_LT(worstPositionError(*heading, vo), 1e-9);
}

TEST(AttitudeOracle, MismatchedOrEmptyRunsAndAZeroUpAreRefused) {
  const auto gt = trueDrive(10);
  std::vector<Isometry3> short_vo(gt.begin(), gt.begin() + 9);
  auto r = withTrueAttitude(short_vo, gt, kUp, AttitudeOracle::kTrueAttitude);
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().toString().find("9 VO poses against 10 true poses"), std::string::npos);
  EXPECT_FALSE(withTrueAttitude({}, {}, kUp, AttitudeOracle::kTrueAttitude));
  auto z = withTrueAttitude(gt, gt, Eigen::Vector3d::Zero(), AttitudeOracle::kTrueTilt);
  ASSERT_FALSE(z);
  EXPECT_NE(z.status().toString().find("up is zero"), std::string::npos);
  EXPECT_STREQ(attitudeOracleName(AttitudeOracle::kTrueHeading), "Pure VO, true heading (oracle)");
}

}  // namespace
}  // namespace sunvo::experiment
