#include "sunvo/sunfusion/sun_window_term.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

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
  if (!(min_drift_deg_per_frame >= 0.0 && min_drift_deg_per_frame <= max_drift_deg_per_frame &&
        max_drift_deg_per_frame <= 5.0)) {
    return invalidArgument(
        "sun_fusion.min_drift_deg_per_frame / max_drift_deg_per_frame: need 0 <= min <= max <= 5");
  }
  if (!(drift_adaptation_rate > 0.0 && drift_adaptation_rate <= 1.0)) {
    return invalidArgument("sun_fusion.drift_adaptation_rate out of range (0, 1]");
  }
  if (!(innovation_gate_chi2 >= 0.0 && innovation_gate_chi2 <= 1e6)) {
    return invalidArgument("sun_fusion.innovation_gate_chi2 out of range [0, 1e6]");
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
  drift_deg_per_frame_ = options.attitude_drift_deg_per_frame;
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
  const std::uint64_t newest = window.sequence(window.size() - 1);
  if (estimate && last_sequence_ && newest > *last_sequence_) {
    propagate(static_cast<double>(newest - *last_sequence_));
  }
  last_sequence_ = newest;
  delta_ = {0.0, 0.0, 0.0};
  num_used_ = 0;

  // Prior of this solve's base correction delta_b = C_b_w dtheta_w: N(0, C_b_w P_theta C_w_b).
  const Eigen::Matrix3d C_b_w = window.T_w_b().linear().transpose();
  const Eigen::Matrix3d P_b = C_b_w * P_ * C_b_w.transpose();
  for (int s = 1; s < window.size(); ++s) {
    const std::size_t ring = window.sequence(s) % pending_.size();
    if (!used_[ring] || pending_[ring].obs.measurement.sequence != window.sequence(s)) continue;
    Pending& p = pending_[ring];
    const Eigen::Vector3d sun_b = C_b_w * p.obs.sun_w;
    if (!p.decided) {
      const Eigen::Vector3d predicted_c = window.T_k_b(s).linear() * sun_b;
      const double up = p.obs.sun_w.dot(options_.world_up);
      GateResult r = gateSunMeasurement(options_.gate, predicted_c, up, p.obs.measurement);
      if (r == GateResult::kAccepted && estimate) {
        int m = 0;
        const double nis = innovationSq(window.T_k_b(s), sun_b, p.obs.measurement, P_b, &m);
        if (options_.innovation_gate_chi2 > 0.0 && nis > options_.innovation_gate_chi2) {
          r = GateResult::kRejectedInnovation;
        } else if (options_.adaptive_drift && m > 0) {
          adaptDrift(nis, m);
        }
      }
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
    // Square-root information of the prior: L^T L = P_b^-1.
    const Eigen::Matrix3d info = P_b.inverse();
    const Eigen::Matrix3d L = Eigen::LLT<Eigen::Matrix3d>(info).matrixU();
    prior_cost_.reset(AttitudePriorResidual::Create(L));
    double* extra[] = {delta_.data()};
    SUNVO_RETURN_IF_ERROR(window.addResidual(-1, prior_cost_.get(), nullptr, extra));
  }
  return Status::ok();
}

void SunWindowTerm::onSolved(backend::BundleWindow& window) {
  if (!options_.estimate_base_attitude || num_used_ == 0) return;
  // Information of the sun residuals about delta_b at the solution.
  Eigen::Matrix3d info_b = Eigen::Matrix3d::Zero();
  for (int i = 0; i < num_used_; ++i) {
    const Pending& p =
        pending_[static_cast<std::size_t>(used_in_solve_[static_cast<std::size_t>(i)])];
    int slot = -1;
    for (int s = 1; s < window.size(); ++s) {
      if (window.sequence(s) == p.obs.measurement.sequence) slot = s;
    }
    if (slot < 0 || !p.cost) continue;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J_d;
    Eigen::Vector3d r;
    int m = 0;
    if (!evaluateAt(*p.cost, window.T_k_b(slot), delta_.data(), &r, &J_d, &m)) continue;
    const Eigen::MatrixXd J = J_d.topRows(m);
    info_b += J.transpose() * J;
  }
  const Eigen::Vector3d delta_b(delta_[0], delta_[1], delta_[2]);
  delta_ = {0.0, 0.0, 0.0};
  num_used_ = 0;
  if (!delta_b.allFinite() || !info_b.allFinite()) return;
  const Eigen::Matrix3d C_w_b = window.T_w_b().linear();
  const Eigen::Matrix3d A = C_w_b * info_b * C_w_b.transpose();  // information about dtheta_w

  // P <- (P^-1 + A)^-1, written as P - P (I + A P)^-1 A P: no inverse of a singular A (an
  // azimuth-only measurement informs one or two axes only).
  const Eigen::Matrix3d M = (Eigen::Matrix3d::Identity() + A * P_).inverse() * A;
  Eigen::Matrix3d P_new = P_ - P_ * M * P_;
  P_new = 0.5 * (P_new + P_new.transpose());
  if (!P_new.allFinite()) return;
  P_ = P_new;
  window.correctBaseAttitude(expSO3(delta_b));
}

void SunWindowTerm::propagate(double frames) {
  const double q = drift_deg_per_frame_ * kDeg;
  P_ += Eigen::Matrix3d::Identity() * q * q * frames;
}

bool SunWindowTerm::evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                               const double* delta_b, Eigen::Vector3d* r,
                               Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d, int* m) {
  const Eigen::Quaterniond q(T_k_b.linear());
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_q;
  const double* params[] = {q.coeffs().data(), delta_b};
  double* jacobians[] = {J_q.data(), J_d->data()};
  *m = cost.num_residuals();
  return cost.Evaluate(params, r->data(), jacobians) && r->head(*m).allFinite() &&
         J_d->topRows(*m).allFinite();
}

