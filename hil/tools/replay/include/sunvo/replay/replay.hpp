#pragma once
// Replay of a recorded (or rendered) drive in the KITTI raw layout through the whole estimation
// chain, as it runs on the rover:
//   KittiStereoSource (images, UTC timestamps) -> OXTS of the first frame -> local ENU world
//   (GeographicLib) and the first camera pose through the calibration chain -> per frame:
//   image pipeline (front end + RANSAC + window) with the sun residual every n-th frame, the sun
//   in the world from the NREL SPA at the frame's GPS fix and UTC time.
// Sun measurements come from a sun source: here the drive's ground-truth sun in the camera
// (gt/sun_cam0.csv, written by the renderer) through an error model, until the image estimators
// land. Ground truth for the evaluation: gt/poses_cam0_enu.txt (camera 0 in the same ENU frame).
// Deterministic: the solver is bounded by iterations only.

#include <optional>
#include <string>
#include <vector>

#include "sunvo/experiment/experiment.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/pipeline/stereo_visual_odometry.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::replay {

struct ReplayOptions {
  std::string drive_dir;          // <date>/<date>_drive_NNNN_sync, with oxts/ and gt/
  std::int64_t utc_offset_s = 0;  // s: offset of the drive's timestamps to UTC (renderer: 0)
  int every_n_frames = 5;         // a sun measurement every n-th frame, [1, 1000]
  int max_frames = 0;             // 0 = all
  pipeline::PipelineOptions pipeline;
  // The first camera pose comes from the first OXTS record (an RT3000-class INS: about 0.03 deg
  // roll/pitch and 0.1 deg heading), so the attitude prior sigma is 0.1 deg, not the generic 1.
  sunfusion::SunFusionOptions fusion = [] {
    sunfusion::SunFusionOptions f;
    f.initial_attitude_sigma_deg = 0.1;
    return f;
  }();
  // Cap of the adapted attitude random walk for the image estimators, deg/frame,
  // [fusion.min_drift_deg_per_frame, 5]; the error-model sources use
  // fusion.max_drift_deg_per_frame. An image estimator's error is correlated along a street (the
  // same scene for many frames), and the persistence test reads such a stretch as a drift. 0.01 is
  // the random walk's start value: on the three benchmark drives Sun-CNN made VO worse by up to
  // +246 % rot. ARMSE with 0.05, and by at most +0.5 % with 0.01 (docs/sun_estimators.md).
  double image_max_drift_deg_per_frame = 0.01;
  // The fusion options of an image-estimator run: `fusion` with the cap above.
  sunfusion::SunFusionOptions imageFusion() const;
  Status validate() const;
};

struct ReplayRun {
  std::string name;
  std::vector<Isometry3> T_w_c;  // ENU world
  sunfusion::GateCounters gate;
  int lost_frames = 0;
  double median_ms = 0.0;  // pipeline time per frame
  double p99_ms = 0.0;
  int sun_calls = 0;           // image estimator calls (every n-th frame)
  std::vector<double> sun_ms;  // their wall times, ms
};

struct ReplayData {
  std::vector<Isometry3> T_w_c_gt;  // camera 0 in the replay's world (ENU at the first GPS fix)
  std::vector<TimeNs> times_ns;
  geodesy::GeodeticPoint origin;
};

// Loads the ground truth of a drive (gt/poses_cam0_enu.txt in the ENU frame of gt/origin.txt,
// moved into the world of the replay; image_00/timestamps.txt; the first OXTS fix).
Expected<ReplayData> loadReplayData(const ReplayOptions& options);

// One run: pure VO (no spec, no estimator), VO + sun from one error-model source (spec), or
// VO + sun from an image estimator run on the left colour image every n-th frame, with the prior
// from the last VO pose and the ephemeris (image_sun; not both).
Expected<ReplayRun> replayDrive(const ReplayOptions& options,
                                const std::optional<experiment::SunSourceSpec>& spec,
                                sunfusion::ImageSunEstimator* image_sun = nullptr);

}  // namespace sunvo::replay
