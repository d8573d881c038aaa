#pragma once
// The sun-aided estimator every program calls: stereo visual odometry whose world attitude is
// corrected by absolute sun directions inside the bounded bundle window (the paper's Eq. 3).
//
//   SunAidedOdometry odo;
//   SUNVO_RETURN_IF_ERROR(odo.init(options, camera, T_w_c0));       // images (front end + VO)
//   for each frame k:
//     if (odo.isSunFrame(k)) odo.addSun({measurement_in_camera_k, sun_w});   // when one exists
//     Expected<FrameResult> r = odo.process(frame);                        // or FrameFeatures
//
// It owns the odometry (front end for images, or tracks in; RANSAC; the Ceres window), the sun
// fusion (gate, residuals, the world-attitude estimate and its covariance), the every-n schedule
// and the window's residual hooks: callers never reach into the window. A sun measurement is
// offered for a frame about to be processed or still in the window; a later one is counted late.
// sun_w, the sun in the VO world, comes from the caller (an ephemeris at the frame's time and
// place, or a dataset's truth), so this class stays free of clocks and positions.
//
// Online stereo self-calibration (pipeline.self_calibration.enabled) runs for both inputs: inside
// the image pipeline on the front end's right rows, or here on the tracks' right rows before the
// back end (feature input; frontend.measure_v_right is then not needed). Either way its report is
// lastSelfCalibration().
//
// With vertical.enabled and image input, the same every-n frames also measure the camera's "up"
// from the left image (estimator/vertical: the vertical vanishing point) and give it to the fusion
// as a second absolute direction (SunWindowTerm::addVertical), with or without the sun; with
// feature input there are no images and the cue is skipped (verticalActive() is false).
//
// No threads, files or devices; deterministic for the same inputs. Not thread-safe except
// isSunFrame(), which reads the immutable schedule (the rover's capture thread asks it).

#include <cstdint>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/pipeline/stereo_image_odometry.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"
#include "sunvo/vertical/vertical_estimator.hpp"

namespace sunvo::pipeline {

// The gravity cue. Config keys: vertical.enabled and the estimator's keys (vertical.max_tilt_deg,
// ...; vertical_estimator.hpp).
struct VerticalCueOptions {
  bool enabled = false;  // measure "up" from the left image on the every-n frames (images only)
  vertical::VerticalOptions estimator;
  // Not a config key: false when the caller measures "up" itself and gives it through
  // addVertical() (sunvo_rover does, in its sun thread: the cue allocates, the estimator's loop
  // must not). The fusion's vertical channel stays on either way.
  bool measure_here = true;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("enabled", s.enabled);
    vertical::VerticalOptions::fields(s.estimator, v);
  }
};

struct SunAidedOptions {
  PipelineOptions pipeline;            // front end (image input) and back end
  bool use_sun = true;                 // false: pure VO (the schedule never asks for the sun)
  int every_n_frames = 5;              // a sun measurement every n-th frame, [1, 1000]
  sunfusion::SunFusionOptions fusion;  // gate, world "up", attitude model (sun_window_term.hpp)
  VerticalCueOptions vertical;         // the camera's "up" from the images (off by default)

  // The error names the bad key relative to these options ("every_n_frames", "fusion.x",
  // "window.x").
  Status validate() const;
  // The pipeline's fields are listed at this level; use_sun is the program's to set (the rover:
  // sun.provider).
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    PipelineOptions::fields(s.pipeline, v);
    v("every_n_frames", s.every_n_frames);
    v("fusion", s.fusion);
    v("vertical", s.vertical);
  }
};

enum class OdometryInput { kImages, kFeatures };

class SunAidedOdometry {
 public:
  // Allocates every buffer. input kImages: process(StereoFrame) (front end + back end);
  // kFeatures: process(FrameFeatures) (back end only; the front end is not allocated).
  // T_w_c0: camera 0 of the first frame in the world. May be called again to restart.
  Status init(const SunAidedOptions& options, const StereoCamera& camera, const Isometry3& T_w_c0,
              OdometryInput input = OdometryInput::kImages);

