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
// The tracker's own vertical error is the noise (sigma_px). The prior (prior_sigma_*) keeps the
// state near zero until the data speak; a gate on |y - H x| (gate_px) drops outliers. The estimate
// corrects the right observations: vR by the whole model, and uR by the roll
// (uR = uR_obs + theta (vR - cv)), which is how the roll reaches an estimator that uses the
// disparity (the paper's (u, v, d) residual never uses vR). The scale is estimated so that it does
// not leak into the roll, and is not applied to uR.
//
// Not estimated: a turn psi about the camera's y axis. It shifts every disparity by about fu psi
// (0.13 px for 0.01 deg) but the rows only by -psi (uR - cu) (vR - cv) / fu (0.026 px in the image
// corners). The ways tried on rendered drives (docs/selfcal.md, 2026-11-26) failed on rigs turned
// by 0: from that term psi came out 0.008-0.011 deg and a calibrated drive drifted 23 times as
// far; from the motion (near and far points must agree on the depth change, over one frame or
// over 8-frame segments) the bias wandered by 0.1-0.4 px and drives drifted up to 50 times as
// far. On the real 0020 tracks the rows' yaw term ran to -0.44 deg: the tracks sit above cv, so
// its column correlates with the roll's (-0.75). On antialiased validation drives (session 15)
// neither held either: the bias from the motion with the motion refitted per 8-frame segment is
// right only to +-0.03 px over 150 frames and made every drive drift more (0.066 -> 0.358 m on a
// calibrated one), and read -1.1 px on 0020; the rows' yaw term took 0.01-0.02 deg from the roll.
// Not estimated: a rig's yaw needs an offline calibration (docs/selfcal.md). Its disparity bias
// a (d_measured = fu b / z + a, constant over a drive) is VO-invisible: the odometry's own poses
// absorb it (docs/disparity_bias.md: 0020's tracks carry -0.37 px, read as 0 with VO's poses).
// Measured offline (scripts/disparity_bias.py with poses of a known length), it is entered as
// disparity_bias_px and taken out of every uR (uR + a), with or without the estimation.
//
// Drift model. A rig warms and cools over minutes, so its error changes as a ramp more than as a
// random walk: a random walk small enough to stay quiet on a steady rig trails a ramp by
// rate / gain (0.04 deg behind a 3.3e-4 deg/frame ramp, docs/selfcal.md). So pitch and roll carry
// a drift rate (rad/frame), a first-order Gauss-Markov process with stationary std
// drift_rate_sigma_deg and correlation time drift_rate_time_frames (0 sigma: no rate state):
//   x = (delta, theta, s, delta_dot, theta_dot),
//   predict:  delta += delta_dot, theta += theta_dot, rate *= a,  a = exp(-1 / tau),
//             P = F P F^T + Q,  Q = diag(q_a^2, q_a^2, q_s^2, sr^2 (1 - a^2), sr^2 (1 - a^2)),
// with q_a, q_s the random walks (random_walk_*) and sr the rate's stationary std. The rates do
// not enter H; they are observed through the angles over frames. Update with the frame's
// information Y = sum H^T H / sigma^2 and b = sum H^T y / sigma^2 in a form that needs no P^-1
// (the rate block of P is zero without the rate state):
//   P+ = P (I + Y P)^-1,  x+ = x + P+ (b - Y x).
//
// Divergence: a non-finite state, |delta| or |theta| beyond max_angle_deg, |s| beyond max_scale
// or a rate beyond 10 of its stds resets the state to the prior and is counted; the odometry goes
// on with the observations as measured for that frame.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::selfcal {

