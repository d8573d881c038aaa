// SunAidedOdometry (the estimator every program calls) on degenerate images between real KITTI
// frames: an all-sky frame (a smooth vertical gradient, no corners), a textureless grey frame and
// a fully dark frame, with a sun measurement offered on the dark one, then a sun below the
// horizon. Never an error, never NaN, no stall; the frames are reported lost, tracking comes
// back on the real frames, and the sun below the horizon is skipped and counted.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "../support/kitti_first_frames.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"

namespace sunvo::pipeline {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool finitePose(const Isometry3& T) {
  return T.matrix().allFinite();
}

TEST(DegenerateFrames, SkyTexturelessAndDarkFramesAreLostNotNaNAndTrackingReturns) {
  auto data = testing::loadKittiFirstFrames();
  ASSERT_TRUE(data) << data.status().toString();
  ASSERT_EQ(data->frames.size(), 11u);
  const int h = data->camera.height;
  const int w = data->camera.width;
  // All sky: brighter towards the horizon, the same in both eyes (no texture, no disparity).
  cv::Mat sky(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) sky.row(v).setTo(cv::Scalar(120 + (110 * v) / h));
  cv::GaussianBlur(sky, sky, cv::Size(0, 0), 3.0);
  const cv::Mat grey(h, w, CV_8UC1, cv::Scalar(128));
  const cv::Mat dark(h, w, CV_8UC1, cv::Scalar(0));
  std::vector<StereoFrame> frames = data->frames;
  frames[3].left = sky;
  frames[3].right = sky.clone();
  frames[4].left = grey;
  frames[4].right = grey.clone();
  frames[5].left = dark;
  frames[5].right = dark.clone();

  SunAidedOptions options;
  options.every_n_frames = 5;                                    // sun frames 5 (dark) and 10
  options.fusion.world_up = -Eigen::Vector3d::UnitY();           // the world is camera 0 of frame 0
  options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;  // bounded by iterations
  SunAidedOdometry odo;
  ASSERT_TRUE(odo.init(options, data->camera, Isometry3::Identity()).isOk());
  // 40 deg above the horizon (up = -y), and 10 deg below it.
  const Eigen::Vector3d sun_day_w = Eigen::Vector3d(0.5, -std::sin(40.0 * kDeg), 0.7).normalized();
  const Eigen::Vector3d sun_night_w =
      Eigen::Vector3d(0.5, std::sin(10.0 * kDeg), 0.85).normalized();

  std::vector<vo::TrackingStatus> status;
  double slowest_s = 0.0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (odo.isSunFrame(frames[k].sequence)) {
      const Eigen::Vector3d sun_w = k == 5 ? sun_day_w : sun_night_w;
      sunfusion::SunObservation obs;
      obs.measurement.sequence = frames[k].sequence;
      obs.measurement.time_ns = frames[k].trigger_time_ns;
      // In camera k as the last pose predicts it (the drive barely turns in 11 frames).
      obs.measurement.sun_c = odo.T_w_c().linear().transpose() * sun_w;
      obs.measurement.sigma = 0.02;
      obs.sun_w = sun_w;
      odo.addSun(obs);
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto r = odo.process(frames[k]);
    slowest_s = std::max(
        slowest_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    ASSERT_TRUE(r.hasValue()) << "frame " << k << ": " << r.status().toString();
    ASSERT_TRUE(finitePose(r->vo.T_w_c)) << "frame " << k;
    ASSERT_TRUE(finitePose(odo.T_w_c())) << "frame " << k;
    ASSERT_TRUE(odo.attitudeCovariance().allFinite()) << "frame " << k;
    std::printf("frame %2zu: %-12s %4d features %3d inliers\n", k, vo::toString(r->vo.status),
                r->num_features, r->vo.ransac_inliers);
    status.push_back(r->vo.status);
  }
  std::printf("slowest frame %.3f s\n", slowest_s);
  // No stall: a degenerate frame costs no more than a normal one (0.009 s at most here); 2 s is a
  // bound that only a hang or a solver running away would break.
  EXPECT_LT(slowest_s, 2.0);
  for (std::size_t k = 1; k <= 2; ++k) EXPECT_EQ(status[k], vo::TrackingStatus::kTracking) << k;
  for (std::size_t k = 3; k <= 5; ++k) EXPECT_EQ(status[k], vo::TrackingStatus::kLost) << k;
  // Frame 6 has only new features (none survived the bad frames); 7 matches it and recovers.
  EXPECT_EQ(status[7], vo::TrackingStatus::kRecovered);
  for (std::size_t k = 8; k <= 10; ++k) EXPECT_EQ(status[k], vo::TrackingStatus::kTracking) << k;
  // The sun below the horizon (frame 10) is skipped and counted. The one offered on the dark
  // frame never reaches the gate: a lost frame is never solved in the window, so it is offered
  // but not decided (sunOffered() - sunCounters().total()).
  EXPECT_EQ(odo.sunOffered(), 2u);
  EXPECT_EQ(odo.sunCounters().rejected_sun_down, 1u);
  EXPECT_EQ(odo.sunCounters().total(), 1u);
}

}  // namespace
}  // namespace sunvo::pipeline
