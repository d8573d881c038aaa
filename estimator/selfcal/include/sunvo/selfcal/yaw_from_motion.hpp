#pragma once
// The right camera's yaw from the motion (issue 15): a turn psi of the right camera about its y
// axis shifts every right column, uR_obs = uR - fu psi (1 + x^2) with x = (uR - cu) / fu, so every
// disparity reads fu psi (1 + x^2) too large (0.126 px at the image centre for 0.01 deg). The rows
// barely see it (docs/selfcal.md), but the depths do: near and far points must agree with one
// motion. A point at inverse depth d / (fu b) moves in the image by an amount proportional to
// its true inverse depth, so a disparity bias, which changes the inverse depth of far points
// the most, shows up as flow that does not match the depth.
//
// Measurement (one per segment of `segment_frames` tracked frames, from frame k0 to frame k1):
// every landmark seen in both frames, with (u0, v0, d0) in k0 and (u1, v1, d1) in k1, the
// disparities after the rows' pitch and roll correction and before any yaw correction:
//   p0 = triangulate(u0, v0, d0 - beta g0),     g = 1 + ((uR - cu) / fu)^2,
//   p1 = Exp(w) R p0 + t + dt,                  (R, t) = the odometry's T_k1_k0,
//   r  = (u1, v1, d1) - (project(p1) + (0, 0, beta g1)),
// Huber-weighted Gauss-Newton over (w, dt, beta) from w = dt = 0 and beta = fu psi (the current
// estimate). The motion is refitted together with beta because the odometry's own motion was
// fitted to the biased depths. beta's variance is (H^-1)_bb times the weighted residual variance.
// Jacobians (z = p1_z): d project / d p1 = [[fu/z, 0, -fu x1/z], [0, fv/z, -fv y1/z],
// [0, 0, -fu b/z^2]] with (x1, y1) = p1_xy / z; d p1 / d w = -[R p0]x; d p1 / d dt = I;
// d p0 / d beta = (g0 / (d0 - beta g0)) p0, so d p1 / d beta = R d p0 / d beta; and the d row of
// r has -g1 more in its beta column.
//
// Filter: psi is a random walk (random_walk_deg per frame) with a prior (yaw_prior_sigma_deg); a
// segment's psi_hat = beta / fu enters with its own variance; a segment whose innovation exceeds
// yaw_gate_sigma of its predicted std is refused and counted. A non-finite state or |psi| beyond
// max_angle_deg resets it to the prior (counted). The segment restarts whenever a frame was not
// tracked from its predecessor.
//
// Measured on the validation drives before it was built (docs/selfcal.md, 2026-11-26, session 15):
// 8-frame segments give beta within the fit's own std of the truth on an antialiased drive with
// and without a yaw; one- and two-frame pairs are biased by up to 0.85 px by the nearest points.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::selfcal {

// Config keys self_calibration.yaw.<field>.
struct YawFromMotionOptions {
  bool enabled = false;           // off: psi stays 0 and nothing is corrected
  int segment_frames = 8;         // frames, [2, 100]: the baseline of one measurement
  double prior_sigma_deg = 0.05;  // deg, (0, 10]: prior of psi (0.63 px of disparity at fu 721)
  double random_walk_deg = 1e-4;  // deg per frame, [0, 1]
  double huber_px = 0.5;          // px, (0, 10]: Huber threshold of one residual
  double gate_sigma = 4.0;        // (0, 100]: a segment farther than this many stds is refused
  double max_angle_deg = 1.0;     // deg, (0, 10]: larger |psi| is a divergence
  int min_landmarks = 15;         // count, [8, 100000]: fewer in a segment: no measurement
  int max_iterations = 10;        // [1, 100]: Gauss-Newton iterations per segment

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("enabled", s.enabled);
    v("segment_frames", s.segment_frames);
    v("prior_sigma_deg", s.prior_sigma_deg);
    v("random_walk_deg", s.random_walk_deg);
    v("huber_px", s.huber_px);
    v("gate_sigma", s.gate_sigma);
    v("max_angle_deg", s.max_angle_deg);
    v("min_landmarks", s.min_landmarks);
    v("max_iterations", s.max_iterations);
  }
};

struct YawReport {
  double psi_rad = 0.0;    // after the last segment
  double sigma_rad = 0.0;  // sqrt(P)
  double beta_px = 0.0;    // the last segment's measurement, fu psi_hat (0 before one)
  double beta_sigma_px = 0.0;
  int landmarks = 0;           // in the last segment
  std::uint64_t segments = 0;  // measurements used since init
  std::uint64_t refused = 0;   // beyond the gate
  std::uint64_t resets = 0;    // divergences
};

class YawFromMotion {
 public:
  Status init(const YawFromMotionOptions& options, const StereoCamera& camera);

  // This frame's observations after the pitch/roll correction, before the yaw correction.
  void setFrame(const FrameFeatures& frame);
  // The odometry's pose of the frame last given to setFrame and whether it was tracked from its
  // predecessor; completes a segment every segment_frames tracked frames.
  void addPose(const Eigen::Isometry3d& T_w_c, bool tracked);
  // uR += fu psi (1 + x^2): the inverse of the model above.
  void correct(FrameFeatures* frame) const;

  double psi() const { return psi_; }
  const YawReport& report() const { return report_; }

 private:
  // Fits (w, dt, beta) over start_ -> current_; false when too few landmarks or singular.
  bool fitSegment(const Eigen::Isometry3d& T_k1_k0, double* beta, double* var);
  void resetState();

  YawFromMotionOptions options_;
  StereoCamera camera_;
  std::vector<StereoObservation> start_;                         // frame k0, sorted by landmark id
  std::vector<StereoObservation> current_;                       // the newest frame
  Eigen::Isometry3d T_w_start_ = Eigen::Isometry3d::Identity();  // frame k0's pose
  int frames_in_segment_ = -1;                                   // -1: no start frame yet
  double psi_ = 0.0;
  double P_ = 0.0;
  double P0_ = 0.0;
  double q_ = 0.0;  // rad^2 per frame
  YawReport report_;
};

}  // namespace sunvo::selfcal