  // True for the frames of the every-n schedule when the sun is used (never frame 0: its pose
  // is the given start, nothing to correct).
  bool isSunFrame(std::uint64_t sequence) const {
    return options_.use_sun && sequence > 0 &&
           sequence % static_cast<std::uint64_t>(options_.every_n_frames) == 0;
  }
  // The frames of the every-n schedule, sun or not (the vertical cue's frames).
  bool isCueFrame(std::uint64_t sequence) const {
    return sequence > 0 && sequence % static_cast<std::uint64_t>(options_.every_n_frames) == 0;
  }
  // The frames that get an absolute direction: the sun's (isSunFrame) or, with vertical.enabled,
  // the cue's. What a caller that measures them itself (vertical.measure_here false) asks for.
  bool isAidFrame(std::uint64_t sequence) const {
    return isSunFrame(sequence) || (options_.vertical.enabled && isCueFrame(sequence));
  }
  // A measurement in camera k (observation.measurement.sequence = k) with the sun in the world.
  // Ignored (counted in sunOffered() only) when the sun is off.
  void addSun(const sunfusion::SunObservation& observation);
  // An "up" measured by another source (an error model, an accelerometer at rest) for camera k:
  // measurement.sun_c = up in camera k (sun_w is not read: the world's up is worldUp()). Used
  // when vertical.enabled (with any input); ignored otherwise.
  void addVertical(const sunfusion::SunObservation& observation);

  Expected<FrameResult> process(const StereoFrame& frame);     // kImages
  Expected<vo::VoResult> process(const FrameFeatures& frame);  // kFeatures

  // Camera 0 of the last processed frame in the world (T_w_c0 before the first).
  const Isometry3& T_w_c() const { return T_w_c_; }
  // Sun bookkeeping: what the gate decided, the world-attitude covariance (rad^2, world frame).
  const sunfusion::GateCounters& sunCounters() const { return sun_term_.counters(); }
  Eigen::Matrix3d attitudeCovariance() const { return sun_term_.attitudeCovariance(); }
  const sunfusion::SunWindowTerm& sunTerm() const { return sun_term_; }
  // The world's up: fusion.world_up, or its estimate from the first frames' "up" answers when
  // fusion.world_up_alignment_frames > 0 (sun_window_term.hpp).
  const Eigen::Vector3d& worldUp() const { return sun_term_.worldUp(); }
  std::uint64_t sunOffered() const { return sun_offered_; }
  // The vertical cue: active (enabled, image input), its gate counters, and the estimator's
  // calls, valid answers and input errors (a frame whose image it refused; the run goes on).
  bool verticalActive() const { return vertical_active_; }
  const sunfusion::GateCounters& verticalCounters() const { return sun_term_.verticalCounters(); }
  struct VerticalStats {
    std::uint64_t calls = 0;
    std::uint64_t valid = 0;
    std::uint64_t errors = 0;
  };
  const VerticalStats& verticalStats() const { return vertical_stats_; }

  // The self-calibration's report of the last frame (all zero when it is off), and for feature
  // input the wall time it took, ms.
  const selfcal::SelfCalibrationReport& lastSelfCalibration() const { return selfcal_report_; }
  double lastSelfCalibrationMs() const { return selfcal_ms_; }

  // The rover shrinks the solver's time budget when a frame is late (seconds, > 0).
  void setSolverTimeBudget(double seconds);
  // A monotonically increasing event count sampled around the front end and the back end.
  void setStageCounter(StereoImageOdometry::StageCounter counter) { vo_.setStageCounter(counter); }
  // The features of the last image frame (valid until the next call).
  const FrameFeatures& lastFeatures() const { return vo_.lastFeatures(); }
  const SunAidedOptions& options() const { return options_; }
  // The back end's window, e.g. its yaw-axis estimate (BundleWindow::yawAxis).
  const backend::BundleWindow& window() { return backEnd().window(); }

 private:
  vo::StereoTrackOdometry& backEnd() {
    return input_ == OdometryInput::kImages ? vo_.odometry() : tracks_;
  }
  // fusion.world_up_alignment_use kStartTilt: before frame `sequence`, turns VO's world about
  // the first camera once the fusion has measured the start's tilt error.
  void levelStartIfDue(std::uint64_t sequence);

  SunAidedOptions options_;
  OdometryInput input_ = OdometryInput::kImages;
  StereoImageOdometry vo_;          // image input: front end + its own back end
  vo::StereoTrackOdometry tracks_;  // feature input: the back end alone
  sunfusion::SunWindowTerm sun_term_;
  selfcal::StereoSelfCalibration selfcal_;  // feature input (images: inside vo_)
  FrameFeatures corrected_;                 // the tracks with corrected right rows
  selfcal::SelfCalibrationReport selfcal_report_;
  double selfcal_ms_ = 0.0;
  vertical::VerticalEstimator vertical_;
  bool vertical_active_ = false;
  VerticalStats vertical_stats_;
  Isometry3 T_w_c_ = Isometry3::Identity();
  Eigen::Vector3d p_w_c0_ = Eigen::Vector3d::Zero();  // the first camera's world position
  std::uint64_t sun_offered_ = 0;
  bool initialized_ = false;
};

}  // namespace sunvo::pipeline
