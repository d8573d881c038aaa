#include "sunvo/track_stats/track_stats.hpp"

#include <gtest/gtest.h>

#include "../support/exact_tracks.hpp"

namespace sunvo::track_stats {
namespace {

StereoCamera kittiCamera() {
  return {707.0912, 707.0912, 601.8873, 183.1104, 0.5372, 1226, 370};
}

// 1 m/frame along camera z with a gentle left turn in the middle.
std::vector<Isometry3> drive(int frames) {
  std::vector<Isometry3> T_0_k;
  Isometry3 T = Isometry3::Identity();
  for (int k = 0; k < frames; ++k) {
    T_0_k.push_back(T);
    Isometry3 step = Isometry3::Identity();
    step.translation() = Eigen::Vector3d(0, 0, 1.0);
    if (k >= frames / 3 && k < frames / 3 + 20) {
      step.linear() = Eigen::AngleAxisd(-M_PI / 80.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    }
    T = T * step;
  }
  return T_0_k;
}

std::vector<FrameFeatures> cleanTracks(const std::vector<Isometry3>& T_0_k) {
  return testing::exactTracks(T_0_k, kittiCamera());
}

TEST(TrackStats, CleanTracksHaveNoErrorAnywhere) {
  const auto T_0_k = drive(80);
  const auto frames = cleanTracks(T_0_k);
  auto s = computeTrackStats(kittiCamera(), frames, T_0_k, {}, TrackStatsOptions{});
  ASSERT_TRUE(s) << s.status().toString();
  ASSERT_EQ(s->frames.size(), 80u);
  for (std::size_t k = 1; k < s->frames.size(); ++k) {
    if (k < 60) {  // the route's landmarks end at 80 m
      ASSERT_GT(s->frames[k].pairs, 5) << k;
    }
    EXPECT_NEAR(s->frames[k].mean_du, 0.0, 1e-6) << k;
    EXPECT_NEAR(s->frames[k].mean_dv, 0.0, 1e-6) << k;
    EXPECT_NEAR(s->frames[k].mean_dd, 0.0, 1e-6) << k;
  }
  EXPECT_NEAR(s->plane.a_px, 0.0, 1e-9);
  EXPECT_NEAR(s->plane.b, 0.0, 1e-12);
  EXPECT_GT(s->mono_landmarks, 50u);
  for (const DepthBin& b : s->depth_bins) EXPECT_NEAR(b.mean_px, 0.0, 1e-5) << b.z_min_m;
  EXPECT_NEAR(s->flow.gain, 0.0, 1e-9);
  std::size_t pairs = 0;
  for (const ResidualDepthBin& b : s->residual_depths) {
    pairs += b.n;
    EXPECT_NEAR(b.mean_dv, 0.0, 1e-6) << b.z_min_m;
  }
  EXPECT_GT(pairs, 500u);
  EXPECT_TRUE(s->jumps.empty());
}

TEST(TrackStats, RecoversAnInjectedOffsetPlaneAndDisparityBias) {
  const auto T_0_k = drive(80);
  auto frames = cleanTracks(T_0_k);
  const StereoCamera cam = kittiCamera();
  // vL - vR = 0.11 + 0.75e-3 (uL - cu) - 0.55e-3 (vL - cv); d observed 0.3 px too small.
  for (FrameFeatures& f : frames) {
    for (StereoObservation& o : f.observations) {
      o.v_right -= 0.11 + 0.75e-3 * (o.u_left - cam.cu) - 0.55e-3 * (o.v_left - cam.cv);
      o.u_right += 0.3;
    }
  }
  auto s = computeTrackStats(cam, frames, T_0_k, {}, TrackStatsOptions{});
  ASSERT_TRUE(s) << s.status().toString();
  EXPECT_NEAR(s->plane.a_px, 0.11, 1e-9);
  EXPECT_NEAR(s->plane.b, 0.75e-3, 1e-12);
  EXPECT_NEAR(s->plane.c, -0.55e-3, 1e-12);
  EXPECT_NEAR(s->plane.rms_px, 0.0, 1e-9);
  ASSERT_FALSE(s->blocks.empty());
  EXPECT_NEAR(s->blocks.front().b, 0.75e-3, 1e-12);
  std::size_t used = 0;
  for (const DepthBin& b : s->depth_bins) {
    if (b.n == 0) continue;
    used += b.n;
    EXPECT_NEAR(b.mean_px, -0.3, 1e-5) << b.z_min_m;
  }
  EXPECT_GT(used, 100u);
  ASSERT_EQ(s->fraction_bins.size(), 10u);
  std::size_t by_fraction = 0;
  for (const FractionBin& b : s->fraction_bins) {
    by_fraction += b.n;
    if (b.n > 0) {
      EXPECT_NEAR(b.mean_px, -0.3, 1e-5) << b.f_min;
    }
  }
  EXPECT_EQ(by_fraction, used);
}

// A written image drive's tracks carry vR = vL where the front end did not measure the right row
// (v_right_measured false): those rows say nothing about the offset and must not pull it to 0.
TEST(TrackStats, UnmeasuredRightRowsAreLeftOutOfTheOffsetPlane) {
  const auto T_0_k = drive(80);
  auto frames = cleanTracks(T_0_k);
  const StereoCamera cam = kittiCamera();
  std::size_t i = 0;
  for (FrameFeatures& f : frames) {
    for (StereoObservation& o : f.observations) {
      if (i++ % 2 == 0) {
        o.v_right_measured = false;  // vR stays vL
      } else {
        o.v_right -= 0.2 + 0.5e-3 * (o.u_left - cam.cu);
      }
    }
  }
  auto s = computeTrackStats(cam, frames, T_0_k, {}, TrackStatsOptions{});
  ASSERT_TRUE(s) << s.status().toString();
  EXPECT_NEAR(s->plane.a_px, 0.2, 1e-9);
  EXPECT_NEAR(s->plane.b, 0.5e-3, 1e-12);
  EXPECT_NEAR(s->plane.rms_px, 0.0, 1e-9);
  ASSERT_FALSE(s->blocks.empty());
  EXPECT_NEAR(s->blocks.front().a_px, 0.2, 1e-9);
}

TEST(TrackStats, AnEstimateWithARollKickIsAJump) {
  const auto T_0_k = drive(60);
  const auto frames = cleanTracks(T_0_k);
  // The estimate follows the truth but turns 0.3 deg about camera z between frames 29 and 30.
  std::vector<Isometry3> est = T_0_k;
  Isometry3 kick = Isometry3::Identity();
  kick.linear() =
      Eigen::AngleAxisd(0.3 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (std::size_t k = 30; k < est.size(); ++k)
    est[k] = est[29] * kick * (T_0_k[29].inverse() * T_0_k[k]);
  auto s = computeTrackStats(kittiCamera(), frames, T_0_k, est, TrackStatsOptions{});
  ASSERT_TRUE(s) << s.status().toString();
  // The kick seen from camera 30, which is turning: mostly about z.
  EXPECT_NEAR(s->frames[30].rot_err_mdeg, 300.0, 1e-6);
  EXPECT_NEAR(s->frames[30].rot_err_c_mdeg.z(), 300.0, 1.0);
  EXPECT_NEAR(s->frames[31].rot_err_mdeg, 0.0, 1e-6);
  ASSERT_EQ(s->jumps.size(), 1u);
  EXPECT_EQ(s->jumps[0].frame, 30);
  EXPECT_TRUE(s->jumps[0].rotation);
  EXPECT_FALSE(s->jumps[0].residual);
}

TEST(TrackStats, RejectsBadInput) {
  const auto T_0_k = drive(20);
  const auto frames = cleanTracks(T_0_k);
  TrackStatsOptions bad;
  bad.block_frames = 5;
  EXPECT_EQ(computeTrackStats(kittiCamera(), frames, T_0_k, {}, bad).status().code(),
            StatusCode::kInvalidArgument);
  const std::vector<Isometry3> short_gt(T_0_k.begin(), T_0_k.begin() + 10);
  EXPECT_EQ(computeTrackStats(kittiCamera(), frames, short_gt, {}, TrackStatsOptions{})
                .status()
                .message(),
            "track stats: 10 ground-truth poses for 20 frames");
}

}  // namespace
}  // namespace sunvo::track_stats
