#include "sunvo/pipeline/sun_aided_odometry.hpp"

namespace sunvo::pipeline {

Status SunAidedOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(pipeline.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("every_n_frames: " + std::to_string(every_n_frames) +
                           " is outside [1, 1000]");
  }
  return Status::ok();
}

Status SunAidedOdometry::init(const SunAidedOptions& options, const StereoCamera& camera,
                              const Isometry3& T_w_c0, OdometryInput input) {
  initialized_ = false;
  SUNVO_RETURN_IF_ERROR(options.validate());
  options_ = options;
  input_ = input;
  if (input == OdometryInput::kImages) {
    SUNVO_RETURN_IF_ERROR(vo_.init(options.pipeline, camera, T_w_c0));
  } else {
    SUNVO_RETURN_IF_ERROR(tracks_.init(options.pipeline.vo, camera, T_w_c0));
  }
  backend::BundleWindow& window = backEnd().window();
  if (options.use_sun) {
    SUNVO_RETURN_IF_ERROR(sun_term_.init(options.fusion));
    sun_term_.attach(window);
  } else {
    window.setPoseResidualHook(nullptr);
    window.setPostSolveHook(nullptr);
  }
  T_w_c_ = T_w_c0;
  sun_offered_ = 0;
  initialized_ = true;
  return Status::ok();
}

void SunAidedOdometry::addSun(const sunfusion::SunObservation& observation) {
  ++sun_offered_;
  if (!initialized_ || !options_.use_sun) return;
  sun_term_.addObservation(observation);
}

Expected<FrameResult> SunAidedOdometry::process(const StereoFrame& frame) {
  if (!initialized_ || input_ != OdometryInput::kImages) {
    return failedPrecondition("SunAidedOdometry::process(StereoFrame): not initialised for images");
  }
  Expected<FrameResult> r = vo_.process(frame);
  if (r) T_w_c_ = r->vo.T_w_c;
  return r;
}

Expected<vo::VoResult> SunAidedOdometry::process(const FrameFeatures& frame) {
  if (!initialized_ || input_ != OdometryInput::kFeatures) {
    return failedPrecondition(
        "SunAidedOdometry::process(FrameFeatures): not initialised for features");
  }
  Expected<vo::VoResult> r = tracks_.process(frame);
  if (r) T_w_c_ = r->T_w_c;
  return r;
}

void SunAidedOdometry::setSolverTimeBudget(double seconds) {
  backEnd().window().setSolverTimeBudget(seconds);
}

}  // namespace sunvo::pipeline
