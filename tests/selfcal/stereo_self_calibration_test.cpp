#include "sunvo/selfcal/stereo_self_calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sunvo/simtracks/simulated_tracks.hpp"

namespace sunvo::selfcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

StereoCamera camera() {
  return {707.0912, 707.0912, 601.8873, 183.1104, 0.5372, 1226, 370};
}

std::vector<FrameFeatures> tracks(int frames, double noise_px) {
  std::vector<Isometry3> T_w_c;
  Isometry3 T = Isometry3::Identity();
  for (int k = 0; k < frames; ++k) {
    T_w_c.push_back(T);
    T.translation().z() += 1.0;
  }
  simtracks::SimTrackOptions sim;
  sim.pixel_noise_px = noise_px;
  sim.outlier_share = 0.0;
  auto f = simtracks::simulateTracks(T_w_c, {}, camera(), sim);
  EXPECT_TRUE(f) << f.status().toString();
  return f ? *f : std::vector<FrameFeatures>();
}

// The right camera pitched by delta and rolled by theta (the header's first-order model).
void miscalibrate(std::vector<FrameFeatures>& frames, double delta, double theta) {
  const StereoCamera c = camera();
  for (FrameFeatures& f : frames) {
    for (StereoObservation& o : f.observations) {
      const double u = o.u_right, v = o.v_right;
      o.u_right = u - theta * (v - c.cv);
      o.v_right = v + c.fv * delta + theta * (u - c.cu);
    }
  }
}

StereoSelfCalibrationOptions on() {
  StereoSelfCalibrationOptions o;
  o.enabled = true;
  return o;
}

TEST(StereoSelfCalibration, RecoversAnInjectedRightCameraRotation) {
  auto frames = tracks(200, 0.3);
  miscalibrate(frames, 0.03 * kDeg, 0.05 * kDeg);
  StereoSelfCalibration cal;
  ASSERT_TRUE(cal.init(on(), camera()).isOk());
  FrameFeatures out;
  SelfCalibrationReport r;
  for (std::size_t k = 0; k < 150; ++k) {  // the route's landmarks thin out at its end
    r = cal.process(frames[k], &out);
    EXPECT_TRUE(r.updated) << k;
  }
  EXPECT_EQ(r.resets, 0u);
  EXPECT_NEAR(r.roll_mrad, 0.05 * kDeg * 1e3, 0.01 * kDeg * 1e3);  // issue 15: within 0.01 deg
  EXPECT_NEAR(r.pitch_mrad, 0.03 * kDeg * 1e3, 0.01 * kDeg * 1e3);
  EXPECT_GT(r.used, 20);
  EXPECT_LT(r.roll_sigma_mrad, 0.01 * kDeg * 1e3);
}

// A rig that warms up turns its right camera as a ramp. The drift rate follows it; the random walk
// alone trails it by rate / gain.
TEST(StereoSelfCalibration, FollowsARampingRigWithItsDriftRate) {
  const auto clean = tracks(200, 0.3);
  constexpr int kFrames = 150;
  const double roll_rate = 6e-4 * kDeg;  // rad per frame: 0.09 deg over the frames used
  const double pitch_rate = -2e-4 * kDeg;
  auto frames = clean;
  for (int k = 0; k < kFrames; ++k) {
    std::vector<FrameFeatures> one{frames[static_cast<std::size_t>(k)]};
    miscalibrate(one, 0.02 * kDeg + pitch_rate * k, 0.01 * kDeg + roll_rate * k);
    frames[static_cast<std::size_t>(k)] = one[0];
  }
  auto lag = [&](double rate_sigma_deg, SelfCalibrationReport* last) {
    StereoSelfCalibrationOptions o = on();
    o.drift_rate_sigma_deg = rate_sigma_deg;
    StereoSelfCalibration cal;
    EXPECT_TRUE(cal.init(o, camera()).isOk());
    FrameFeatures out;
    for (int k = 0; k < kFrames; ++k)
      *last = cal.process(frames[static_cast<std::size_t>(k)], &out);
    return std::abs(last->roll_mrad * 1e-3 - (0.01 * kDeg + roll_rate * (kFrames - 1))) / kDeg;
  };
  SelfCalibrationReport with_rate, without;
  const double lag_rate = lag(5e-4, &with_rate);
  const double lag_walk = lag(0.0, &without);
  EXPECT_LT(lag_rate, 0.005);  // deg
  EXPECT_GT(lag_walk, 0.01);   // deg: the random walk of 1e-4 deg/frame alone trails the ramp
  EXPECT_NEAR(with_rate.roll_rate_urad * 1e-6, roll_rate, 0.25 * roll_rate);
  EXPECT_NEAR(with_rate.pitch_mrad * 1e-3, 0.02 * kDeg + pitch_rate * (kFrames - 1), 0.005 * kDeg);
  EXPECT_EQ(without.roll_rate_urad, 0.0);
  EXPECT_EQ(with_rate.resets, 0u);
}

