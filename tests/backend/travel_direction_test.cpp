// TravelDirection: the median direction of travel of the window's recent steps, which the
// non-holonomic row uses as beta (WindowOptions::lateral_beta_frames).

#include "sunvo/backend/travel_direction.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace sunvo::backend {
namespace {

// 200 steps: a camera turned by 2 mrad, 15 mrad of noise per step (0020's pure VO, robust std),
// and one step in twenty thrown sideways as the weak frames' are (+0.1 rad). The mean moves by
// 5 mrad; the median by 0.07 of the noise's std (1 mrad) plus its own sampling noise (1.3 mrad).
TEST(TravelDirection, IsTheMedianAndIgnoresTheWeakFramesSteps) {
  TravelDirection d(200);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 0.015);
  double sum = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double beta = i % 20 == 0 ? 0.1 : -0.002 + n(rng);
    sum += beta;
    ASSERT_TRUE(d.push(beta));
  }
  std::printf("200 steps: median %.2e rad, mean %.2e rad (truth -2e-3)\n", d.beta(), sum / 200);
  EXPECT_NEAR(d.beta(), -0.002, 0.003);
  EXPECT_GT(sum / 200 + 0.002, 0.004);
}

TEST(TravelDirection, NeedsAQuarterOfItsStepsAndForgetsTheOldest) {
  TravelDirection d(64);
  for (int i = 0; i < 15; ++i) d.push(0.01);
  EXPECT_FALSE(d.ready());
  EXPECT_EQ(d.beta(), 0.0);  // straight ahead until learnt
  d.push(0.01);
  EXPECT_TRUE(d.ready());
  EXPECT_DOUBLE_EQ(d.beta(), 0.01);
  for (int i = 0; i < 64; ++i) d.push(-0.003);  // every 0.01 leaves the ring
  EXPECT_EQ(d.size(), 64);
  EXPECT_DOUBLE_EQ(d.beta(), -0.003);
  // A ring smaller than kMinSamples is ready when full; the even count takes the middle pair.
  TravelDirection small(4);
  for (const double b : {0.004, 0.001, 0.003, 0.002}) small.push(b);
  EXPECT_TRUE(small.ready());
  EXPECT_DOUBLE_EQ(small.beta(), 0.0025);
}

TEST(TravelDirection, UndoTakesBackOnlyTheNewestUncommittedPush) {
  TravelDirection d(8);
  for (int i = 0; i < 8; ++i) d.push(0.001);
  d.commit();
  EXPECT_FALSE(d.undoLastPush());  // nothing since the commit
  d.push(0.5);                     // replaces a 0.001 (ring full)
  EXPECT_TRUE(d.undoLastPush());
  EXPECT_FALSE(d.undoLastPush());  // only the newest
  EXPECT_EQ(d.size(), 8);
  EXPECT_DOUBLE_EQ(d.beta(), 0.001);
  TravelDirection growing(16);
  growing.push(0.002);
  EXPECT_TRUE(growing.undoLastPush());
  EXPECT_EQ(growing.size(), 0);
}

TEST(TravelDirection, RefusesNonFiniteSamplesAndAZeroCapacityKeepsNothing) {
  TravelDirection d(8);
  EXPECT_FALSE(d.push(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(d.push(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(d.size(), 0);
  TravelDirection off(0);
  EXPECT_FALSE(off.push(0.01));
  EXPECT_FALSE(off.ready());
  EXPECT_EQ(off.beta(), 0.0);
  TravelDirection big(1'000'000);  // clamped
  EXPECT_EQ(big.capacity(), TravelDirection::kMaxFrames);
}

}  // namespace
}  // namespace sunvo::backend
