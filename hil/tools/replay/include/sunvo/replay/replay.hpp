#pragma once
// Replay of a recorded (or rendered) drive with images through the whole estimation chain, as it
// runs on the rover:
//   dataset (drivers/dataset: a KITTI raw drive, a sunvo render or a KITTI odometry sequence) ->
//   images through kitti::KittiStereoSource -> pipeline::SunAidedOdometry (front end + RANSAC +
//   window, the sun residual every n-th frame) from the dataset's first camera pose.
// The sun in the world comes from the NREL SPA at the frame's GPS fix and UTC time when the
// dataset has fixes and a known UTC (raw drives, renders), else from the dataset's true sun.
// Measurements come from a sun source: the dataset's true sun in the camera through an error model
// (experiment::SunSourceSpec), or an image estimator run on the left image every n-th frame with
// the prior from the last VO pose. Ground truth for the evaluation: the dataset's.
// Deterministic: the solver is bounded by iterations only.
// Bad frames (a missing, truncated or corrupt image, or one of the wrong size or channel count) are
// dropped and counted; VO matches the next good frame against the last good one. The run stops
// with the frame's error only when more than max_consecutive_bad_frames come in a row.

#include <optional>
#include <string>
#include <vector>

#include "sunvo/dataset/dataset.hpp"
#include "sunvo/experiment/experiment.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::replay {

struct ReplayOptions {
  // The drive: dataset.path and, for a KITTI raw drive, dataset.utc_offset_s (KITTI's files name
  // no zone; a render writes UTC). dataset.last_frame limits the frames.
  dataset::DatasetOptions dataset;
  int every_n_frames = 5;  // a sun measurement every n-th frame, [1, 1000]
  pipeline::PipelineOptions pipeline;
  // The camera's "up" from the images on the every-n frames (off by default): with the sun or
  // alone (a pure-VO run then becomes "VO+vertical").
  pipeline::VerticalCueOptions vertical;
  // The first camera pose comes from the first OXTS record (an RT3000-class INS: about 0.03 deg
  // roll/pitch and 0.1 deg heading), so the attitude prior sigma is 0.1 deg, not the generic 1.
  sunfusion::SunFusionOptions fusion = [] {
    sunfusion::SunFusionOptions f;
    f.initial_attitude_sigma_deg = 0.1;
    return f;
  }();
  // The image estimators' fusion settings (sunfusion::ImageEstimatorFusion says why); the
  // error-model sources use `fusion`'s. Cap of the adapted attitude random walk, deg/frame,
  // [fusion.min_drift_deg_per_frame, 5]; the azimuth bias state's std, deg [0, 45] (0 = none), and
  // correlation length, frames [1, 1e6].
  double image_max_drift_deg_per_frame = sunfusion::ImageEstimatorFusion::kMaxDriftDegPerFrame;
  double image_sun_bias_sigma_deg = sunfusion::ImageEstimatorFusion::kSunBiasSigmaDeg;
  double image_sun_bias_length_frames = sunfusion::ImageEstimatorFusion::kSunBiasLengthFrames;
  // fusion.world_up_alignment_frames for the drive, frames, -1 or [0, 100000]: -1 = by its world,
  // sunfusion::kWorldUpAlignmentFrames when that is the first camera (KITTI odometry: no gravity
  // in it), sunfusion::kStartTiltFrames when fusion.world_up_alignment_use is kStartTilt (an ENU
  // world whose start tilt is measured, as on a rover; not for a first-camera world), 0 in ENU
  // (raw drives and renders: the first pose comes from the INS).
  int world_up_alignment_frames = -1;
  // A start attitude that is wrong in tilt, deg, [-30, 30] each: VO starts from the first camera
  // pose turned by this much about the camera's x axis (pitch) and optical axis (roll), as on a
  // rover whose configured start pitch and roll (world.camera_pitch_deg / camera_roll_deg) are not
  // those of the ground it was parked on. The evaluation stays against the true poses.
  double start_pitch_error_deg = 0.0;
  double start_roll_error_deg = 0.0;
  // Bad frames in a row that are dropped before the run stops with the last one's error, frames,
  // [0, 100000]; 0 = the first bad frame stops the run (and open() needs every image file).
  int max_consecutive_bad_frames = 10;
  // Keep every processed frame's front-end output (ReplayRun::features), e.g. to write the drive's
  // tracks as a track folder (files::writeTrackFolder).
  bool record_features = false;
  // The fusion options of an image-estimator run: `fusion` with the cap and the bias state above.
  sunfusion::SunFusionOptions imageFusion() const;
  Status validate() const;
};

struct ReplayRun {
  std::string name;
  std::vector<Isometry3> T_w_c;          // the dataset's world, one per frame processed
  std::vector<TimeNs> times_ns;          // the frames' times
  std::vector<std::size_t> frame_index;  // each pose's frame: index in the dataset's range
  int dropped_frames = 0;                // bad frames dropped (see ReplayOptions)
  sunfusion::GateCounters gate;
  sunfusion::GateCounters vertical_gate;                     // the vertical cue's (if enabled)
  pipeline::SunAidedOdometry::VerticalStats vertical_stats;  // its calls, valid, errors
  int world_up_answers = 0;        // cue answers that measured the world's up (if aligned)
  double world_up_tilt_deg = 0.0;  // the estimate's angle from the assumed up, deg
  Eigen::Vector3d world_up = Eigen::Vector3d::Zero();  // the world's up in use at the end
  // start_tilt: the answers measured the start's tilt error (world_up_tilt_deg), which was judged
  // and, where significant, removed.
  bool start_tilt_judged = false;
  bool start_levelled = false;
  int lost_frames = 0;
  double median_ms = 0.0;  // pipeline time per frame
  double p99_ms = 0.0;
  int sun_calls = 0;                                // image estimator calls (every n-th frame)
  std::vector<double> sun_ms;                       // their wall times, ms
  selfcal::SelfCalibrationReport self_calibration;  // after the last frame (if enabled)
  std::vector<selfcal::SelfCalibrationReport> self_calibration_log;  // per frame (if enabled)
  // The fusion's attitude walks after each frame (runs with a sun or the vertical cue): the
  // tilt's and the heading's walk, deg/frame, and with the likelihood rule the bank's estimate of
  // the tilt's own walk (deg/frame) and of the cue's noise scale (true / reported std), and the
  // cue's bias state (its turn about the camera's x and z axes, deg); 0 without.
  struct WalkSample {
    double tilt_deg = 0.0;
    double heading_deg = 0.0;
    double bank_tilt_deg = 0.0;
    double noise_scale = 0.0;
    double up_bias_x_deg = 0.0;
    double up_bias_z_deg = 0.0;
  };
  std::vector<WalkSample> walk_log;
  // Per processed frame, the front end's observations before any self-calibration correction
  // (only with ReplayOptions::record_features).
  std::vector<FrameFeatures> features;
};

// Opens the dataset of a replay; it must have images. An image estimator gets the colour images
// when the drive has them, else the gray ones (if it accepts gray).
Expected<dataset::Dataset> openReplayDataset(const ReplayOptions& options);

// One run: pure VO (no spec, no estimator), VO + sun from one error-model source (spec), or
// VO + sun from an image estimator (image_sun; not both).
Expected<ReplayRun> replayDrive(const dataset::Dataset& data, const ReplayOptions& options,
                                const std::optional<experiment::SunSourceSpec>& spec,
                                sunfusion::ImageSunEstimator* image_sun = nullptr);

}  // namespace sunvo::replay