struct StereoSelfCalibrationOptions {
  bool enabled = false;  // the switch; off: observations pass unchanged (but for
                         //   disparity_bias_px)
  // The rig's constant disparity error, measured offline (see the header), taken out of every
  // observation whether or not the estimation is enabled; 0 = none.
  double disparity_bias_px = 0.0;   // px, [-5, 5]
  double sigma_px = 0.5;            // px, (0, 10]: vertical noise of one observation
  double gate_px = 1.5;             // px, (0, 50]: larger |y - H x| is not used
  double prior_sigma_deg = 0.1;     // deg, (0, 10]: prior of pitch and roll
  double prior_sigma_scale = 1e-3;  // 1, (0, 0.1]: prior of the vertical scale
  double random_walk_deg = 1e-4;    // deg per frame, [0, 1]: pitch and roll random walk
  double random_walk_scale = 1e-6;  // 1 per frame, [0, 0.01]: scale random walk
  // Drift rate of pitch and roll (see the header): a warming rig turns by up to ~0.1 deg in a
  // minute (600 frames at 10 Hz), 1.7e-4 deg/frame; the std covers three times that. The rate
  // forgets over tau (100 s at 10 Hz). A rate beyond 10 stds is a divergence.
  double drift_rate_sigma_deg = 5e-4;      // deg per frame, [0, 0.1]: 0 = no rate state
  double drift_rate_time_frames = 1000.0;  // frames, [1, 1e7]: correlation time tau
  double max_angle_deg = 1.0;              // deg, (0, 10]: larger pitch or roll is a divergence
  double max_scale = 0.01;                 // 1, (0, 0.1]: larger |s| is a divergence
  int min_observations = 10;               // count, [3, 100000]: fewer in a frame: no update

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("enabled", s.enabled);
    v("disparity_bias_px", s.disparity_bias_px);
    v("sigma_px", s.sigma_px);
    v("gate_px", s.gate_px);
    v("prior_sigma_deg", s.prior_sigma_deg);
    v("prior_sigma_scale", s.prior_sigma_scale);
    v("random_walk_deg", s.random_walk_deg);
    v("random_walk_scale", s.random_walk_scale);
    v("drift_rate_sigma_deg", s.drift_rate_sigma_deg);
    v("drift_rate_time_frames", s.drift_rate_time_frames);
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
  double pitch_rate_urad = 0.0;  // delta_dot, urad per frame (0 without the rate state)
  double roll_rate_urad = 0.0;   // theta_dot
  int used = 0;                  // observations in the update
  int gated = 0;                 // observations beyond gate_px
  bool updated = false;          // false: too few observations (prediction only) or disabled
  bool reset = false;            // this frame diverged and was reset
  std::uint64_t resets = 0;      // since init
};

// The per-frame log of the programs that run it (sunvo_track_vo --self-calib-log, sunvo_replay
// --self-calib): the CSV header, and the row of frame `frame`; each line ends in '\n'.
inline constexpr const char* kReportCsvHeader =
    "frame,pitch_mrad,roll_mrad,scale,roll_sigma_mrad,used,reset,pitch_rate_urad,roll_rate_urad\n";
std::string reportCsvRow(std::size_t frame, const SelfCalibrationReport& r);

class StereoSelfCalibration {
 public:
  Status init(const StereoSelfCalibrationOptions& options, const StereoCamera& camera);
  bool enabled() const { return options_.enabled; }
  // Whether process() changes anything: the estimation is on or a disparity bias is entered.
  bool active() const { return options_.enabled || options_.disparity_bias_px != 0.0; }

  // Estimates from `in`, then writes `in` with corrected right observations to `out` (its vector
  // is reused: no allocation once its capacity suffices). Disabled: out = in, less the entered
  // disparity bias.
  SelfCalibrationReport process(const FrameFeatures& in, FrameFeatures* out);

  // (delta rad, theta rad, s, delta_dot rad/frame, theta_dot rad/frame)
  const Eigen::Matrix<double, 5, 1>& state() const { return x_; }
  std::uint64_t resets() const { return resets_; }

 private:
  void resetState();

  StereoSelfCalibrationOptions options_;
  StereoCamera camera_;
  using Vec5 = Eigen::Matrix<double, 5, 1>;
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  Vec5 x_ = Vec5::Zero();
  Mat5 P_ = Mat5::Identity();
  Mat5 P0_ = Mat5::Identity();
  Mat5 F_ = Mat5::Identity();  // the prediction (see the header)
  Mat5 Q_ = Mat5::Zero();
  double max_rate_ = 0.0;  // rad/frame: 10 stationary stds
  std::uint64_t resets_ = 0;
};

}  // namespace sunvo::selfcal
