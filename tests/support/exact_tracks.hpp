#pragma once
// Noise-free, outlier-free simulated stereo tracks along a given trajectory (simtracks), for the
// tests that check what an error field does to exact measurements.

#include <gtest/gtest.h>

#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/simtracks/simulated_tracks.hpp"

namespace sunvo::testing {

// T_0_k: camera k in the frame of camera 0. A failure is a test failure and gives no frames.
inline std::vector<FrameFeatures> exactTracks(const std::vector<Isometry3>& T_0_k,
                                              const StereoCamera& camera) {
  simtracks::SimTrackOptions sim;
  sim.pixel_noise_px = 0.0;
  sim.outlier_share = 0.0;
  auto frames = simtracks::simulateTracks(T_0_k, {}, camera, sim);
  EXPECT_TRUE(frames) << frames.status().toString();
  return frames ? *frames : std::vector<FrameFeatures>();
}

}  // namespace sunvo::testing
