#pragma once
// Online stereo self-calibration (issue 15): a slowly varying rotation of the right camera
// against the rectified rig, estimated from every stereo pair's vertical offsets and taken out of
// the right observations before the odometry sees them.
//
// Model. Rectification makes a point's rows equal: vL = vR. A right camera pitched by delta
// (about its x axis), rolled by theta (about its optical axis z) and with a vertical scale error s
// sees, to first order in the small angles,
//   vR_obs = vR + fv delta + theta (uR - cu) + s (vR - cv),   uR_obs = uR - theta (vR - cv).
// Measurement per observation (the residual whose Jacobian gives H):
//   y = vL - vR_obs = H x + noise,  x = (delta, theta, s),  H = -(fv, uR - cu, vR - cv).
// The tracker's own vertical error is the noise (sigma_px). The state is a random walk: per frame
// P += diag(q^2) (random_walk_*), then the frame's observations update it in information form,
// with a gate on |y - H x| (gate_px). A prior (prior_sigma_*) keeps it near zero until the data
// speak. The estimate corrects the right observations: vR by the whole model, and uR by the roll
// (uR = uR_obs + theta (vR - cv)), which is how the roll reaches an estimator that uses the
// disparity (the paper's (u, v, d) residual never uses vR). The scale is estimated so that it does
// not leak into the roll, and is not applied to uR.
//
// Divergence: a non-finite state, |delta| or |theta| beyond max_angle_deg or |s| beyond max_scale
// resets the state to the prior and is counted; the odometry goes on with the observations as
// measured for that frame.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::selfcal {

struct StereoSelfCalibrationOptions {
  bool enabled = false;             // the switch; off: observations pass unchanged
  double sigma_px = 0.5;            // px, (0, 10]: vertical noise of one observation
  double gate_px = 1.5;             // px, (0, 50]: larger |y - H x| is not used
  double prior_sigma_deg = 0.1;     // deg, (0, 10]: prior of pitch and roll
  double prior_sigma_scale = 1e-3;  // 1, (0, 0.1]: prior of the vertical scale
  double random_walk_deg = 1e-4;    // deg per frame, [0, 1]: pitch and roll random walk
  double random_walk_scale = 1e-6;  // 1 per frame, [0, 0.01]: scale random walk
  double max_angle_deg = 1.0;       // deg, (0, 10]: larger pitch or roll is a divergence
  double max_scale = 0.01;          // 1, (0, 0.1]: larger |s| is a divergence
  int min_observations = 10;        // count, [3, 100000]: fewer in a frame: no update

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("enabled", s.enabled);
    v("sigma_px", s.sigma_px);
    v("gate_px", s.gate_px);
    v("prior_sigma_deg", s.prior_sigma_deg);
    v("prior_sigma_scale", s.prior_sigma_scale);
    v("random_walk_deg", s.random_walk_deg);
    v("random_walk_scale", s.random_walk_scale);
    v("max_angle_deg", s.max_angle_deg);
    v("max_scale", s.max_scale);
    v("min_observations", s.min_observations);
  }
};

// Per frame.
struct SelfCalibrationReport {
  double pitch_mrad = 0.0;       // delta after this frame's update
  double roll_mrad = 0.0;        // theta
  double scale = 0.0;            // s
  double roll_sigma_mrad = 0.0;  // sqrt(P(1, 1))
  int used = 0;                  // observations in the update
  int gated = 0;                 // observations beyond gate_px
  bool updated = false;          // false: too few observations (prediction only) or disabled
  bool reset = false;            // this frame diverged and was reset
  std::uint64_t resets = 0;      // since init
};

// The per-frame log of the programs that run it (sunvo_track_vo --self-calib-log, sunvo_replay
// --self-calib): the CSV header, and the row of frame `frame`; each line ends in '\n'.
inline constexpr const char* kReportCsvHeader =
    "frame,pitch_mrad,roll_mrad,scale,roll_sigma_mrad,used,reset\n";
std::string reportCsvRow(std::size_t frame, const SelfCalibrationReport& r);

class StereoSelfCalibration {
 public:
  Status init(const StereoSelfCalibrationOptions& options, const StereoCamera& camera);
  bool enabled() const { return options_.enabled; }

  // Estimates from `in`, then writes `in` with corrected right observations to `out` (its vector
  // is reused: no allocation once its capacity suffices). Disabled: out = in.
  SelfCalibrationReport process(const FrameFeatures& in, FrameFeatures* out);

  const Eigen::Vector3d& state() const { return x_; }  // (delta rad, theta rad, s)
  std::uint64_t resets() const { return resets_; }

 private:
  void resetState();

  StereoSelfCalibrationOptions options_;
  StereoCamera camera_;
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d P0_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d Q_ = Eigen::Matrix3d::Zero();
  std::uint64_t resets_ = 0;
};

}  // namespace sunvo::selfcal
