// Validation of SunFusionOptions (sun_fusion_options.hpp): each field against its documented range,
// the error naming the config key.
#include "sunvo/sunfusion/sun_fusion_options.hpp"

#include <cmath>

#include "sunvo/sunfusion/walk_bank.hpp"

namespace sunvo::sunfusion {

Status SunFusionOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(gate.validate());
  if (const Status s = vertical_gate.validate(); !s.isOk()) {
    return invalidArgument("fusion.vertical_gate: " + s.message());
  }
  if (!world_up.allFinite() || std::abs(world_up.norm() - 1.0) > 1e-6) {
    return invalidArgument("fusion.world_up must be a unit vector");
  }
  if (!(world_up_alignment_frames >= 0 && world_up_alignment_frames <= 100000)) {
    return invalidArgument("fusion.world_up_alignment_frames out of range [0, 100000]");
  }
  if (!(start_tilt_max_deg > 0.0 && start_tilt_max_deg <= 45.0)) {
    return invalidArgument("fusion.start_tilt_max_deg out of range (0, 45]");
  }
  if (!(loss_scale >= 0.0 && loss_scale <= 100.0)) {
    return invalidArgument("fusion.loss_scale out of range [0, 100]");
  }
  if (!(initial_attitude_sigma_deg > 0.0 && initial_attitude_sigma_deg <= 45.0)) {
    return invalidArgument("fusion.initial_attitude_sigma_deg out of range (0, 45]");
  }
  if (!(attitude_drift_deg_per_frame >= 0.0 && attitude_drift_deg_per_frame <= 5.0)) {
    return invalidArgument("fusion.attitude_drift_deg_per_frame out of range [0, 5]");
  }
  if (!(min_drift_deg_per_frame >= 0.0 && min_drift_deg_per_frame <= max_drift_deg_per_frame &&
        max_drift_deg_per_frame <= 5.0)) {
    return invalidArgument(
        "fusion.min_drift_deg_per_frame / max_drift_deg_per_frame: need 0 <= min <= max <= 5");
  }
  if (!(vertical_max_drift_deg_per_frame >= min_drift_deg_per_frame &&
        vertical_max_drift_deg_per_frame <= 5.0)) {
    return invalidArgument(
        "fusion.vertical_max_drift_deg_per_frame out of range [min_drift_deg_per_frame, 5]");
  }
  if (!(drift_adaptation_rate > 0.0 && drift_adaptation_rate <= 1.0)) {
    return invalidArgument("fusion.drift_adaptation_rate out of range (0, 1]");
  }
  if (!(persistence_forgetting > 0.0 && persistence_forgetting < 1.0)) {
    return invalidArgument("fusion.persistence_forgetting out of range (0, 1)");
  }
  if (!(persistence_false_alarm > 0.0 && persistence_false_alarm <= 0.5)) {
    return invalidArgument("fusion.persistence_false_alarm out of range (0, 0.5]");
  }
  if (!(persistence_step_up > 0.0 && persistence_step_up <= 2.0)) {
    return invalidArgument("fusion.persistence_step_up out of range (0, 2]");
  }
  if (!(persistence_step_down > 0.0 && persistence_step_down <= 2.0)) {
    return invalidArgument("fusion.persistence_step_down out of range (0, 2]");
  }
  if (!(persistence_huber > 0.0 && persistence_huber <= 100.0)) {
    return invalidArgument("fusion.persistence_huber out of range (0, 100]");
  }
  if (!(innovation_gate_chi2 >= 0.0 && innovation_gate_chi2 <= 1e6)) {
    return invalidArgument("fusion.innovation_gate_chi2 out of range [0, 1e6]");
  }
  if (!(evidence_sigmas > 0.0 && evidence_sigmas <= 100.0)) {
    return invalidArgument("fusion.evidence_sigmas out of range (0, 100]");
  }
  if (vertical_drift_adaptation == VerticalDriftAdaptation::kLikelihood ||
      heading_drift_adaptation == HeadingDriftAdaptation::kLikelihood) {
    if (likelihood_walks < 2 || likelihood_walks > WalkBank::kMaxWalks) {
      return invalidArgument("fusion.likelihood_walks out of range [2, 8]");
    }
    if (likelihood_noise_scales < 1 || likelihood_noise_scales > WalkBank::kMaxScales) {
      return invalidArgument("fusion.likelihood_noise_scales out of range [1, 8]");
    }
    if (!(likelihood_noise_min > 0.0 && likelihood_noise_min <= likelihood_noise_max &&
          likelihood_noise_max <= 100.0)) {
      return invalidArgument(
          "fusion.likelihood_noise_min / likelihood_noise_max: need 0 < min <= max <= 100");
    }
    if (!(likelihood_forgetting > 0.0 && likelihood_forgetting <= 1.0)) {
      return invalidArgument("fusion.likelihood_forgetting out of range (0, 1]");
    }
    if (likelihood_up_bias_scales < 1 || likelihood_up_bias_scales > WalkBank::kMaxBiasScales) {
      return invalidArgument("fusion.likelihood_up_bias_scales out of range [1, 4]");
    }
    if (!(likelihood_up_bias_max_deg > 0.0 && likelihood_up_bias_max_deg <= 10.0)) {
      return invalidArgument("fusion.likelihood_up_bias_max_deg out of range (0, 10]");
    }
    if (likelihood_up_bias_scales > 1 && vertical_bias_sigma_deg > 0.0) {
      return invalidArgument(
          "fusion.likelihood_up_bias_scales > 1 and vertical_bias_sigma_deg > 0: the cue's bias "
          "is estimated one way or the other, not both");
    }
    if (!(min_drift_deg_per_frame > 0.0)) {
      return invalidArgument(
          "fusion.min_drift_deg_per_frame must be > 0 with vertical_drift_adaptation or "
          "heading_drift_adaptation likelihood (the bank's slowest walk)");
    }
  }
  if (!(evidence_forgetting > 0.0 && evidence_forgetting < 1.0)) {
    return invalidArgument("fusion.evidence_forgetting out of range (0, 1)");
  }
  if (!(evidence_correlation >= 1.0 && evidence_correlation <= 1000.0)) {
    return invalidArgument("fusion.evidence_correlation out of range [1, 1000]");
  }
  if (!(max_correction_deg >= 0.0 && max_correction_deg <= 180.0)) {
    return invalidArgument("fusion.max_correction_deg out of range [0, 180]");
  }
  if (!(sun_bias_sigma_deg >= 0.0 && sun_bias_sigma_deg <= 45.0)) {
    return invalidArgument("fusion.sun_bias_sigma_deg out of range [0, 45]");
  }
  if (!(sun_bias_length_frames >= 1.0 && sun_bias_length_frames <= 1e6)) {
    return invalidArgument("fusion.sun_bias_length_frames out of range [1, 1e6]");
  }
  if (!(vertical_bias_sigma_deg >= 0.0 && vertical_bias_sigma_deg <= 10.0)) {
    return invalidArgument("fusion.vertical_bias_sigma_deg out of range [0, 10]");
  }
  if (!(vertical_bias_length_frames >= 1.0 && vertical_bias_length_frames <= 1e7)) {
    return invalidArgument("fusion.vertical_bias_length_frames out of range [1, 1e7]");
  }
  return Status::ok();
}

}  // namespace sunvo::sunfusion
