#include "sunvo/pipeline/sun_aided_odometry.hpp"

#include <chrono>

#include "sunvo/core/geometry.hpp"

namespace sunvo::pipeline {

Status SunAidedOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(pipeline.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  SUNVO_RETURN_IF_ERROR(vertical.estimator.validate());
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("every_n_frames: " + std::to_string(every_n_frames) +
                           " is outside [1, 1000]");
  }
  return Status::ok();
}

Status SunAidedOdometry::init(const SunAidedOptions& options, const StereoCamera& camera,
                              const Isometry3& T_w_c0, OdometryInput input) {
  initialized_ = false;
  if (input == OdometryInput::kFeatures) {
    // No front end: the tracks carry their own right rows, so the self-calibration does not need
    // frontend.measure_v_right.
    SunAidedOptions checked = options;
    checked.pipeline.frontend.measure_v_right = true;
    SUNVO_RETURN_IF_ERROR(checked.validate());
  } else {
    SUNVO_RETURN_IF_ERROR(options.validate());
  }
  options_ = options;
  input_ = input;
  if (input == OdometryInput::kImages) {
    SUNVO_RETURN_IF_ERROR(vo_.init(options.pipeline, camera, T_w_c0));
  } else {
    SUNVO_RETURN_IF_ERROR(tracks_.init(options.pipeline.vo, camera, T_w_c0));
    SUNVO_RETURN_IF_ERROR(selfcal_.init(options.pipeline.self_calibration, camera));
    corrected_.observations.reserve(static_cast<std::size_t>(options.pipeline.vo.max_observations));
  }
  selfcal_report_ = selfcal::SelfCalibrationReport{};
  selfcal_ms_ = 0.0;
  backend::BundleWindow& window = backEnd().window();
  vertical_active_ =
      options.vertical.enabled && options.vertical.measure_here && input == OdometryInput::kImages;
  vertical_stats_ = VerticalStats{};
  if (vertical_active_) SUNVO_RETURN_IF_ERROR(vertical_.init(options.vertical.estimator, camera));
  if (options.use_sun || options.vertical.enabled) {
    SUNVO_RETURN_IF_ERROR(sun_term_.init(options.fusion));
    sun_term_.attach(window);
  } else {
    window.setPoseResidualHook(nullptr);
    window.setPostSolveHook(nullptr);
  }
  T_w_c_ = T_w_c0;
  p_w_c0_ = T_w_c0.translation();
  sun_offered_ = 0;
  initialized_ = true;
  return Status::ok();
}

void SunAidedOdometry::addSun(const sunfusion::SunObservation& observation) {
  ++sun_offered_;
  if (!initialized_ || !options_.use_sun) return;
  sun_term_.addObservation(observation);
}

void SunAidedOdometry::addVertical(const sunfusion::SunObservation& observation) {
  if (!initialized_ || !options_.vertical.enabled) return;
  sun_term_.addVertical(observation);
}

Expected<FrameResult> SunAidedOdometry::process(const StereoFrame& frame) {
  if (!initialized_ || input_ != OdometryInput::kImages) {
    return failedPrecondition("SunAidedOdometry::process(StereoFrame): not initialised for images");
  }
  levelStartIfDue(frame.sequence);
  double vertical_ms = 0.0;
  if (vertical_active_ && isCueFrame(frame.sequence)) {
    const auto t0 = std::chrono::steady_clock::now();
    // The prior: "up" in the last frame's camera (one frame of motion away from this one).
    const Eigen::Vector3d up_w = sun_term_.worldUp();  // aligned, when the world has no gravity
    const Eigen::Vector3d prior_c = T_w_c_.linear().transpose() * up_w;
    ++vertical_stats_.calls;
    Expected<vertical::VerticalMeasurement> m = vertical_.estimate(frame.left, prior_c);
    if (!m) {
      ++vertical_stats_.errors;  // the image is refused; VO goes on without the cue
    } else if (m->valid) {
      ++vertical_stats_.valid;
      sunfusion::SunObservation o;
      o.measurement.sequence = frame.sequence;
      o.measurement.time_ns = frame.trigger_time_ns;
      o.measurement.kind = sunfusion::SunMeasurementKind::kFull3d;
      o.measurement.sun_c = m->up_c;
      o.measurement.sigma = m->sigma_rad;
      o.measurement.sigma_strong = m->sigma_strong_rad;
      o.measurement.strong_axis_c = m->strong_axis_c;
      o.sun_w = up_w;
      sun_term_.addVertical(o);
    }
    vertical_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  Expected<FrameResult> r = vo_.process(frame);
  if (r) {
    T_w_c_ = r->vo.T_w_c;
    selfcal_report_ = r->self_calibration;
    r->times.vertical_ms = vertical_ms;
    r->times.total_ms += vertical_ms;
  }
  return r;
}

Expected<vo::VoResult> SunAidedOdometry::process(const FrameFeatures& frame) {
  if (!initialized_ || input_ != OdometryInput::kFeatures) {
    return failedPrecondition(
        "SunAidedOdometry::process(FrameFeatures): not initialised for features");
  }
  levelStartIfDue(frame.sequence);
  const FrameFeatures* in = &frame;
  if (selfcal_.active()) {
    const auto t0 = std::chrono::steady_clock::now();
    selfcal_report_ = selfcal_.process(frame, &corrected_);
    in = &corrected_;
    selfcal_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  Expected<vo::VoResult> r = tracks_.process(*in);
  if (r) T_w_c_ = r->T_w_c;
  return r;
}

void SunAidedOdometry::levelStartIfDue(std::uint64_t sequence) {
  if (!options_.use_sun && !options_.vertical.enabled) return;  // no fusion, no cue
  const std::optional<Eigen::Vector3d> e_w = sun_term_.takeStartLevelling(sequence);
  if (!e_w) return;
  const Eigen::Matrix3d C_w_wnew = expSO3(*e_w);
  backEnd().turnWorldAbout(C_w_wnew, p_w_c0_);
  T_w_c_.translation() = p_w_c0_ + C_w_wnew * (T_w_c_.translation() - p_w_c0_);
  T_w_c_.linear() = C_w_wnew * T_w_c_.linear();
}

void SunAidedOdometry::setSolverTimeBudget(double seconds) {
  backEnd().window().setSolverTimeBudget(seconds);
}

}  // namespace sunvo::pipeline
