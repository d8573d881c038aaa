#include "sunvo/pipeline/sun_aided_odometry.hpp"

#include <gtest/gtest.h>

#include <vector>

#ifdef SUNVO_HAVE_ALLOC_COUNTER
#include "sunvo/runtime/alloc_counter.hpp"
#endif

#include "../support/kitti_first_frames.hpp"
#include "../support/synthetic_stereo.hpp"

namespace sunvo::pipeline {
namespace {

using testing::forwardMotion;
using testing::kittiCamera;
using testing::makeLandmarks;
using testing::observe;
using testing::rotationErrorDeg;
using testing::SceneOptions;
using testing::trajectory;

constexpr double kDeg = M_PI / 180.0;
constexpr int kFrames = 60;

// A synthetic drive (world = camera 0 of the true first frame) whose estimate starts with a 2 deg
// attitude error, as a rover's level and compass would give it.
class SunAidedOdometryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    camera_ = kittiCamera();
    SceneOptions so;
    so.pixel_noise_px = 0.5;
    const auto pts = makeLandmarks(so, 80.0);
    T_w_k_ = trajectory(kFrames, forwardMotion(1.0, 0.3));
    for (int k = 0; k < kFrames; ++k) {
      frames_.push_back(observe(camera_, pts, T_w_k_[static_cast<std::size_t>(k)].inverse(),
                                static_cast<std::uint64_t>(k), so));
    }
    // The sun 40 deg above the horizon to the front-right; up is -y in this world. One sun
    // direction observes the two rotation axes orthogonal to it: the start error is about one.
    sun_w_ = Eigen::Vector3d(0.5, -std::sin(40.0 * kDeg), 0.7).normalized();
    const Eigen::Vector3d axis = sun_w_.cross(Eigen::Vector3d::UnitY()).normalized();
    T_w_c0_ = Isometry3::Identity();
    T_w_c0_.linear() = expSO3(2.0 * kDeg * axis);
    options_.fusion.world_up = -Eigen::Vector3d::UnitY();
    options_.fusion.initial_attitude_sigma_deg = 3.0;
    options_.pipeline.vo.window.max_solver_time_in_seconds = 10.0;  // bounded by iterations
  }

  // Runs the drive; returns the final rotation error in degrees.
  double run(SunAidedOdometry* odo) {
    EXPECT_TRUE(odo->init(options_, camera_, T_w_c0_, OdometryInput::kFeatures).isOk());
    for (int k = 0; k < kFrames; ++k) {
      const Isometry3& T_w_k = T_w_k_[static_cast<std::size_t>(k)];
      if (odo->isSunFrame(static_cast<std::uint64_t>(k))) {
        sunfusion::SunObservation obs;
        obs.measurement.sequence = static_cast<std::uint64_t>(k);
        obs.measurement.sun_c = T_w_k.linear().transpose() * sun_w_;
        obs.measurement.sigma = 0.02;
        obs.sun_w = sun_w_;
        odo->addSun(obs);
      }
      auto r = odo->process(frames_[static_cast<std::size_t>(k)]);
      EXPECT_TRUE(r) << r.status().toString();
      poses_.push_back(odo->T_w_c());
    }
    return rotationErrorDeg(odo->T_w_c(), T_w_k_.back());
  }

  StereoCamera camera_;
  std::vector<Isometry3> T_w_k_;
  std::vector<FrameFeatures> frames_;
  Isometry3 T_w_c0_;
  Eigen::Vector3d sun_w_;
  SunAidedOptions options_;
  std::vector<Isometry3> poses_;
};

TEST_F(SunAidedOdometryTest, TheSunPullsAWrongStartAttitudeBack) {
  options_.use_sun = false;
  SunAidedOdometry pure;
  const double pure_err = run(&pure);
  EXPECT_EQ(pure.sunCounters().total(), 0u);
  EXPECT_GT(pure_err, 1.8);  // VO keeps the start error

  options_.use_sun = true;
  SunAidedOdometry aided;
  const double sun_err = run(&aided);
  // Frames 5, 10, ..., 55: eleven measurements, all accepted.
  EXPECT_EQ(aided.sunOffered(), 11u);
  EXPECT_EQ(aided.sunCounters().total(), 11u);
  EXPECT_EQ(aided.sunCounters().accepted, 11u);
  EXPECT_LT(sun_err, 0.25 * pure_err) << "pure " << pure_err << " deg, sun " << sun_err << " deg";
  // The covariance shrank from the 3 deg prior on the two axes one sun direction observes; the
  // rotation about the sun stays near its prior.
  const double prior_var = (3.0 * kDeg) * (3.0 * kDeg);
  EXPECT_LT(aided.attitudeCovariance().trace(), 0.5 * 3.0 * prior_var);
  const double about_sun = sun_w_.dot(aided.attitudeCovariance() * sun_w_);
  EXPECT_GT(about_sun, 0.9 * prior_var);
}

