// The window's rotation-rate prior (WindowOptions::rotation_rate_prior): its residuals between
// consecutive slots and the yaw-axis estimate they are built around. Part of BundleWindow, kept
// apart from bundle_window.cpp by topic.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "sunvo/backend/bundle_window.hpp"

namespace sunvo::backend {
namespace {
// The rotation-rate prior's basis for the yaw axis a (unit, camera frame): the pitch-like
// direction e1 = a x e2, a, and the roll-like direction e2 (the optical axis made orthogonal to a).
Eigen::Matrix3d rateBasis(const Eigen::Vector3d& a) {
  const Eigen::Vector3d e2 = (Eigen::Vector3d::UnitZ() - a.z() * a).normalized();
  Eigen::Matrix3d B;
  B.row(0) = a.cross(e2).transpose();
  B.row(1) = a.transpose();
  B.row(2) = e2.transpose();
  return B;
}
}  // namespace

// Rotation-rate priors between consecutive slots (RotationRatePriorResidual): basis rows
// rateBasis(yaw axis); std = rate std x dt per row, the rate std raised to the spread of the
// vehicle's own recent rates on that axis (RateSpread). While that spread is not known yet (the
// first frames after init()) there is no prior: a 2 deg/s prior on a vehicle rolling at 15 deg/s
// would tilt the start of the drive, and a drift prior has nothing to do in the first second.
Status BundleWindow::addRatePriors(WindowSolveSummary& out, bool use_ceres) {
  constexpr double kDegToRad = M_PI / 180.0;
  if (rate_spread_.capacity() > 0 && !rate_spread_.ready()) return Status::ok();
  const Eigen::Vector3d spread = rate_spread_.spread();
  double rates[3] = {options_.rate_prior_pitch_deg_s * kDegToRad,
                     options_.rate_prior_yaw_deg_s * kDegToRad,
                     options_.rate_prior_roll_deg_s * kDegToRad};
  for (int i = 0; i < 3; ++i) {
    if (rates[i] > 0.0) rates[i] = std::max(rates[i], spread[i]);
    out.rate_prior_std_deg_s[static_cast<std::size_t>(i)] = rates[i] / kDegToRad;
  }
  if (!(rates[0] > 0.0 || rates[1] > 0.0 || rates[2] > 0.0)) return Status::ok();
  const Eigen::Matrix3d B = rateBasis(yaw_axis_c_);
  for (int s = 1; s < size_; ++s) {
    const auto us = static_cast<std::size_t>(s);
    double dt_s = static_cast<double>(frames_[us].time_ns - frames_[us - 1].time_ns) * 1e-9;
    if (!(dt_s > 0.0) || !std::isfinite(dt_s)) continue;
    // A glitching time stamp (frames < 1 ms apart) must not make the prior rigid.
    dt_s = std::max(dt_s, 1e-3);
    RotationRatePriorData& d = frames_[us].rate_prior;
    for (int i = 0; i < 3; ++i) {
      d.sqrt_info[i] = rates[i] > 0.0 ? 1.0 / (rates[i] * dt_s) : 0.0;
      for (int j = 0; j < 3; ++j) d.basis[3 * i + j] = B(i, j);
    }
    ++out.num_rate_prior_residuals;
    if (!use_ceres) {
      using Kind = SchurLmSolver::BlockRef::Kind;
      const SchurLmSolver::BlockRef refs[] = {{Kind::kRotation, s - 1, nullptr},
                                              {Kind::kRotation, s, nullptr}};
      SUNVO_RETURN_IF_ERROR(schur_.addGeneric(rate_prior_pool_[us].get(), nullptr, refs));
      ++num_residuals_;
      continue;
    }
    residual_ids_[static_cast<std::size_t>(num_residuals_++)] = problem_->AddResidualBlock(
        rate_prior_pool_[us].get(), nullptr, poses_[us - 1].q.data(), poses_[us].q.data());
  }
  return Status::ok();
}

// Yaw axis = principal eigenvector of M = sum_k lambda^(t_now - t_k) phi_k phi_k^T + w0^2 y y^T,
// phi_k the newest frame's rotation vector relative to the previous window frame (turns
// dominate M: a 3 deg/frame turn weighs 900 times a 0.1 deg/frame wobble), lambda = exp(-dt / tau).
// The regulariser w0^2 y y^T is kept at a constant weight, so that without turns the axis
// returns to the camera's y axis.
void BundleWindow::updateYawAxis(double dt_s, const Eigen::Vector3d& phi) {
  if (!phi.allFinite()) return;
  // The rate about the prior's axes as they were in this solve (before the axis moves).
  rate_spread_.push(rateBasis(yaw_axis_c_) * phi / std::max(dt_s, 1e-3));
  const double lambda = std::exp(-dt_s / options_.yaw_axis_memory_s);
  const double w0 = options_.yaw_axis_prior_deg * M_PI / 180.0;
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  yaw_scatter_ =
      lambda * yaw_scatter_ + phi * phi.transpose() + (1.0 - lambda) * w0 * w0 * y * y.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(yaw_scatter_);
  if (eig.info() != Eigen::Success) return;
  Eigen::Vector3d a = eig.eigenvectors().col(2);  // largest eigenvalue last
  if (!a.allFinite() || a.norm() < 0.5) return;
  a.normalize();
  if (a.y() < 0.0) a = -a;
  // An axis more than 45 deg from the camera's y axis is not the turn axis of a camera looking
  // along the direction of travel (e.g. the scatter of a long straight drive without turns):
  // keep the previous one (this also keeps the roll-like direction well defined).
  if (a.y() > std::sqrt(0.5)) yaw_axis_c_ = a;
}

}  // namespace sunvo::backend