// Observations whose right row was not measured (v_right_measured = false: the image front end
// found no row information in the window) carry no information and are not used, whatever their
// v_right says.
TEST(StereoSelfCalibration, UnmeasuredRightRowsAreNotUsed) {
  auto frames = tracks(50, 0.3);
  miscalibrate(frames, 0.2 * kDeg, 0.0);
  for (FrameFeatures& f : frames) {
    for (StereoObservation& o : f.observations) o.v_right_measured = false;
  }
  StereoSelfCalibration cal;
  ASSERT_TRUE(cal.init(on(), camera()).isOk());
  FrameFeatures out;
  SelfCalibrationReport r;
  for (const FrameFeatures& f : frames) r = cal.process(f, &out);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(r.used, 0);
  EXPECT_EQ(r.pitch_mrad, 0.0);
  EXPECT_EQ(r.roll_mrad, 0.0);
}

TEST(StereoSelfCalibration, CorrectsTheDisparityAndLeavesCleanDataAlone) {
  const auto clean = tracks(120, 0.0);
  auto bent = clean;
  miscalibrate(bent, 0.0, 0.08 * kDeg);
  StereoSelfCalibration cal, cal_clean;
  ASSERT_TRUE(cal.init(on(), camera()).isOk());
  ASSERT_TRUE(cal_clean.init(on(), camera()).isOk());
  FrameFeatures out, out_clean;
  double before = 0.0, after = 0.0;
  for (std::size_t k = 0; k < clean.size(); ++k) {
    cal.process(bent[k], &out);
    const auto r = cal_clean.process(clean[k], &out_clean);
    EXPECT_NEAR(r.roll_mrad, 0.0, 1e-9);
    ASSERT_EQ(out.observations.size(), clean[k].observations.size());
    if (k < 100) continue;  // converged
    for (std::size_t i = 0; i < out.observations.size(); ++i) {
      before = std::max(
          before, std::abs(bent[k].observations[i].u_right - clean[k].observations[i].u_right));
      after =
          std::max(after, std::abs(out.observations[i].u_right - clean[k].observations[i].u_right));
      EXPECT_DOUBLE_EQ(out_clean.observations[i].u_right, clean[k].observations[i].u_right);
    }
  }
  EXPECT_GT(before, 0.1);   // the roll bends uR by up to 0.25 px at the top and bottom rows
  EXPECT_LT(after, 0.005);  // second-order terms of the model
}

TEST(StereoSelfCalibration, DivergenceIsResetAndCountedNeverNaN) {
  auto frames = tracks(30, 0.3);
  miscalibrate(frames, 0.0, 0.05 * kDeg);
  frames[3].observations[0].v_right = std::numeric_limits<double>::quiet_NaN();
  StereoSelfCalibrationOptions o = on();
  o.max_angle_deg = 0.02;  // the true 0.05 deg roll is beyond it: every converged frame resets
  StereoSelfCalibration cal;
  ASSERT_TRUE(cal.init(o, camera()).isOk());
  FrameFeatures out;
  int resets = 0;
  for (const FrameFeatures& f : frames) {
    const auto r = cal.process(f, &out);
    resets += r.reset;
    EXPECT_TRUE(cal.state().allFinite());
    if (r.reset) {
      // Passed on as measured.
      EXPECT_DOUBLE_EQ(out.observations[1].u_right, f.observations[1].u_right);
    }
  }
  EXPECT_GT(resets, 0);
  EXPECT_EQ(cal.resets(), static_cast<std::uint64_t>(resets));
}

