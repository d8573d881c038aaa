#pragma once
// The spread of the vehicle's own recent rotation rates, per axis of the rotation-rate prior's
// basis (pitch-like, yaw, roll-like), from the window's solved per-frame rotations (issue 15).
//
// Why: the rotation-rate prior's std comes from vehicle dynamics, and a passenger car on a paved
// road (the KITTI drives: pitch and roll rates of 1-2 deg/s RMS) is not a rover on rough ground
// (the rendered rough-road drives: 10-14 deg/s RMS at 1-5 Hz). With a 2 deg/s std on such ground
// the prior shrinks every frame's true roll and pitch and the window moves the rest into the
// translation (docs/backend.md, "The rate prior on rough ground"). So the prior's std on an axis
// is raised to the robust spread of the rates actually seen about it: 1.4826 x median |rate| over
// the last N frames (the std of a zero-mean Gaussian; a few frames where the window's own roll is
// wrong, as on the one-sided frames of the real tracks, do not move a median).
//
// Fixed memory (SampleRing), no allocation, no threads. undoLastPush() takes back the newest
// sample (the window's restoreInitialGuess()).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "sunvo/backend/sample_ring.hpp"

namespace sunvo::backend {

inline constexpr int kRateSpreadMaxFrames = 256;

class RateSpread : private SampleRing<3, kRateSpreadMaxFrames> {
  using Ring = SampleRing<3, kRateSpreadMaxFrames>;

 public:
  static constexpr int kMaxFrames = kRateSpreadMaxFrames;
  // Fewer samples than this give no spread (the configured std alone holds).
  static constexpr int kMinSamples = 10;

  // frames: samples kept per axis, [0, kMaxFrames] (setCapacity clamps and clears); 0 keeps
  // nothing (spread() is always 0).
  explicit RateSpread(int frames = 0) { setCapacity(frames); }
  using Ring::capacity, Ring::clear, Ring::commit, Ring::setCapacity, Ring::size,
      Ring::undoLastPush;

  // rate: the newest frame's rotation rate along the basis rows, rad/s. A non-finite sample is
  // ignored (returns false).
  bool push(const Eigen::Vector3d& rate_rad_s) {
    return Ring::push(
        {std::abs(rate_rad_s.x()), std::abs(rate_rad_s.y()), std::abs(rate_rad_s.z())});
  }
  // Whether enough samples are kept for spread(): at least min(kMinSamples, capacity), and any.
  bool ready() const { return size() > 0 && size() >= std::min(kMinSamples, capacity()); }
  // 1.4826 x median |rate| per axis over the kept samples, rad/s; 0 while not ready().
  Eigen::Vector3d spread() const {
    if (!ready()) return Eigen::Vector3d::Zero();
    return 1.4826 * Eigen::Vector3d(median(0), median(1), median(2));
  }
};

}  // namespace sunvo::backend