// Issue 19: no heap allocation per sun frame. Feature input, a sun and an "up" measurement every
// fifth frame, with and without the bias state: after a warm-up the frames allocate nothing, the
// sun frames included.
TEST_F(SunAidedOdometryTest, SunFramesAllocateNothing) {
#if !defined(SUNVO_HAVE_ALLOC_COUNTER)
  GTEST_SKIP() << "no allocation counter in this build";
#else
  ASSERT_TRUE(runtime::allocCounterActive());
  for (const double bias_deg : {0.0, 5.0}) {
    options_.fusion.sun_bias_sigma_deg = bias_deg;
    SunAidedOdometry odo;
    ASSERT_TRUE(odo.init(options_, camera_, T_w_c0_, OdometryInput::kFeatures).isOk());
    std::uint64_t sun_frames = 0, allocations = 0;
    for (int k = 0; k < kFrames; ++k) {
      const auto seq = static_cast<std::uint64_t>(k);
      const Isometry3& T_w_k = T_w_k_[static_cast<std::size_t>(k)];
      const std::uint64_t before = runtime::allocationCount();
      if (odo.isSunFrame(seq)) {
        sunfusion::SunObservation sun;
        sun.measurement.sequence = seq;
        sun.measurement.sun_c = T_w_k.linear().transpose() * sun_w_;
        sun.measurement.sigma = 0.02;
        sun.sun_w = sun_w_;
        odo.addSun(sun);
        sunfusion::SunObservation up = sun;
        up.sun_w = options_.fusion.world_up;
        up.measurement.sun_c = T_w_k.linear().transpose() * up.sun_w;
        odo.addVertical(up);
        if (k >= 20) ++sun_frames;
      }
      ASSERT_TRUE(odo.process(frames_[static_cast<std::size_t>(k)]));
      if (k >= 20) allocations += runtime::allocationCount() - before;
    }
    EXPECT_EQ(sun_frames, 8u);
    EXPECT_EQ(odo.sunCounters().accepted, 11u) << "bias " << bias_deg;
    EXPECT_EQ(allocations, 0u) << "frames 20..59, bias state " << bias_deg << " deg";
  }
#endif
}

TEST_F(SunAidedOdometryTest, PureVoIsTheBackEndAlone) {
  options_.use_sun = false;
  SunAidedOdometry pure;
  run(&pure);
  vo::StereoTrackOdometry back;
  ASSERT_TRUE(back.init(options_.pipeline.vo, camera_, T_w_c0_).isOk());
  for (int k = 0; k < kFrames; ++k) {
    auto r = back.process(frames_[static_cast<std::size_t>(k)]);
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->T_w_c.isApprox(poses_[static_cast<std::size_t>(k)], 1e-12)) << k;
  }
}

TEST_F(SunAidedOdometryTest, AnUpCueFixesTheTiltNotTheHeading) {
  // Start 2 deg off in roll (about the camera's z, a tilt) and 2 deg off in heading (about up).
  // With feature input there are no images: the image cue is inactive, and "up" comes from
  // another source (here the truth, 0.3 deg sigma) through addVertical on the every-n frames.
  const Eigen::Vector3d up_w = -Eigen::Vector3d::UnitY();
  T_w_c0_.linear() = expSO3(2.0 * kDeg * Eigen::Vector3d::UnitZ() + 2.0 * kDeg * up_w);
  options_.use_sun = false;
  options_.vertical.enabled = true;
  SunAidedOdometry odo;
  ASSERT_TRUE(odo.init(options_, camera_, T_w_c0_, OdometryInput::kFeatures).isOk());
  EXPECT_FALSE(odo.verticalActive());
  for (int k = 0; k < kFrames; ++k) {
    const auto seq = static_cast<std::uint64_t>(k);
    EXPECT_EQ(odo.isSunFrame(seq), false);
    if (odo.isCueFrame(seq)) {
      sunfusion::SunObservation obs;
      obs.measurement.sequence = seq;
      obs.measurement.sun_c = T_w_k_[static_cast<std::size_t>(k)].linear().transpose() * up_w;
      obs.measurement.sigma = 0.3 * kDeg;
      obs.sun_w = up_w;
      odo.addVertical(obs);
    }
    ASSERT_TRUE(odo.process(frames_[static_cast<std::size_t>(k)]));
  }
  EXPECT_EQ(odo.verticalCounters().accepted, 11u);
  EXPECT_EQ(odo.sunCounters().total(), 0u);
  // C_w_true = Exp(e) C_w_est: split e into tilt and heading.
  const Eigen::Vector3d e =
      logSO3(T_w_k_.back().linear() * odo.T_w_c().linear().transpose()) / kDeg;
  const double heading = e.dot(up_w);
  const double tilt = (e - heading * up_w).norm();
  EXPECT_LT(tilt, 0.5) << "tilt " << tilt << " deg";
  EXPECT_GT(std::abs(heading), 1.8) << "heading " << heading << " deg";
}

