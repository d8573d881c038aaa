#include "sunvo/simtracks/simulated_tracks.hpp"

#include <gtest/gtest.h>

#include <map>

namespace sunvo::simtracks {
namespace {

StereoCamera kittiCamera() {
  return {718.856, 718.856, 607.1928, 185.2157, 0.53716, 1241, 376};
}

// A straight 1 m/frame drive along camera z, then a 90 degree left turn.
std::vector<Isometry3> drive(int frames) {
  std::vector<Isometry3> T_w_c;
  Isometry3 T = Isometry3::Identity();
  for (int k = 0; k < frames; ++k) {
    T_w_c.push_back(T);
    Isometry3 step = Isometry3::Identity();
    step.translation() = Eigen::Vector3d(0, 0, 1.0);
    if (k >= frames / 2 && k < frames / 2 + 15) {
      step.linear() = Eigen::AngleAxisd(-M_PI / 30.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    }
    T = T * step;
  }
  return T_w_c;
}

TEST(SimulatedTracks, NoiseFreeObservationsProjectExactly) {
  SimTrackOptions opt;
  opt.pixel_noise_px = 0.0;
  opt.outlier_share = 0.0;
  const auto poses = drive(60);
  const StereoCamera cam = kittiCamera();
  auto frames = simulateTracks(poses, {}, cam, opt);
  ASSERT_TRUE(frames) << frames.status().toString();
  ASSERT_EQ(frames->size(), poses.size());
  // Every pair of observations of one id in consecutive frames must come from one 3-D point:
  // triangulating in frame k-1 and reprojecting into frame k reproduces the observation.
  int checked = 0;
  for (std::size_t k = 1; k < frames->size(); ++k) {
    std::map<std::int64_t, StereoObservation> prev;
    for (const auto& o : (*frames)[k - 1].observations) prev[o.landmark_id] = o;
    const Isometry3 T_k_km1 = poses[k].inverse() * poses[k - 1];
    for (const auto& o : (*frames)[k].observations) {
      auto it = prev.find(o.landmark_id);
      if (it == prev.end()) continue;
      const Eigen::Vector3d p_km1 =
          cam.triangulate(it->second.u_left, it->second.v_left, it->second.disparity());
      const Eigen::Vector3d y = cam.project(T_k_km1 * p_km1);
      EXPECT_NEAR(y.x(), o.u_left, 1e-6);
      EXPECT_NEAR(y.y(), o.v_left, 1e-6);
      EXPECT_NEAR(y.z(), o.disparity(), 1e-6);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(SimulatedTracks, TrackLengthsFollowTheConfiguredMean) {
  SimTrackOptions opt;
  opt.mean_track_length = 8.0;
  auto frames = simulateTracks(drive(200), {}, kittiCamera(), opt);
  ASSERT_TRUE(frames);
  std::map<std::int64_t, int> length;
  std::size_t total = 0;
  for (const auto& f : *frames) {
    EXPECT_LE(f.observations.size(), static_cast<std::size_t>(opt.max_features_per_frame));
    total += f.observations.size();
    for (const auto& o : f.observations) ++length[o.landmark_id];
  }
  EXPECT_GT(total / frames->size(), 100u);  // a street this dense fills the per-frame cap
  double mean = 0.0;
  for (const auto& [id, n] : length) mean += n;
  mean /= static_cast<double>(length.size());
  // Visibility also ends tracks, so the mean is below the survival mean but of its order.
  EXPECT_GT(mean, 3.0);
  EXPECT_LT(mean, 8.0);
}

TEST(SimulatedTracks, DeterministicForASeedAndDifferentAcrossSeeds) {
  SimTrackOptions opt;
  const auto poses = drive(40);
  auto a = simulateTracks(poses, {}, kittiCamera(), opt);
  auto b = simulateTracks(poses, {}, kittiCamera(), opt);
  opt.seed = 2;
  auto c = simulateTracks(poses, {}, kittiCamera(), opt);
  ASSERT_TRUE(a && b && c);
  ASSERT_EQ((*a)[20].observations.size(), (*b)[20].observations.size());
  EXPECT_EQ((*a)[20].observations[5].u_left, (*b)[20].observations[5].u_left);
  EXPECT_NE((*a)[20].observations[5].u_left, (*c)[20].observations[5].u_left);
}

TEST(SimulatedTracks, OptionsValidationNamesTheKey) {
  SimTrackOptions opt;
  opt.outlier_share = 1.5;
  auto r = simulateTracks(drive(10), {}, kittiCamera(), opt);
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("simtracks.outlier_share"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::simtracks
