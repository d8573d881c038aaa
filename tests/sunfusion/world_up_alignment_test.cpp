#include "sunvo/sunfusion/world_up_alignment.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "sunvo/core/geometry.hpp"

namespace sunvo::sunfusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The first camera's -y turned by `pitch` about x and `roll` about z (deg).
Eigen::Vector3d tiltedUp(double pitch_deg, double roll_deg) {
  return Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()) *
         (Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
          -Eigen::Vector3d::UnitY());
}

// `up` turned by a random small angle with per-axis std sigma (rad).
Eigen::Vector3d noisy(const Eigen::Vector3d& up, double sigma, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, sigma);
  const Eigen::Vector3d w(n(*rng), 0.0, n(*rng));
  return Eigen::AngleAxisd(w.norm(), w.norm() > 0 ? w.normalized() : Eigen::Vector3d::UnitX()) * up;
}

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return angleBetween(a, b) / kDeg;
}

TEST(WorldUpAlignment, OffKeepsTheAssumedUp) {
  WorldUpAlignment a;
  a.reset(0, -Eigen::Vector3d::UnitY());
  EXPECT_TRUE(a.done());
  EXPECT_FALSE(a.takes(5));
  EXPECT_EQ(a.up(), -Eigen::Vector3d::UnitY());
  EXPECT_EQ(a.tiltDeg(), 0.0);
}

// Ten answers of a camera whose world is 1.5 deg pitched and 1 deg rolled from level, 0.3 deg
// noise and one 8 deg outlier: the estimate lands within 0.4 deg of the truth (measured 0.31; the
// plain mean of the same answers is 0.51 off), and the answers after the frames are not taken.
TEST(WorldUpAlignment, TheRobustMeanOfTheFirstFramesFindsATiltedWorld) {
  const Eigen::Vector3d truth = tiltedUp(1.5, 1.0);
  WorldUpAlignment a;
  a.reset(50, -Eigen::Vector3d::UnitY());
  std::mt19937 rng(3);
  for (std::uint64_t k = 5; k <= 50; k += 5) {
    ASSERT_TRUE(a.takes(k));
    const Eigen::Vector3d u = k == 25 ? tiltedUp(1.5 + 8.0, 1.0) : noisy(truth, 0.3 * kDeg, &rng);
    a.add(u, 0.3 * kDeg);
    EXPECT_FALSE(a.done());
    EXPECT_EQ(a.up(), -Eigen::Vector3d::UnitY());  // the assumed up until it is done
  }
  EXPECT_FALSE(a.takes(55));
  ASSERT_TRUE(a.done());
  EXPECT_EQ(a.used(), 10);
  EXPECT_LT(angleDeg(a.up(), truth), 0.4);
  EXPECT_NEAR(a.tiltDeg(), angleDeg(truth, -Eigen::Vector3d::UnitY()), 0.4);
  EXPECT_FALSE(a.takes(60));
}

TEST(WorldUpAlignment, WaitsForThreeAnswersAndRefusesBadOnes) {
  WorldUpAlignment a;
  a.reset(10, -Eigen::Vector3d::UnitY());
  ASSERT_TRUE(a.takes(5));
  a.add(Eigen::Vector3d(NAN, 0, 0), 0.01);  // not finite: ignored
  a.add(tiltedUp(2.0, 0.0), 0.0);           // no sigma: ignored
  a.add(tiltedUp(2.0, 0.0), 0.01);
  EXPECT_EQ(a.used(), 1);
  // Past the frames with one answer: still aligning until there are three.
  ASSERT_TRUE(a.takes(15));
  a.add(tiltedUp(2.0, 0.0), 0.01);
  ASSERT_TRUE(a.takes(20));
  a.add(tiltedUp(2.0, 0.0), 0.01);
  EXPECT_FALSE(a.takes(25));
  ASSERT_TRUE(a.done());
  EXPECT_NEAR(a.tiltDeg(), 2.0, 1e-6);
}

