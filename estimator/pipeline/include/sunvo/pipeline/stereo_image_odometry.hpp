#pragma once
// Image stereo visual odometry: StereoFrontend (keypoints, stereo and temporal matching, landmark
// ids) followed by vo::StereoTrackOdometry (3-point RANSAC + bounded Ceres window) behind one
// synchronous call per rectified stereo pair.
//
//   StereoImageOdometry vo;
//   SUNVO_RETURN_IF_ERROR(vo.init(PipelineOptions{}, camera));   // allocates the buffers
//   Expected<FrameResult> r = vo.process(frame);                 // per frame
//
// Per frame it reports the back end's VoResult and the wall time of each stage (monotonic clock):
// detect (both images), temporal matching (tracks around the circle), stereo matching (new
// features), RANSAC (association + RANSAC), window (Ceres) and the total of process().
//
// Motion hint: with PipelineOptions::rotation_hint the front end's temporal search window for
// features without a motion history is centred on the image shift that the last measured
// inter-frame rotation predicts for the next frame (constant velocity, points at infinity: the
// translation part needs depth and is left to the per-feature prediction of the front end).
//
// No threads, files or devices. The front end allocates nothing per frame; RANSAC and the Ceres
// window make their own bounded per-frame allocations (measured by sunvo_bench_vo). An optional
// counter (e.g. a heap allocation counter) is sampled around each of the two stages so a caller
// can attribute events to them without this library knowing what is counted.
// Not thread-safe: one instance per thread.

#include <cstdint>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/frontend/stereo_frontend.hpp"
#include "sunvo/selfcal/stereo_self_calibration.hpp"
#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::pipeline {

// The front end's default max_features (2048) exceeds the back end's default max_observations
// (2000); the pipeline's default caps the front end at the back end's size.
inline FrontendOptions defaultPipelineFrontendOptions() {
  FrontendOptions o;
  o.max_features = 2000;
  return o;
}

struct PipelineOptions {
  // See stereo_frontend.hpp; frontend.max_features must be <= max_observations (vo).
  FrontendOptions frontend = defaultPipelineFrontendOptions();
  vo::VoOptions vo;            // see stereo_track_odometry.hpp
  bool rotation_hint = true;   // centre the front end's un-predicted temporal search on the image
                               //   shift of the last measured rotation (see the header comment)
  double max_hint_px = 100.0;  // px, [0, 1000]: a larger predicted shift is not used as a hint
  // Online stereo self-calibration of the right camera between the front end and the back end
  // (estimator/selfcal); enabled needs frontend.measure_v_right (the right rows it learns from).
  selfcal::StereoSelfCalibrationOptions self_calibration;

  // The error names the bad key as the config names it, relative to the options ("frontend.x",
  // "window.x", "ransac.x", "max_hint_px"); the rover prefixes "estimator.".
  Status validate() const;
  // The back end's fields are listed at this level (estimator.window.*, estimator.ransac.*).
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("frontend", s.frontend);
    vo::VoOptions::fields(s.vo, v);
    v("rotation_hint", s.rotation_hint);
    v("max_hint_px", s.max_hint_px);
    v("self_calibration", s.self_calibration);
  }
};

// Times of one process() call, ms: wall time (monotonic clock) and CPU time of the calling thread
// (*_cpu_ms; lower than the wall time when the core is shared with other work).
struct StageTimes {
  double detect_ms = 0.0;        // front end: smoothing, gradients, responses, NMS, descriptors
  double temporal_ms = 0.0;      // front end: tracks around the circle (previous <-> current)
  double stereo_ms = 0.0;        // front end: new features, left <-> right matching, subpixel
  double frontend_ms = 0.0;      // the whole front end call (>= detect + temporal + stereo)
  double ransac_ms = 0.0;        // back end: association by id + 3-point RANSAC
  double window_ms = 0.0;        // back end: window update + Ceres solve
  double odometry_ms = 0.0;      // the whole back end call (>= ransac + window)
  double total_ms = 0.0;         // process() from entry to return
  double vertical_ms = 0.0;      // the vertical cue (SunAidedOdometry, its frames; in total_ms)
  double detect_cpu_ms = 0.0;    // CPU time of detect
  double match_cpu_ms = 0.0;     // CPU time of temporal + stereo matching
  double frontend_cpu_ms = 0.0;  // CPU time of the whole front end call
  double odometry_cpu_ms = 0.0;  // CPU time of the whole back end call
  double total_cpu_ms = 0.0;     // CPU time of process()

  double matchMs() const { return temporal_ms + stereo_ms; }
};

struct FrameResult {
  vo::VoResult vo;          // pose, status, RANSAC/window figures of this frame
  StageTimes times;         // per-stage wall times
  FrontendStats frontend;   // the front end's counters of this frame
  int num_features = 0;     // stereo observations output by the front end
  float hint_du_px = 0.0F;  // pixel-shift hint given to the front end for this frame
  float hint_dv_px = 0.0F;
  // Increase of the stage counter (setStageCounter) during the front end / back end call; 0
  // without a counter.
  std::uint64_t frontend_counter_delta = 0;
  std::uint64_t odometry_counter_delta = 0;
  selfcal::SelfCalibrationReport self_calibration;  // this frame's estimate (if enabled)
};

class StereoImageOdometry {
 public:
  // A monotonically increasing event count sampled around each stage (e.g. heap allocations).
  using StageCounter = std::uint64_t (*)();

  // Allocates every front-end and back-end buffer. T_w_c0: pose of the first frame's camera.
  // May be called again to restart (forgets everything).
  Status init(const PipelineOptions& options, const StereoCamera& camera,
              const Isometry3& T_w_c0 = Isometry3::Identity());

  // One rectified stereo pair (CV_8UC1, the camera's size or smaller within the front end's
  // maximum). Degenerate images (black, textureless, no stereo structure) are not errors: the
  // frame is reported kLost and never carries NaN. Errors: not initialised, wrong image type or
  // size, more features than the back end accepts.
  Expected<FrameResult> process(const StereoFrame& frame);

  // The features of the last process() call (valid until the next call).
  const FrameFeatures& lastFeatures() const { return features_; }

  void setStageCounter(StageCounter counter) { counter_ = counter; }

  StereoFrontend& frontend() { return frontend_; }
  vo::StereoTrackOdometry& odometry() { return odometry_; }  // e.g. its window's residual hook
  const PipelineOptions& options() const { return options_; }

 private:
  // Image shift (current - previous) of a point at infinity on the optical axis under rotation
  // C_k_km1; false if it does not project in front of the camera or exceeds max_hint_px.
  bool rotationShift(const Isometry3& T_k_km1, float* du, float* dv) const;

  PipelineOptions options_;
  StereoCamera camera_;
  StereoFrontend frontend_;
  vo::StereoTrackOdometry odometry_;
  FrameFeatures features_;
  selfcal::StereoSelfCalibration self_calibration_;
  FrameFeatures corrected_;  // features_ with the self-calibration's corrections
  StageCounter counter_ = nullptr;
  bool initialized_ = false;
  bool have_motion_ = false;  // last_motion_ was measured on the previous frame
  Isometry3 last_motion_ = Isometry3::Identity();
};

}  // namespace sunvo::pipeline
