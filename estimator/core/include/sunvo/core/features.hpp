#pragma once
// Stereo feature observations of one frame: what the front end produces and the back end
// consumes; a track file replays the same thing.

#include <cstdint>
#include <vector>

#include "sunvo/core/time.hpp"

namespace sunvo {

struct StereoObservation {
  std::int64_t landmark_id = -1;  // persists across frames while the feature is tracked
  double u_left = 0.0;            // px, rectified left image
  double v_left = 0.0;
  double u_right = 0.0;  // px, rectified right image (v_right ~ v_left after rectification)
  double v_right = 0.0;
  // false: the right row was not measured (v_right = v_left, as rectification promises) and
  // carries no information about the rig (what stereo self-calibration learns from).
  bool v_right_measured = true;
  double disparity() const { return u_left - u_right; }
};

struct FrameFeatures {
  TimeNs time_ns = 0;
  std::uint64_t sequence = 0;
  std::vector<StereoObservation> observations;  // capacity reserved once by the producer
};

}  // namespace sunvo