TEST(WorldUpAlignment, AFullStoreFinishes) {
  WorldUpAlignment a;
  a.reset(100000, -Eigen::Vector3d::UnitY());
  for (int i = 0; i < WorldUpAlignment::kMaxMeasurements; ++i) {
    ASSERT_TRUE(a.takes(static_cast<std::uint64_t>(i + 1)));
    a.add(tiltedUp(0.0, -1.0), 0.01);
  }
  EXPECT_TRUE(a.done());
  EXPECT_NEAR(a.tiltDeg(), 1.0, 1e-6);
}

// For a world whose up is known (ENU) the estimate measures VO's tilt error at the start: the
// correction turns it onto the assumed up, and its sigma is that of a mean (sigma / sqrt(n) for
// n equal answers). finishIfPast ends the alignment only past the frames with three answers.
TEST(WorldUpAlignment, TheTiltCorrectionTurnsTheEstimateOntoTheKnownUp) {
  const Eigen::Vector3d up_w = Eigen::Vector3d::UnitZ();
  // VO's world attitude is 5 deg off about x and -3 deg about y: it sees up at Exp(-e) up_w.
  const Eigen::Vector3d e(5.0 * kDeg, -3.0 * kDeg, 0.0);
  const Eigen::Vector3d seen = expSO3(-e) * up_w;
  WorldUpAlignment a;
  a.reset(15, up_w);
  EXPECT_EQ(a.tiltCorrection(), Eigen::Vector3d::Zero());  // not done
  for (std::uint64_t k = 5; k <= 10; k += 5) {
    ASSERT_TRUE(a.takes(k));
    a.add(seen, 0.5 * kDeg);
  }
  a.finishIfPast(20);  // two answers: not yet
  EXPECT_FALSE(a.done());
  ASSERT_TRUE(a.takes(15));
  a.add(seen, 0.5 * kDeg);
  a.finishIfPast(15);  // not past the frames
  EXPECT_FALSE(a.done());
  a.finishIfPast(16);
  ASSERT_TRUE(a.done());
  const Eigen::Vector3d c = a.tiltCorrection();
  EXPECT_LT(angleBetween(expSO3(c) * a.up(), up_w), 1e-9);
  EXPECT_NEAR(c.dot(up_w), 0.0, 1e-12);    // no heading in it
  EXPECT_LT((c - e).norm(), 0.01 * kDeg);  // the tilt of e (it has no heading part here)
  EXPECT_NEAR(a.sigma(), 0.5 * kDeg / std::sqrt(3.0), 1e-9);
}

// A correction of the attitude the answers were carried by turns them all, and the estimate once
// it is done: the tilt left is what was seen minus what the fusion has taken out.
TEST(WorldUpAlignment, AnswersFollowTheCorrectionsOfTheirAttitude) {
  const Eigen::Vector3d up_w = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d e(4.0 * kDeg, 0.0, 0.0);
  WorldUpAlignment a;
  a.reset(15, up_w);
  for (std::uint64_t k = 5; k <= 15; k += 5) {
    ASSERT_TRUE(a.takes(k));
    a.add(expSO3(-e) * up_w, 0.5 * kDeg);
  }
  a.turn(expSO3(Eigen::Vector3d(3.0 * kDeg, 0.0, 0.0)));  // the filter took 3 of the 4 deg
  a.finishIfPast(16);
  ASSERT_TRUE(a.done());
  EXPECT_NEAR(a.tiltDeg(), 1.0, 1e-6);
  a.turn(expSO3(Eigen::Vector3d(1.0 * kDeg, 0.0, 0.0)));  // and the rest
  EXPECT_NEAR(a.tiltDeg(), 0.0, 1e-6);
  a.turn(Eigen::Matrix3d::Constant(NAN));  // not finite: ignored
  EXPECT_NEAR(a.tiltDeg(), 0.0, 1e-6);
}

}  // namespace
}  // namespace sunvo::sunfusion
