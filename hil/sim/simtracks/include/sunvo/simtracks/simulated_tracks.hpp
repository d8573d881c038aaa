#pragma once
// Simulated stereo feature tracks along a real trajectory.
//
// Landmarks are scattered around the ground-truth path the way an urban street looks to a car's
// stereo rig: facades on both sides (lateral 4-25 m, from the ground up to 8 m above the camera)
// and the road surface. Each frame sees the landmarks in front of it, inside the image and within
// a depth limit, projected through the real rectified calibration with Gaussian pixel noise.
// Tracks end at random like real KLT tracks (geometric lifetime); a landmark seen again after its
// track ended gets a new id, as a re-detection would. A configurable share of observations are
// gross mismatches (uniform in the image, plausible disparity).
//
// The output is the same FrameFeatures a front end or a track file produces, so the back end
// cannot tell the difference. Deterministic for a given seed.

#include <cstdint>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::simtracks {

struct SimTrackOptions {
  std::uint32_t seed = 1;                  // RNG seed; same seed, same tracks
  double landmarks_per_metre = 12.0;       // landmarks created per metre of path, (0, 200]
  double facade_min_lateral_m = 4.0;       // nearest facade point from the path, [1, 50] m
  double facade_max_lateral_m = 25.0;      // farthest facade point, (min, 100] m
  double max_height_above_camera_m = 8.0;  // facade top above the camera, [0, 50] m
  double camera_height_m = 1.65;           // camera above the road, [0.2, 5] m
  double ground_share = 0.3;               // share of landmarks on the road surface, [0, 1]
  double max_depth_m = 40.0;               // farthest observed depth, (1, 200] m
  double min_depth_m = 2.0;                // nearest observed depth, (0, max_depth_m) m
  double pixel_noise_px = 0.5;             // sigma of u, v and u_right noise, [0, 10] px
  double outlier_share = 0.05;             // share of gross mismatches among observations, [0, 0.9]
  double mean_track_length = 12.0;         // mean frames a track survives, [2, 1000]
  int max_features_per_frame = 250;        // cap per frame (strongest = nearest kept), [10, 5000]

  Status validate() const;
};

// T_w_c[k] = pose of camera k in the world (e.g. KITTI ground truth: world = camera 0).
// Returns one FrameFeatures per pose (time_ns from times_ns when given, else k * 0.1 s).
Expected<std::vector<FrameFeatures>> simulateTracks(const std::vector<Isometry3>& T_w_c,
                                                    const std::vector<TimeNs>& times_ns,
                                                    const StereoCamera& camera,
                                                    const SimTrackOptions& options);

}  // namespace sunvo::simtracks