void SunWindowTerm::adaptDrift(double nis, int dof) {
  // Robust innovation-based adaptation (a stochastic approximation of the median): with a
  // consistent filter the NIS is chi-square with `dof` degrees of freedom and exceeds its median
  // half of the time. q_theta is raised by a log-step when the NIS is above that median and
  // lowered when below, so it settles where the innovations are consistent; an outlier moves it
  // by one step only, whatever its size.
  const double median = dof <= 1 ? 0.455 : (dof == 2 ? 1.386 : 2.366);
  const double step =
      nis > median ? options_.drift_adaptation_rate : -options_.drift_adaptation_rate;
  drift_deg_per_frame_ *= std::exp(step);
  drift_deg_per_frame_ = std::clamp(drift_deg_per_frame_, options_.min_drift_deg_per_frame,
                                    options_.max_drift_deg_per_frame);
}

double SunWindowTerm::innovationSq(const Isometry3& T_k_b, const Eigen::Vector3d& sun_b,
                                   const SunMeasurement& m, const Eigen::Matrix3d& P_b,
                                   int* dof) const {
  const bool azimuth = m.kind == SunMeasurementKind::kAzimuthOnly;
  const std::unique_ptr<ceres::CostFunction> cost(
      azimuth ? SunAzimuthResidual::CreateWithBaseCorrection(sun_b, xzDirection(m.sun_c), m.sigma)
              : SunDirectionResidual::CreateWithBaseCorrection(sun_b, m.sun_c, m.sigma));
  const double zero[3] = {0.0, 0.0, 0.0};
  Eigen::Vector3d r;
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J_d;
  int n = 0;
  *dof = 0;
  if (!evaluateAt(*cost, T_k_b, zero, &r, &J_d, &n)) return std::numeric_limits<double>::infinity();
  *dof = n;
  const Eigen::MatrixXd J = J_d.topRows(n);
  const Eigen::MatrixXd S = J * P_b * J.transpose() + Eigen::MatrixXd::Identity(n, n);
  const Eigen::VectorXd rn = r.head(n);
  return rn.dot(S.ldlt().solve(rn));
}

}  // namespace sunvo::sunfusion
