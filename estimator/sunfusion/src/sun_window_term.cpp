#include "sunvo/sunfusion/sun_window_term.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "sunvo/core/geometry.hpp"
#include "sunvo/sunfusion/sun_residual.hpp"

namespace sunvo::sunfusion {
namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

Status SunFusionOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(gate.validate());
  if (!world_up.allFinite() || std::abs(world_up.norm() - 1.0) > 1e-6) {
    return invalidArgument("sun_fusion.world_up must be a unit vector");
  }
  if (!(loss_scale >= 0.0 && loss_scale <= 100.0)) {
    return invalidArgument("sun_fusion.loss_scale out of range [0, 100]");
  }
  if (!(initial_attitude_sigma_deg > 0.0 && initial_attitude_sigma_deg <= 45.0)) {
    return invalidArgument("sun_fusion.initial_attitude_sigma_deg out of range (0, 45]");
  }
  if (!(attitude_drift_deg_per_frame >= 0.0 && attitude_drift_deg_per_frame <= 5.0)) {
    return invalidArgument("sun_fusion.attitude_drift_deg_per_frame out of range [0, 5]");
  }
  return Status::ok();
}

Status SunWindowTerm::init(const SunFusionOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  options_ = options;
  loss_.reset(options.loss_scale > 0.0 ? new ceres::CauchyLoss(options.loss_scale) : nullptr);
  for (auto& p : pending_) p = Pending{};
  used_.fill(false);
  counters_ = GateCounters{};
  last_decision_.reset();
  delta_ = {0.0, 0.0, 0.0};
  const double s0 = options.initial_attitude_sigma_deg * kDeg;
  P_ = Eigen::Matrix3d::Identity() * s0 * s0;
  last_sequence_.reset();
  num_used_ = 0;
  return Status::ok();
}

void SunWindowTerm::attach(backend::BundleWindow& window) {
  window.setPoseResidualHook([this](backend::BundleWindow& w) { return onSolve(w); });
  window.setPostSolveHook([this](backend::BundleWindow& w) { onSolved(w); });
}

void SunWindowTerm::addObservation(const SunObservation& observation) {
  const std::size_t slot = observation.measurement.sequence % pending_.size();
  pending_[slot] = Pending{};
  pending_[slot].obs = observation;
  used_[slot] = true;
}

Status SunWindowTerm::onSolve(backend::BundleWindow& window) {
  const bool estimate = options_.estimate_base_attitude;
  // Grow the attitude uncertainty to the newest frame: a random walk per frame.
  const std::uint64_t newest = window.sequence(window.size() - 1);
  if (last_sequence_ && newest > *last_sequence_) {
    const double q = options_.attitude_drift_deg_per_frame * kDeg;
    P_ += Eigen::Matrix3d::Identity() * q * q * static_cast<double>(newest - *last_sequence_);
  }
  last_sequence_ = newest;
  delta_ = {0.0, 0.0, 0.0};
  num_used_ = 0;

  const Eigen::Matrix3d C_b_w = window.T_w_b().linear().transpose();
  for (int s = 1; s < window.size(); ++s) {
    const std::size_t ring = window.sequence(s) % pending_.size();
    if (!used_[ring] || pending_[ring].obs.measurement.sequence != window.sequence(s)) continue;
    Pending& p = pending_[ring];
    const Eigen::Vector3d sun_b = C_b_w * p.obs.sun_w;
    if (!p.decided) {
      const Eigen::Vector3d predicted_c = window.T_k_b(s).linear() * sun_b;
      const double up = p.obs.sun_w.dot(options_.world_up);
      const GateResult r = gateSunMeasurement(options_.gate, predicted_c, up, p.obs.measurement);
      counters_.count(r);
      last_decision_ = r;
      p.decided = true;
      p.accepted = r == GateResult::kAccepted;
    }
    if (!p.accepted || p.consumed) continue;
    // The base may have moved since the last solve (the window slid), so s_b is rebuilt each time.
    const SunMeasurement& m = p.obs.measurement;
    const bool azimuth = m.kind == SunMeasurementKind::kAzimuthOnly;
    if (estimate) {
      p.cost.reset(
          azimuth
              ? SunAzimuthResidual::CreateWithBaseCorrection(sun_b, xzDirection(m.sun_c), m.sigma)
              : SunDirectionResidual::CreateWithBaseCorrection(sun_b, m.sun_c, m.sigma));
      double* extra[] = {delta_.data()};
      SUNVO_RETURN_IF_ERROR(window.addResidual(s, p.cost.get(), loss_.get(), extra));
      p.consumed = true;
      used_in_solve_[static_cast<std::size_t>(num_used_++)] = static_cast<int>(ring);
    } else {
      p.cost.reset(azimuth ? SunAzimuthResidual::Create(sun_b, xzDirection(m.sun_c), m.sigma)
                           : SunDirectionResidual::Create(sun_b, m.sun_c, m.sigma));
      SUNVO_RETURN_IF_ERROR(window.addPoseResidual(s, p.cost.get(), loss_.get()));
    }
  }
  if (estimate && num_used_ > 0) {
    // Square-root information of the prior: L^T L = P^-1.
    const Eigen::Matrix3d info = P_.inverse();
    const Eigen::Matrix3d L = Eigen::LLT<Eigen::Matrix3d>(info).matrixU();
    prior_cost_.reset(AttitudePriorResidual::Create(L));
    double* extra[] = {delta_.data()};
    SUNVO_RETURN_IF_ERROR(window.addResidual(-1, prior_cost_.get(), nullptr, extra));
  }
  return Status::ok();
}

void SunWindowTerm::onSolved(backend::BundleWindow& window) {
  if (!options_.estimate_base_attitude || num_used_ == 0) return;
  // Information of the sun residuals about delta at the solution.
  Eigen::Matrix3d info = P_.inverse();
  for (int i = 0; i < num_used_; ++i) {
    const Pending& p =
        pending_[static_cast<std::size_t>(used_in_solve_[static_cast<std::size_t>(i)])];
    int slot = -1;
    for (int s = 1; s < window.size(); ++s) {
      if (window.sequence(s) == p.obs.measurement.sequence) slot = s;
    }
    if (slot < 0 || !p.cost) continue;
    const Eigen::Quaterniond q(window.T_k_b(slot).linear());
    const int m = p.cost->num_residuals();
    Eigen::Matrix<double, 3, 1> r;
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_q;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J_d;
    const double* params[] = {q.coeffs().data(), delta_.data()};
    double* jacobians[] = {J_q.data(), J_d.data()};
    if (!p.cost->Evaluate(params, r.data(), jacobians)) continue;
    const Eigen::MatrixXd J = J_d.topRows(m);
    info += J.transpose() * J;
  }
  const Eigen::Vector3d delta(delta_[0], delta_[1], delta_[2]);
  if (delta.allFinite()) window.correctBaseAttitude(expSO3(delta));
  const Eigen::Matrix3d P_new = info.inverse();
  if (P_new.allFinite()) P_ = 0.5 * (P_new + P_new.transpose());
  delta_ = {0.0, 0.0, 0.0};
  num_used_ = 0;
}

}  // namespace sunvo::sunfusion
