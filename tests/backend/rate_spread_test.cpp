// RateSpread: the robust spread (1.4826 x median |rate|) of the window's recent rates per axis,
// which raises the rotation-rate prior's std on rough ground
// (WindowOptions::rate_prior_adapt_frames).

#include "sunvo/backend/rate_spread.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace sunvo::backend {
namespace {

TEST(RateSpread, IsTheStdOfZeroMeanGaussianRates) {
  RateSpread r(200);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 200; ++i) r.push(Eigen::Vector3d(0.05 * n(rng), 0.5 * n(rng), 0.2 * n(rng)));
  const Eigen::Vector3d s = r.spread();
  EXPECT_NEAR(s.x(), 0.05, 0.012);
  EXPECT_NEAR(s.y(), 0.5, 0.12);
  EXPECT_NEAR(s.z(), 0.2, 0.05);
}

TEST(RateSpread, AFewLargeSamplesDoNotMoveIt) {
  RateSpread r(50);
  for (int i = 0; i < 50; ++i) {
    const double rate = i % 10 == 0 ? 1.0 : 0.01 * ((i % 3) + 1);  // 5 spikes of 100x
    r.push(Eigen::Vector3d::Constant(rate));
  }
  // |rates| sorted: 45 of 0.01/0.02/0.03 and 5 of 1.0; the median is one of the small ones.
  EXPECT_LE(r.spread().x(), 1.4826 * 0.03 + 1e-12);
}

TEST(RateSpread, NeedsSamplesAndForgetsTheOldest) {
  RateSpread r(20);
  for (int i = 0; i < RateSpread::kMinSamples - 1; ++i) r.push(Eigen::Vector3d::Constant(1.0));
  EXPECT_FALSE(r.ready());
  EXPECT_EQ(r.spread(), Eigen::Vector3d::Zero());
  r.push(Eigen::Vector3d::Constant(-1.0));  // the sign does not matter
  EXPECT_TRUE(r.ready());
  EXPECT_DOUBLE_EQ(r.spread().z(), 1.4826);
  // 20 samples of 0.1 push every 1.0 out of the ring.
  for (int i = 0; i < 20; ++i) r.push(Eigen::Vector3d::Constant(0.1));
  EXPECT_EQ(r.size(), 20);
  EXPECT_DOUBLE_EQ(r.spread().z(), 1.4826 * 0.1);
  // A capacity below kMinSamples is ready when full.
  RateSpread small(3);
  for (int i = 0; i < 3; ++i) small.push(Eigen::Vector3d::Constant(2.0));
  EXPECT_TRUE(small.ready());
  EXPECT_DOUBLE_EQ(small.spread().y(), 1.4826 * 2.0);
}

TEST(RateSpread, UndoTakesBackOnlyTheNewestUncommittedPush) {
  RateSpread r(10);
  for (int i = 0; i < 10; ++i) r.push(Eigen::Vector3d::Constant(0.1));
  r.commit();
  EXPECT_FALSE(r.undoLastPush());  // nothing since the commit
  // Ring full: the push replaces the oldest sample and the undo puts it back.
  r.push(Eigen::Vector3d::Constant(5.0));
  EXPECT_TRUE(r.undoLastPush());
  EXPECT_FALSE(r.undoLastPush());
  EXPECT_EQ(r.size(), 10);
  for (int i = 0; i < 9; ++i) r.push(Eigen::Vector3d::Constant(0.1));
  EXPECT_DOUBLE_EQ(r.spread().x(), 1.4826 * 0.1);  // the 5.0 is gone, not hidden in the ring
  // Ring not full: the undo shrinks it.
  RateSpread s(10);
  s.push(Eigen::Vector3d::Constant(0.1));
  EXPECT_TRUE(s.undoLastPush());
  EXPECT_EQ(s.size(), 0);
}

TEST(RateSpread, IgnoresNonFiniteRatesAndAZeroCapacity) {
  RateSpread r(10);
  EXPECT_FALSE(r.push(Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0)));
  EXPECT_FALSE(r.push(Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0.0, 0.0)));
  EXPECT_EQ(r.size(), 0);
  RateSpread off(0);
  EXPECT_FALSE(off.push(Eigen::Vector3d::Constant(1.0)));
  EXPECT_FALSE(off.ready());
  EXPECT_FALSE(off.undoLastPush());
  RateSpread big(100000);
  EXPECT_EQ(big.capacity(), RateSpread::kMaxFrames);
}

}  // namespace
}  // namespace sunvo::backend
