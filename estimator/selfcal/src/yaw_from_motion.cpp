#include "sunvo/selfcal/yaw_from_motion.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

namespace sunvo::selfcal {
namespace {
constexpr double kDegToRad = M_PI / 180.0;

bool byLandmark(const StereoObservation& a, const StereoObservation& b) {
  return a.landmark_id < b.landmark_id;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}
}  // namespace

Status YawFromMotionOptions::validate() const {
  auto bad = [](const char* key, const char* range) {
    return invalidArgument(std::string("self_calibration.yaw.") + key + " outside " + range);
  };
  if (segment_frames < 2 || segment_frames > 100) return bad("segment_frames", "[2, 100]");
  if (!(prior_sigma_deg > 0.0 && prior_sigma_deg <= 10.0)) {
    return bad("prior_sigma_deg", "(0, 10] deg");
  }
  if (!(random_walk_deg >= 0.0 && random_walk_deg <= 1.0)) {
    return bad("random_walk_deg", "[0, 1] deg");
  }
  if (!(huber_px > 0.0 && huber_px <= 10.0)) return bad("huber_px", "(0, 10] px");
  if (!(gate_sigma > 0.0 && gate_sigma <= 100.0)) return bad("gate_sigma", "(0, 100]");
  if (!(max_angle_deg > 0.0 && max_angle_deg <= 10.0)) return bad("max_angle_deg", "(0, 10] deg");
  if (min_landmarks < 8 || min_landmarks > 100000) return bad("min_landmarks", "[8, 100000]");
  if (max_iterations < 1 || max_iterations > 100) return bad("max_iterations", "[1, 100]");
  return Status::ok();
}

Status YawFromMotion::init(const YawFromMotionOptions& options, const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  options_ = options;
  camera_ = camera;
  const double s0 = options.prior_sigma_deg * kDegToRad;
  const double q = options.random_walk_deg * kDegToRad;
  P0_ = s0 * s0;
  q_ = q * q;
  report_ = YawReport{};
  resetState();
  return Status::ok();
}

void YawFromMotion::resetState() {
  psi_ = 0.0;
  P_ = P0_;
  frames_in_segment_ = -1;
  report_.psi_rad = 0.0;
  report_.sigma_rad = std::sqrt(P_);
}

void YawFromMotion::setFrame(const FrameFeatures& frame) {
  if (!options_.enabled) return;
  current_.assign(frame.observations.begin(), frame.observations.end());
}

void YawFromMotion::correct(FrameFeatures* frame) const {
  if (!options_.enabled || psi_ == 0.0) return;
  const double fu = camera_.fu, cu = camera_.cu;
  for (StereoObservation& o : frame->observations) {
    const double x = (o.u_right - cu) / fu;
    o.u_right += fu * psi_ * (1.0 + x * x);
  }
}

void YawFromMotion::addPose(const Eigen::Isometry3d& T_w_c, bool tracked) {
  if (!options_.enabled) return;
  P_ += q_;
  report_.sigma_rad = std::sqrt(P_);
  if (!tracked || frames_in_segment_ < 0) {  // this frame starts a segment
    start_.swap(current_);
    std::sort(start_.begin(), start_.end(), byLandmark);
    T_w_start_ = T_w_c;
    frames_in_segment_ = 0;
    return;
  }
  if (++frames_in_segment_ < options_.segment_frames) return;

  double beta = 0.0, var = 0.0;
  if (fitSegment(T_w_c.inverse() * T_w_start_, &beta, &var)) {
    const double fu = camera_.fu;
    const double y = beta / fu - psi_;  // innovation, rad
    const double R = var / (fu * fu);
    const double S = P_ + R;
    report_.beta_px = beta;
    report_.beta_sigma_px = std::sqrt(var);
    if (y * y > options_.gate_sigma * options_.gate_sigma * S) {
      ++report_.refused;
    } else {
      const double K = P_ / S;
      psi_ += K * y;
      P_ *= 1.0 - K;
      ++report_.segments;
    }
    if (!std::isfinite(psi_) || !std::isfinite(P_) ||
        std::abs(psi_) > options_.max_angle_deg * kDegToRad) {
      ++report_.resets;
      resetState();
    }
  }
  report_.psi_rad = psi_;
  report_.sigma_rad = std::sqrt(P_);
  // The segment's end frame starts the next one.
  start_.swap(current_);
  std::sort(start_.begin(), start_.end(), byLandmark);
  T_w_start_ = T_w_c;
  frames_in_segment_ = 0;
}

bool YawFromMotion::fitSegment(const Eigen::Isometry3d& T_k1_k0, double* beta_out,
                               double* var_out) {
  const double fu = camera_.fu, fv = camera_.fv, cu = camera_.cu, cv = camera_.cv;
  const double fb = fu * camera_.baseline_m;
  const double huber = options_.huber_px;
  using Mat7 = Eigen::Matrix<double, 7, 7>;
  using Vec7 = Eigen::Matrix<double, 7, 1>;
  using Row7 = Eigen::Matrix<double, 1, 7>;
  Eigen::Matrix3d R = T_k1_k0.linear();
  Eigen::Vector3d t = T_k1_k0.translation();
  double beta = fu * psi_;
  Mat7 H = Mat7::Zero();
  double cost = 0.0;
  int landmarks = 0;
  for (int it = 0; it < options_.max_iterations; ++it) {
    H.setZero();
    Vec7 g = Vec7::Zero();
    cost = 0.0;
    landmarks = 0;
    for (const StereoObservation& o1 : current_) {
      StereoObservation key;
      key.landmark_id = o1.landmark_id;
      auto it0 = std::lower_bound(start_.begin(), start_.end(), key, byLandmark);
      if (it0 == start_.end() || it0->landmark_id != o1.landmark_id) continue;
      const StereoObservation& o0 = *it0;
      const double x0 = (o0.u_right - cu) / fu, x1 = (o1.u_right - cu) / fu;
      const double g0 = 1.0 + x0 * x0, g1 = 1.0 + x1 * x1;
      const double e0 = o0.disparity() - beta * g0;
      const double d1 = o1.disparity();
      if (!(e0 > 0.5) || !(d1 > 0.5)) continue;
      const Eigen::Vector3d p0 = camera_.triangulate(o0.u_left, o0.v_left, e0);
      const Eigen::Vector3d q = R * p0;
      const Eigen::Vector3d p1 = q + t;
      if (!(p1.z() > 0.1)) continue;
      const double iz = 1.0 / p1.z();
      const Eigen::Vector3d r(o1.u_left - (fu * p1.x() * iz + cu),
                              o1.v_left - (fv * p1.y() * iz + cv), d1 - (fb * iz + beta * g1));
      Eigen::Matrix3d dpi;  // d project / d p1
      dpi << fu * iz, 0.0, -fu * p1.x() * iz * iz, 0.0, fv * iz, -fv * p1.y() * iz * iz, 0.0, 0.0,
          -fb * iz * iz;
      Eigen::Matrix<double, 3, 7> J;
      J.leftCols<3>() = dpi * skew(q);  // -(dpi)(-[q]x)
      J.middleCols<3>(3) = -dpi;
      J.col(6) = -dpi * (R * ((g0 / e0) * p0));
      J(2, 6) -= g1;
      for (int i = 0; i < 3; ++i) {
        const double a = std::abs(r[i]);
        const double w = a <= huber ? 1.0 : huber / a;
        const Row7 Ji = J.row(i);
        H.noalias() += w * Ji.transpose() * Ji;
        g.noalias() += w * Ji.transpose() * r[i];
        cost += w * r[i] * r[i];
      }
      ++landmarks;
    }
    if (landmarks < options_.min_landmarks) return false;
    const Eigen::LDLT<Mat7> ldlt(H);
    if (ldlt.info() != Eigen::Success) return false;
    // r(x + dx) ~ r + J dx; minimising sum w (r + J dx)^2 gives H dx = -g.
    const Vec7 step = ldlt.solve(-g);
    if (!step.allFinite()) return false;
    const Eigen::Vector3d dw = step.head<3>();
    const double angle = dw.norm();
    if (angle > 1e-12) R = Eigen::AngleAxisd(angle, dw / angle).toRotationMatrix() * R;
    t += step.segment<3>(3);
    beta += step[6];
    if (step.cwiseAbs().maxCoeff() < 1e-9) break;
  }
  const double dof = 3.0 * landmarks - 7.0;
  const double sigma2 = dof > 0.0 ? cost / dof : 0.0;
  const Mat7 Hinv = H.inverse();
  const double var = Hinv(6, 6) * sigma2;
  if (!std::isfinite(beta) || !std::isfinite(var) || !(var > 0.0)) return false;
  report_.landmarks = landmarks;
  *beta_out = beta;
  *var_out = var;
  return true;
}

}  // namespace sunvo::selfcal
