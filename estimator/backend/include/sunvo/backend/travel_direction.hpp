#pragma once
// The direction of travel as the camera sees it, learnt from the window's own steps, for the
// non-holonomic prior (issue 15; docs/lateral_prior.md, "beta learnt on line").
//
// Why: the prior holds a frame's sideways step to beta t_z + psi (t_z / 2 + L), where beta is the
// camera's turn against the vehicle's direction of travel. Set to 0 it pulls each step of a
// camera turned by 1.5 mrad sideways by 1.5 mm per metre, and the window trades the pull against
// the yaw of weakly tracked frames (measured: 0020's truth -1.5e-3, odometry 00's, another day's
// rig, +1.3e-3). Each solved step gives one sample beta = (t_x - psi (t_z / 2 + L)) / t_z; the
// median of the last N samples is robust to the weak frames whose sideways steps are wrong by
// 0.1 m (they throw a mean off). The samples come from steps the prior has already pulled
// towards the current beta; the median then moves part of the way each time and settles where the
// tracks and the prior agree (on 0020, iterated over whole runs: 0, -0.96, -1.44, ... -1.84e-3).
//
// Fixed memory (SampleRing), no allocation, no threads. undoLastPush() takes back the newest
// sample (the window's restoreInitialGuess()).

#include <algorithm>

#include "sunvo/backend/sample_ring.hpp"

namespace sunvo::backend {

inline constexpr int kTravelDirectionMaxFrames = 1024;

class TravelDirection : private SampleRing<1, kTravelDirectionMaxFrames> {
  using Ring = SampleRing<1, kTravelDirectionMaxFrames>;

 public:
  static constexpr int kMaxFrames = kTravelDirectionMaxFrames;
  // Fewer samples than this leave beta() at 0 (a ring smaller than this is ready when full). On the
  // real 0020 tracks the medians of 16 consecutive steps scatter by 10 (vertical) and 18 mrad
  // (sideways) about the drive's, inside the 35 mrad (2 deg) a row's mount std allows; the rows
  // wait for it (WindowOptions::lateral_beta_frames). Chosen on the validation sets over 8 and 50.
  static constexpr int kMinSamples = 16;

  // frames: samples kept, [0, kMaxFrames] (setCapacity clamps and clears); 0 keeps nothing.
  explicit TravelDirection(int frames = 0) { setCapacity(frames); }
  using Ring::capacity, Ring::clear, Ring::commit, Ring::setCapacity, Ring::size,
      Ring::undoLastPush;

  // beta_rad: one step's direction of travel, x over z in the camera frame. A non-finite sample
  // is ignored (returns false).
  bool push(double beta_rad) { return Ring::push({beta_rad}); }
  // Whether enough samples are kept: kMinSamples, or a full ring.
  bool ready() const { return capacity() > 0 && size() >= std::min(capacity(), kMinSamples); }
  // The median of the kept samples, rad; 0 while not ready().
  double beta() const { return ready() ? median(0) : 0.0; }
};

}  // namespace sunvo::backend
