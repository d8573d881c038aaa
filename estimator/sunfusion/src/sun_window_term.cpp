#include "sunvo/sunfusion/sun_window_term.hpp"

#include <cmath>

#include "sunvo/sunfusion/sun_residual.hpp"

namespace sunvo::sunfusion {

Status SunFusionOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(gate.validate());
  if (!world_up.allFinite() || std::abs(world_up.norm() - 1.0) > 1e-6) {
    return invalidArgument("sun_fusion.world_up must be a unit vector");
  }
  if (!(loss_scale >= 0.0 && loss_scale <= 100.0)) {
    return invalidArgument("sun_fusion.loss_scale out of range [0, 100]");
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
  return Status::ok();
}

void SunWindowTerm::attach(backend::BundleWindow& window) {
  window.setPoseResidualHook([this](backend::BundleWindow& w) { return onSolve(w); });
}

void SunWindowTerm::addObservation(const SunObservation& observation) {
  const std::size_t slot = observation.measurement.sequence % pending_.size();
  pending_[slot] = Pending{};
  pending_[slot].obs = observation;
  used_[slot] = true;
}

Status SunWindowTerm::onSolve(backend::BundleWindow& window) {
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
    if (!p.accepted) continue;
    // The base may have moved since the last solve (the window slid), so s_b is rebuilt each time.
    const SunMeasurement& m = p.obs.measurement;
    if (m.kind == SunMeasurementKind::kAzimuthOnly) {
      p.cost.reset(SunAzimuthResidual::Create(sun_b, xzDirection(m.sun_c), m.sigma));
    } else {
      p.cost.reset(SunDirectionResidual::Create(sun_b, m.sun_c, m.sigma));
    }
    SUNVO_RETURN_IF_ERROR(window.addPoseResidual(s, p.cost.get(), loss_.get()));
  }
  return Status::ok();
}

}  // namespace sunvo::sunfusion
