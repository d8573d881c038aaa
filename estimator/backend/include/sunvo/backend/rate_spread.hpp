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
// Fixed memory (a ring of kMaxFrames per axis, a scratch copy for the median), no allocation, no
// threads. undoLastPush() takes back the newest sample (the window's restoreInitialGuess()).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>

namespace sunvo::backend {

class RateSpread {
 public:
  static constexpr int kMaxFrames = 256;
  // Fewer samples than this give no spread (the configured std alone holds).
  static constexpr int kMinSamples = 10;

  // frames: samples kept per axis, [0, kMaxFrames]; 0 keeps nothing (spread() is always 0).
  explicit RateSpread(int frames = 0) { setCapacity(frames); }
  void setCapacity(int frames);  // clamps to [0, kMaxFrames] and clears
  void clear();

  // rate: the newest frame's rotation rate along the basis rows, rad/s. A non-finite sample is
  // ignored (returns false).
  bool push(const Eigen::Vector3d& rate_rad_s);
  // Takes back the newest push() made since the last commit(); false when there is none.
  bool undoLastPush();
  // Makes the samples pushed so far final (undoLastPush() no longer takes them back).
  void commit() { can_undo_ = false; }

  // Whether enough samples are kept for spread(): at least min(kMinSamples, capacity), and any.
  bool ready() const { return size_ > 0 && size_ >= std::min(kMinSamples, capacity_); }
  // 1.4826 x median |rate| per axis over the kept samples, rad/s; 0 while not ready().
  Eigen::Vector3d spread() const;
  int size() const { return size_; }
  int capacity() const { return capacity_; }

 private:
  std::array<std::array<double, kMaxFrames>, 3> ring_{};  // |rate| per axis
  std::array<double, 3> overwritten_{};                   // the samples the newest push() replaced
  bool overwrote_ = false;                                // whether it replaced samples (ring full)
  bool can_undo_ = false;
  int capacity_ = 0;
  int head_ = 0;  // next slot to write
  int size_ = 0;
  mutable std::array<double, kMaxFrames> scratch_{};
};

}  // namespace sunvo::backend
