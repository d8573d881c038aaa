#pragma once
// The paper's experiment (Table 1): pure VO against VO + sun from several sun sources on one
// route, with the same feature tracks for every run.
//
// A route supplies stereo feature tracks (real or simulated), its ground-truth camera poses and
// the true sun direction in each camera frame. The world frame is the first camera frame (KITTI
// odometry ground truth has no GPS); the sun in that world at frame k is s_w,k = C_w_ck,gt s_ck,gt,
// which is what an ephemeris gives at the frame's time and place once the first pose is known
// (and it keeps the sun's slow motion, about 0.25 deg/min, that the paper ignored). Each run is one
// pipeline::SunAidedOdometry over the tracks.
//
// Sun measurements are made every `every_n_frames` frames from the truth through a sun source:
// the true vector itself ("ground truth"), or an error model emulating an image estimator.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/selfcal/stereo_self_calibration.hpp"
#include "sunvo/sunfusion/simulated_sun_source.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"
#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::experiment {

struct Route {
  std::string name;    // e.g. "2011_09_30_drive_0020 (real tracks)"
  std::string source;  // Dataset::describe() of the data it came from (image size, drops)
  StereoCamera camera;
  std::vector<FrameFeatures> frames;
  std::vector<TimeNs> times_ns;           // frame times (UTC ns when known, else relative)
  std::vector<Isometry3> T_w_c_gt;        // world = first camera frame of the recording
  std::vector<Eigen::Vector3d> sun_c_gt;  // true unit sun vector per frame, camera frame
  std::vector<Eigen::Vector3d> sun_w;     // the same in the world frame
  Eigen::Vector3d world_up = -Eigen::Vector3d::UnitY();  // KITTI's first camera is level
};

struct SunSourceSpec {
  std::string name;                // column header, e.g. "VO+Sun (Sun-CNN-like)"
  sunfusion::SunErrorModel model;  // error model (all zero = the true vector)
  sunfusion::SunGateOptions gate;  // gate for this source's measurements
};

struct ExperimentOptions {
  vo::VoOptions vo;
  int every_n_frames = 5;  // a sun measurement every n-th frame, [1, 1000]
  int max_frames = 0;      // 0 = the whole route; else the first max_frames frames, >= 0
  // A simulated "up" measurement on the every-n frames of every run (the vertical cue's error
  // model; none by default). A pure-VO run with it is "VO+vertical-like".
  std::optional<sunfusion::VerticalErrorModel> vertical;
  // Where the route's gravity truly is (what the simulated "up" measures): the first camera's -y
  // turned about its x axis (pitch) then its z axis (roll), deg, [-30, 30]. The fusion is told -y
  // (route.world_up); a real first camera is tilted by the road's camber and slope and the mount.
  // 0, 0 = level.
  double true_up_pitch_deg = 0.0;
  double true_up_roll_deg = 0.0;
  // A start attitude that is wrong in tilt, deg, [-30, 30] each: VO starts from the first true
  // pose turned by this much about the camera's x axis (pitch) and optical axis (roll), as a
  // rover started with the wrong configured pitch and roll (fusion.world_up_alignment_use
  // kStartTilt levels it from the simulated "up"). The evaluation stays against the true poses.
  double start_pitch_error_deg = 0.0;
  double start_roll_error_deg = 0.0;
  // Online stereo self-calibration of the tracks before the odometry (off by default).
  selfcal::StereoSelfCalibrationOptions self_calibration;
  // Gate and world_up are set per source / route. VO starts at the ground-truth first pose, so the
  // attitude is known at frame 0: its prior sigma is 0.1 deg instead of the generic 1 deg.
  sunfusion::SunFusionOptions fusion = [] {
    sunfusion::SunFusionOptions f;
    f.initial_attitude_sigma_deg = 0.1;
    return f;
  }();
  Status validate() const;
};

struct RunResult {
  std::string name;
  std::vector<Isometry3> T_w_c;
  sunfusion::GateCounters gate;           // all zero for pure VO
  sunfusion::GateCounters vertical_gate;  // the vertical source's (when options.vertical)
  metrics::TiltMetrics tilt;              // attitude error split into tilt and heading
  int world_up_answers = 0;               // "up" answers that measured the world's up (if aligned)
  double world_up_error_deg = 0.0;  // angle of the world's up in use from the route's true one
  bool start_tilt_judged = false;   // kStartTilt: the "up" answers measured the start's tilt error
  bool start_levelled = false;      // and it was significant and removed
  double start_tilt_deg = 0.0;      // the tilt error the answers measured, deg
  int lost_frames = 0;
  double median_ms = 0.0;  // VO time per frame (association, RANSAC, window), median
  double p99_ms = 0.0;
  // Self-calibration (when on): the right camera's roll and pitch at the end, mrad, and resets.
  double selfcal_roll_mrad = 0.0;
  double selfcal_pitch_mrad = 0.0;
  std::uint64_t selfcal_resets = 0;
  metrics::Evaluation evaluation;
};

// Where the route's gravity truly is in its world: route.world_up turned by the options'
// true_up_pitch_deg and true_up_roll_deg (what the simulated "up" measures).
Eigen::Vector3d trueUpWorld(const Route& route, const ExperimentOptions& options);
// The first camera pose T_w_c0 turned by a start attitude error, deg: pitch about the camera's x
// axis, roll about its optical axis (ExperimentOptions/ReplayOptions::start_*_error_deg).
Isometry3 withStartTiltError(const Isometry3& T_w_c0, double pitch_deg, double roll_deg);

// Called after frame k was processed, with the odometry (its pose, sun counters, attitude
// covariance): traces and diagnostics (sunvo_fusion_trace).
using FrameObserver = std::function<void(std::size_t k, const pipeline::SunAidedOdometry&)>;

// Runs pure VO (spec == nullopt) or VO + sun from one source over the route.
Expected<RunResult> runRoute(const Route& route, const std::optional<SunSourceSpec>& spec,
                             const ExperimentOptions& options, const FrameObserver& observer = {});

// The sun sources of the built-in experiment: the true vector, and error models emulating the
// paper's three image estimators (Lalonde, Lalonde-VO, Sun-CNN). The models' statistics are our
// assumptions, documented in docs/experiment.md, not numbers from the paper.
std::vector<SunSourceSpec> defaultSunSources(std::uint32_t seed);

struct SimulatedRouteOptions {
  std::uint32_t seed = 7;
  double pixel_noise_px = 0.7;  // tracks' pixel noise, px
  double outlier_share = 0.05;  // gross mismatches
};

// A route by name or path, through the dataset seam (drivers/dataset):
//  - "0020": the real feature tracks of 2011_09_30_drive_0020 (DATA/kitti_tracks) with the true sun
//    of KITTI odometry sequence 06 (the same drive);
//  - "NN" (a KITTI odometry sequence id): DATA/kitti_odometry/NN, i.e. NN_gt_poses.txt,
//    NN_times.txt and NN_sun_cam.csv, with tracks simulated along the ground truth;
//  - any other string: a dataset path (a track folder with a sun file, or a trajectory folder or
//    prefix): its real tracks when it has them, else tracks simulated along its ground truth.
// The route needs ground truth and the true sun for every frame.
Expected<Route> loadRoute(const std::string& spec, const std::string& data_dir,
                          const SimulatedRouteOptions& options);

}  // namespace sunvo::experiment
