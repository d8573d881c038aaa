#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sun_window_term_fixture.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"

// The vertical channel of SunWindowTerm: "up" as a second absolute direction beside the sun.
namespace sunvo::sunfusion {
namespace {

using test_support::baseAttitudeOptions;
using test_support::kDeg;
using test_support::SunWindowTermTest;

void runStandingTiltError(SunWindowTermTest* t, backend::BundleWindow* window,
                          const SunFusionOptions& opt, SunWindowTerm* term,
                          const Isometry3& T_k_b_true,
                          const std::vector<backend::WindowObservation>& obs_b,
                          const std::vector<backend::WindowObservation>& obs_k) {
  (void)t;
  Isometry3 T_w_b_est = Isometry3::Identity();
  T_w_b_est.linear() = expSO3(Eigen::Vector3d(0.0, 0.0, 2.0 * kDeg));
  ASSERT_TRUE(term->init(opt).isOk());
  const Eigen::Vector3d up_w(0.0, -1.0, 0.0);
  for (std::uint64_t k = 1; k <= 41; k += 2) {
    window->reset(T_w_b_est);
    term->attach(*window);
    SunObservation up;
    up.sun_w = up_w;
    up.measurement.sequence = k;
    up.measurement.sigma = 0.01;
    up.measurement.sun_c = T_k_b_true.linear() * up_w;  // truth: C_b_w = I
    term->addVertical(up);
    const TimeNs time = static_cast<TimeNs>(k) * 100'000'000;
    ASSERT_TRUE(window->addFrame(k - 1, time - 100'000'000, obs_b, Isometry3::Identity()).isOk());
    ASSERT_TRUE(window->addFrame(k, time, obs_k, T_k_b_true).isOk());
    ASSERT_TRUE(window->solve());
  }
}

TEST_F(SunWindowTermTest, VerticalChannelIsCountedApartAndSplitsTheWalkByGravity) {
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.1;
  opt.innovation_gate_chi2 = 0.0;
  opt.max_drift_deg_per_frame = 0.5;
  ASSERT_TRUE(opt.split_drift_by_gravity);
  SunWindowTerm split;
  runStandingTiltError(this, &window_, opt, &split, T_k_b_true_, obs_b_, obs_k_);
  EXPECT_EQ(split.counters().total(), 0u);
  EXPECT_EQ(split.verticalCounters().accepted, 21u);
  // The standing tilt raises the tilt's walk; the heading's, which only the sun's measurements
  // move, stays at its start.
  EXPECT_GT(split.tiltDriftDegPerFrame(), 0.2);
  EXPECT_EQ(split.headingDriftDegPerFrame(), opt.attitude_drift_deg_per_frame);
  EXPECT_EQ(split.driftDegPerFrame(), split.tiltDriftDegPerFrame());
  // The last window's newest frame: most of its tilt is corrected (0.62 deg of 2 left, measured
  // 2026-11-26; each window starts from the same error, so this is one window's share).
  const Eigen::Vector3d e =
      logSO3(T_k_b_true_.linear().transpose() * window_.T_w_newest().linear().transpose());
  EXPECT_LT(std::hypot(e.x(), e.z()) / kDeg, 1.0);

  // One walk for all axes: the heading's grows with the tilt's.
  opt.split_drift_by_gravity = false;
  SunWindowTerm joint;
  runStandingTiltError(this, &window_, opt, &joint, T_k_b_true_, obs_b_, obs_k_);
  EXPECT_GT(joint.headingDriftDegPerFrame(), 0.2);
  EXPECT_EQ(joint.headingDriftDegPerFrame(), joint.tiltDriftDegPerFrame());
}

// An "up" measured better in one direction than the other (the vertical cue: a level camera's
// roll from the segments' image angles, its pitch from their convergence) corrects each axis of
// the tilt by its own sigma: with a 0.1 deg sigma along the camera's x axis (a turn about the
// optical axis moves "up" along x) and 1 deg across, one window removes most of a 1 deg roll error
// and, like the isotropic 1 deg measurement, little of a 1 deg pitch error.
TEST_F(SunWindowTermTest, VerticalWithAStrongAxisCorrectsThatAxisByItsOwnSigma) {
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.3;
  opt.innovation_gate_chi2 = 0.0;
  T_w_b_est_ = Isometry3::Identity();
  T_w_b_est_.linear() = expSO3(Eigen::Vector3d(1.0 * kDeg, 0.0, 1.0 * kDeg));
  const Eigen::Vector3d up_w(0.0, -1.0, 0.0);
  const auto tiltLeft = [&](double sigma_strong) {
    SunWindowTerm term;
    EXPECT_TRUE(term.init(opt).isOk());
    window_.reset(T_w_b_est_);
    term.attach(window_);
    SunObservation up;
    up.sun_w = up_w;
    up.measurement.sequence = 1;
    up.measurement.kind = SunMeasurementKind::kFull3d;
    up.measurement.sun_c = T_k_b_true_.linear() * up_w;  // truth: C_b_w = I
    up.measurement.sigma = 1.0 * kDeg;
    up.measurement.sigma_strong = sigma_strong;
    up.measurement.strong_axis_c = Eigen::Vector3d::UnitX();
    term.addVertical(up);
    EXPECT_TRUE(window_.addFrame(0, 0, obs_b_, Isometry3::Identity()).isOk());
    EXPECT_TRUE(window_.addFrame(1, 100'000'000, obs_k_, T_k_b_true_).isOk());
    EXPECT_TRUE(window_.solve());
    EXPECT_EQ(term.verticalCounters().accepted, 1u);
    const Eigen::Matrix3d dC = window_.T_w_newest().linear() * T_k_b_true_.linear();
    const Eigen::Vector3d e = logSO3(dC) / kDeg;
    return Eigen::Vector2d(std::abs(e.z()), std::abs(e.x()));  // roll, pitch (deg)
  };
  const Eigen::Vector2d iso = tiltLeft(0.0);
  const Eigen::Vector2d strong = tiltLeft(0.1 * kDeg);
  EXPECT_GT(iso.x(), 0.8);  // prior 0.3 deg against 1 deg: about 8 % is taken
  EXPECT_LT(strong.x(), 0.2 * iso.x());
  EXPECT_NEAR(strong.y(), iso.y(), 0.05);
  EXPECT_GT(strong.y(), 0.8);
}

}  // namespace
}  // namespace sunvo::sunfusion