TEST(StereoSelfCalibration, OffPassesThroughAndOptionsAreChecked) {
  const auto frames = tracks(30, 0.3);
  StereoSelfCalibration cal;
  ASSERT_TRUE(cal.init(StereoSelfCalibrationOptions{}, camera()).isOk());
  FrameFeatures out;
  const auto r = cal.process(frames[2], &out);
  EXPECT_FALSE(r.updated);
  ASSERT_EQ(out.observations.size(), frames[2].observations.size());
  ASSERT_FALSE(out.observations.empty());
  EXPECT_DOUBLE_EQ(out.observations[0].v_right, frames[2].observations[0].v_right);
  StereoSelfCalibrationOptions bad = on();
  bad.gate_px = 0.0;
  EXPECT_EQ(cal.init(bad, camera()).message(), "self_calibration.gate_px outside (0, 50] px");
}

// An entered disparity bias a (d_measured = d + a) is taken out of every uR, with the estimation
// off and on; with it on, the rows still give the roll, and the bias does not reach them.
TEST(StereoSelfCalibration, TakesOutAnEnteredDisparityBias) {
  constexpr double kBias = -0.37;  // px: 0020's, docs/disparity_bias.md
  const auto clean = tracks(120, 0.0);
  auto biased = clean;
  miscalibrate(biased, 0.0, 0.08 * kDeg);
  for (FrameFeatures& f : biased) {
    for (StereoObservation& o : f.observations) o.u_right -= kBias;  // uL - uR grows by a
  }
  StereoSelfCalibrationOptions off;
  off.disparity_bias_px = kBias;
  StereoSelfCalibrationOptions est = on();
  est.disparity_bias_px = kBias;
  StereoSelfCalibration cal_off, cal_on, plain;
  ASSERT_TRUE(cal_off.init(off, camera()).isOk());
  ASSERT_TRUE(cal_on.init(est, camera()).isOk());
  ASSERT_TRUE(plain.init(StereoSelfCalibrationOptions{}, camera()).isOk());
  EXPECT_TRUE(cal_off.active());
  EXPECT_FALSE(cal_off.enabled());
  EXPECT_FALSE(plain.active());
  FrameFeatures out_off, out_on;
  SelfCalibrationReport r;
  double worst_on = 0.0;
  for (std::size_t k = 0; k < clean.size(); ++k) {
    cal_off.process(biased[k], &out_off);
    r = cal_on.process(biased[k], &out_on);
    ASSERT_EQ(out_off.observations.size(), clean[k].observations.size());
    ASSERT_EQ(out_on.observations.size(), clean[k].observations.size());
    for (std::size_t i = 0; i < clean[k].observations.size(); ++i) {
      EXPECT_NEAR(out_off.observations[i].u_right, biased[k].observations[i].u_right + kBias,
                  1e-12);
      EXPECT_DOUBLE_EQ(out_off.observations[i].v_right, biased[k].observations[i].v_right);
      if (k >= 100) {  // converged: the roll out too
        worst_on = std::max(
            worst_on, std::abs(out_on.observations[i].u_right - clean[k].observations[i].u_right));
      }
    }
  }
  EXPECT_NEAR(r.roll_mrad, 0.08 * kDeg * 1e3, 0.01);
  EXPECT_LT(worst_on, 0.005);
  StereoSelfCalibrationOptions bad;
  bad.disparity_bias_px = 6.0;
  EXPECT_EQ(plain.init(bad, camera()).message(),
            "self_calibration.disparity_bias_px outside [-5, 5] px");
}

TEST(StereoSelfCalibration, ReportCsvRowMatchesItsHeader) {
  SelfCalibrationReport r;
  r.pitch_mrad = -0.15112;
  r.roll_mrad = -0.78821;
  r.scale = 0.0006171;
  r.roll_sigma_mrad = 0.01437;
  r.used = 207;
  r.reset = true;
  r.pitch_rate_urad = 0.0123;
  r.roll_rate_urad = -5.8171;
  EXPECT_STREQ(kReportCsvHeader,
               "frame,pitch_mrad,roll_mrad,scale,roll_sigma_mrad,used,reset,pitch_rate_urad,"
               "roll_rate_urad\n");
  EXPECT_EQ(reportCsvRow(42, r), "42,-0.15112,-0.78821,0.0006171,0.01437,207,1,0.0123,-5.8171\n");
}

}  // namespace
}  // namespace sunvo::selfcal