TEST(SunAidedOdometryImages, TheImageCueMeasuresUpOnRealFrames) {
  // The 11 real KITTI frames, a cue on every frame after the first: each call answers (the
  // street has poles and facades), nothing is refused as bad input, and no pose is NaN.
  auto data = testing::loadKittiFirstFrames();
  ASSERT_TRUE(data) << data.status().toString();
  SunAidedOptions options;
  options.use_sun = false;
  options.every_n_frames = 1;
  options.vertical.enabled = true;
  options.fusion.world_up = -Eigen::Vector3d::UnitY();
  options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;
  SunAidedOdometry odo;
  ASSERT_TRUE(odo.init(options, data->camera, Isometry3::Identity()).isOk());
  EXPECT_TRUE(odo.verticalActive());
  for (const StereoFrame& f : data->frames) {
    auto r = odo.process(f);
    ASSERT_TRUE(r) << r.status().toString();
    ASSERT_TRUE(allFinite(r->vo.T_w_c));
  }
  const auto n = static_cast<std::uint64_t>(data->frames.size());
  EXPECT_EQ(odo.verticalStats().calls, n - 1);
  EXPECT_EQ(odo.verticalStats().errors, 0u);
  EXPECT_GE(odo.verticalStats().valid, n - 3);
  EXPECT_EQ(odo.verticalCounters().total(), odo.verticalStats().valid);
  EXPECT_EQ(odo.sunCounters().total(), 0u);
  EXPECT_TRUE(odo.attitudeCovariance().allFinite());
}

TEST_F(SunAidedOdometryTest, FeatureInputSelfCalibratesTheTracksRightRows) {
  // Right rows 0.3 px below the left ones (a right camera pitched by 0.3 px / fv): with feature
  // input the self-calibration runs on the tracks before the back end, with no front end and so
  // no frontend.measure_v_right, and reports what the stand-alone filter reports.
  for (FrameFeatures& f : frames_) {
    for (StereoObservation& o : f.observations) o.v_right += 0.3;
  }
  options_.use_sun = false;
  options_.pipeline.self_calibration.enabled = true;
  ASSERT_FALSE(options_.pipeline.frontend.measure_v_right);
  SunAidedOdometry odo;
  ASSERT_TRUE(odo.init(options_, camera_, T_w_c0_, OdometryInput::kFeatures).isOk());
  selfcal::StereoSelfCalibration alone;
  ASSERT_TRUE(alone.init(options_.pipeline.self_calibration, camera_).isOk());
  FrameFeatures corrected;
  for (const FrameFeatures& f : frames_) {
    ASSERT_TRUE(odo.process(f));
    const selfcal::SelfCalibrationReport expected = alone.process(f, &corrected);
    EXPECT_EQ(odo.lastSelfCalibration().pitch_mrad, expected.pitch_mrad);
    EXPECT_EQ(odo.lastSelfCalibration().roll_mrad, expected.roll_mrad);
  }
  EXPECT_NEAR(odo.lastSelfCalibration().pitch_mrad, 0.3 / camera_.fv * 1e3, 0.05);
  EXPECT_EQ(odo.lastSelfCalibration().resets, 0u);
  // The image pipeline still needs the right rows measured.
  const Status images = odo.init(options_, camera_, T_w_c0_, OdometryInput::kImages);
  EXPECT_NE(images.message().find("self_calibration.enabled"), std::string::npos);
}

TEST_F(SunAidedOdometryTest, ScheduleInputsAndOptionsAreChecked) {
  SunAidedOdometry odo;
  options_.every_n_frames = 3;
  ASSERT_TRUE(odo.init(options_, camera_, T_w_c0_, OdometryInput::kFeatures).isOk());
  EXPECT_FALSE(odo.isSunFrame(0));
  EXPECT_TRUE(odo.isSunFrame(3));
  EXPECT_FALSE(odo.isSunFrame(4));
  EXPECT_TRUE(odo.isSunFrame(6));
  EXPECT_TRUE(odo.T_w_c().isApprox(T_w_c0_));
  // Images into a feature-input estimator: a clear error, not a crash.
  StereoFrame frame;
  EXPECT_EQ(odo.process(frame).status().code(), StatusCode::kFailedPrecondition);

  options_.every_n_frames = 0;
  const Status bad = odo.init(options_, camera_, T_w_c0_, OdometryInput::kFeatures);
  EXPECT_EQ(bad.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.message().find("every_n_frames"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::pipeline
