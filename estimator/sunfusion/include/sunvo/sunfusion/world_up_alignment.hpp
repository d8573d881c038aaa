#pragma once
// The world's "up" from the first measurements of the vertical channel, for a world frame whose
// tilt against gravity is not known.
//
// A KITTI odometry sequence, a track folder or any drive whose poses are given relative to the
// first camera has no gravity in it: its world is the first camera, which a road's camber, a
// slope or the mount tilt by a degree or so (the cue reads about -1.4 deg roll and +1.2 deg
// pitch on the 11 real KITTI 00 frames; the rendered ramp drives start 1.27 deg off level). Taking
// the world's up as that camera's -y makes the vertical cue a constant error in the world; the
// fusion would turn the whole trajectory by it.
//
// At the start VO's attitude is as good as it will ever be (the first pose is the world by
// definition), so the cue's first answers, carried into the world by VO's attitude, measure the
// world's up: u_w,i = C_w_ck,i up_ck,i. Their robust mean is the up the fusion then uses. The
// mean: weights 1/sigma_i^2, reweighted five times by Cauchy's 1 / (1 + (theta_i / 2 sigma_i)^2)
// (theta_i: the angle of u_w,i from the mean), so that one wrong answer among a handful moves it
// by a fraction of a sigma. What VO's attitude drifts during those frames goes into the
// estimate (measured, docs/vertical.md: 0.04-0.11 deg off on two rendered drives; 1.1-2.0 deg on
// the real 0020 tracks, whose VO is 0.9 deg off in tilt by frame 10 and 1.6 deg by frame 50).
//
// The same answers serve a world whose up is known (ENU) but whose start attitude is not level
// as configured (a rover parked on a slope): there their mean measures VO's tilt error at the
// start, tiltCorrection() is the rotation that removes it, and the fusion turns VO's world by it
// (SunFusionOptions::world_up_alignment_use kStartTilt). There the answers are also fused while
// they are collected, and each correction the fusion makes turns the estimate they were carried
// by: turn() carries them along, so that at the end their mean measures the tilt error that is
// left, not the one at the start.
//
// No allocation: at most kMaxMeasurements answers are kept.

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace sunvo::sunfusion {

class WorldUpAlignment {
 public:
  static constexpr int kMaxMeasurements = 64;
  static constexpr int kMinMeasurements = 3;

  // frames: the answers of frames 1..frames are collected (at least kMinMeasurements of them,
  // however late); 0 = off (the assumed up is the world's). assumed_up: unit vector.
  void reset(std::uint64_t frames, const Eigen::Vector3d& assumed_up);

  // Whether the answer of frame `sequence` goes into the alignment. Finishes the alignment when
  // it does not (the first answer past the frames, with enough collected).
  bool takes(std::uint64_t sequence);
  // An answer: up_w = C_w_ck up_ck (unit), sigma its 1-sigma angle (rad, > 0). Call after
  // takes() said yes. Finishes when the store is full.
  void add(const Eigen::Vector3d& up_w, double sigma);
  // The attitude estimate the answers were carried by was turned, C_w_c <- C C_w_c (a fusion
  // correction): u_w,i <- C u_w,i for every answer, and the estimate once done.
  void turn(const Eigen::Matrix3d& C);

  bool done() const { return done_; }
  // The world's up: the assumed one until done, then the estimate.
  const Eigen::Vector3d& up() const { return up_; }
  int used() const { return count_; }
  // Angle between the estimate and the assumed up, deg (0 before it is done).
  double tiltDeg() const;
  // The rotation vector e (rad, world frame) with Exp(e) up() = the assumed up: for a world whose
  // up is known, VO's tilt error while the answers were taken. Zero before it is done.
  Eigen::Vector3d tiltCorrection() const;
  // 1-sigma angle of the estimate, rad: 1 / sqrt(sum of the final weights) (0 before it is done).
  double sigma() const { return mean_sigma_; }
  // Finishes now when the frames are past and enough answers were taken (takes() does it on the
  // first answer past the frames).
  void finishIfPast(std::uint64_t sequence);

 private:
  void finish();

  bool done_ = true;
  std::uint64_t frames_ = 0;
  Eigen::Vector3d assumed_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  std::array<Eigen::Vector3d, kMaxMeasurements> u_{};
  std::array<double, kMaxMeasurements> sigma_{};
  int count_ = 0;
  double mean_sigma_ = 0.0;
};

}  // namespace sunvo::sunfusion
