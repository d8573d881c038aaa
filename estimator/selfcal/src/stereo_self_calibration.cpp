#include "sunvo/selfcal/stereo_self_calibration.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

namespace sunvo::selfcal {
namespace {
constexpr double kDegToRad = M_PI / 180.0;

bool inRange(double x, double lo, double hi) {
  return x >= lo && x <= hi;
}
}  // namespace

Status StereoSelfCalibrationOptions::validate() const {
  const char* p = "self_calibration.";
  auto bad = [&](const char* key, const char* range) {
    return invalidArgument(std::string(p) + key + " outside " + range);
  };
  if (!inRange(disparity_bias_px, -5.0, 5.0)) return bad("disparity_bias_px", "[-5, 5] px");
  if (!(sigma_px > 0.0 && sigma_px <= 10.0)) return bad("sigma_px", "(0, 10] px");
  if (!(gate_px > 0.0 && gate_px <= 50.0)) return bad("gate_px", "(0, 50] px");
  if (!(prior_sigma_deg > 0.0 && prior_sigma_deg <= 10.0)) {
    return bad("prior_sigma_deg", "(0, 10] deg");
  }
  if (!(prior_sigma_scale > 0.0 && prior_sigma_scale <= 0.1)) {
    return bad("prior_sigma_scale", "(0, 0.1]");
  }
  if (!inRange(random_walk_deg, 0.0, 1.0)) return bad("random_walk_deg", "[0, 1] deg");
  if (!inRange(random_walk_scale, 0.0, 0.01)) return bad("random_walk_scale", "[0, 0.01]");
  if (!inRange(drift_rate_sigma_deg, 0.0, 0.1)) {
    return bad("drift_rate_sigma_deg", "[0, 0.1] deg per frame");
  }
  if (!inRange(drift_rate_time_frames, 1.0, 1e7)) {
    return bad("drift_rate_time_frames", "[1, 1e7] frames");
  }
  if (!(max_angle_deg > 0.0 && max_angle_deg <= 10.0)) return bad("max_angle_deg", "(0, 10] deg");
  if (!(max_scale > 0.0 && max_scale <= 0.1)) return bad("max_scale", "(0, 0.1]");
  if (min_observations < 3 || min_observations > 100000) {
    return bad("min_observations", "[3, 100000]");
  }
  return Status::ok();
}

Status StereoSelfCalibration::init(const StereoSelfCalibrationOptions& options,
                                   const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  options_ = options;
  camera_ = camera;
  const double sa = options.prior_sigma_deg * kDegToRad;
  const double ss = options.prior_sigma_scale;
  const double sr = options.drift_rate_sigma_deg * kDegToRad;  // 0: no rate state
  P0_ = (Vec5() << sa * sa, sa * sa, ss * ss, sr * sr, sr * sr).finished().asDiagonal();
  const double a = sr > 0.0 ? std::exp(-1.0 / options.drift_rate_time_frames) : 0.0;
  F_.setIdentity();
  F_(0, 3) = F_(1, 4) = sr > 0.0 ? 1.0 : 0.0;
  F_(3, 3) = F_(4, 4) = a;
  const double qa = options.random_walk_deg * kDegToRad;
  const double qs = options.random_walk_scale;
  const double qr = sr * sr * (1.0 - a * a);
  Q_ = (Vec5() << qa * qa, qa * qa, qs * qs, qr, qr).finished().asDiagonal();
  max_rate_ = 10.0 * sr;
  resets_ = 0;
  resetState();
  return Status::ok();
}

void StereoSelfCalibration::resetState() {
  x_.setZero();
  P_ = P0_;
}

SelfCalibrationReport StereoSelfCalibration::process(const FrameFeatures& in, FrameFeatures* out) {
  SelfCalibrationReport r;
  out->time_ns = in.time_ns;
  out->sequence = in.sequence;
  out->observations.assign(in.observations.begin(), in.observations.end());
  // The entered disparity bias: d = uL - uR - a, so uR + a (the estimation below reads only rows).
  const double bias = options_.disparity_bias_px;
  if (bias != 0.0) {
    for (StereoObservation& o : out->observations) o.u_right += bias;
  }
  if (!options_.enabled) return r;

  // Predict: the angles follow their drift rate; random walks and the rates' forgetting.
  x_ = F_ * x_;
  P_ = F_ * P_ * F_.transpose() + Q_;
  // The frame's information about (delta, theta, s); the rates are not in H.
  const double cu = camera_.cu, cv = camera_.cv, fv = camera_.fv;
  const double w = 1.0 / (options_.sigma_px * options_.sigma_px);
  const Eigen::Vector3d x3 = x_.head<3>();
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const StereoObservation& o : in.observations) {
    if (!o.v_right_measured) continue;
    const Eigen::Vector3d H(-fv, -(o.u_right - cu), -(o.v_right - cv));
    const double y = o.v_left - o.v_right;
    if (!std::isfinite(y) || !H.allFinite() || std::abs(y - H.dot(x3)) > options_.gate_px) {
      ++r.gated;
      continue;
    }
    info += w * H * H.transpose();
    b += w * H * y;
    ++r.used;
  }
  if (r.used >= options_.min_observations) {
    // P+ = P (I + Y P)^-1, x+ = x + P+ (b - Y x), Y and b zero outside the first three rows.
    Mat5 Y = Mat5::Zero();
    Y.topLeftCorner<3, 3>() = info;
    Vec5 innovation = Vec5::Zero();
    innovation.head<3>() = b - info * x3;
    const Mat5 P_new = P_ * (Mat5::Identity() + Y * P_).inverse();
    x_ += P_new * innovation;
    P_ = 0.5 * (P_new + P_new.transpose());
    r.updated = true;
  }
  const double max_angle = options_.max_angle_deg * kDegToRad;
  if (!x_.allFinite() || !P_.allFinite() || std::abs(x_[0]) > max_angle ||
      std::abs(x_[1]) > max_angle || std::abs(x_[2]) > options_.max_scale ||
      std::abs(x_[3]) > max_rate_ || std::abs(x_[4]) > max_rate_) {
    resetState();
    ++resets_;
    r.reset = true;
    r.resets = resets_;
    return r;  // this frame goes on as measured (less the entered bias)
  }
  // Correct the right observations (the inverse of the model above; the bias is already out).
  const double delta = x_[0], theta = x_[1], s = x_[2];
  for (StereoObservation& o : out->observations) {
    const double u = o.u_right - bias, v = o.v_right;  // uR as measured: the model's column
    o.u_right += theta * (v - cv);
    o.v_right = v - fv * delta - theta * (u - cu) - s * (v - cv);
  }
  r.pitch_mrad = delta * 1e3;
  r.roll_mrad = theta * 1e3;
  r.scale = s;
  r.roll_sigma_mrad = std::sqrt(P_(1, 1)) * 1e3;
  r.pitch_rate_urad = x_[3] * 1e6;
  r.roll_rate_urad = x_[4] * 1e6;
  r.resets = resets_;
  return r;
}

std::string reportCsvRow(std::size_t frame, const SelfCalibrationReport& r) {
  char row[200];
  std::snprintf(row, sizeof(row), "%zu,%.5f,%.5f,%.7f,%.5f,%d,%d,%.4f,%.4f\n", frame, r.pitch_mrad,
                r.roll_mrad, r.scale, r.roll_sigma_mrad, r.used, r.reset ? 1 : 0, r.pitch_rate_urad,
                r.roll_rate_urad);
  return row;
}

}  // namespace sunvo::selfcal
