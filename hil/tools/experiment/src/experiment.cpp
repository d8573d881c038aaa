#include "sunvo/experiment/experiment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sunvo/core/geometry.hpp"
#include "sunvo/dataset/dataset.hpp"
#include "sunvo/dataset/kitti_rigs.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/simtracks/simulated_tracks.hpp"

namespace sunvo::experiment {

Status ExperimentOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(vo.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  SUNVO_RETURN_IF_ERROR(self_calibration.validate());
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("experiment.every_n_frames out of range [1, 1000]");
  }
  if (max_frames < 0) return invalidArgument("experiment.max_frames must be >= 0");
  if (vertical) SUNVO_RETURN_IF_ERROR(vertical->validate());
  if (!(std::abs(true_up_pitch_deg) <= 30.0 && std::abs(true_up_roll_deg) <= 30.0)) {
    return invalidArgument(
        "experiment.true_up_pitch_deg / true_up_roll_deg out of range [-30, 30]");
  }
  if (!(std::abs(start_pitch_error_deg) <= 30.0 && std::abs(start_roll_error_deg) <= 30.0)) {
    return invalidArgument(
        "experiment.start_pitch_error_deg / start_roll_error_deg out of range [-30, 30]");
  }
  return Status::ok();
}

Isometry3 withStartTiltError(const Isometry3& T_w_c0, double pitch_deg, double roll_deg) {
  Isometry3 T = T_w_c0;
  T.linear() = T_w_c0.linear() * expSO3(Eigen::Vector3d(pitch_deg, 0.0, roll_deg) * (M_PI / 180.0));
  return T;
}

Expected<RunResult> runRoute(const Route& route, const std::optional<SunSourceSpec>& spec,
                             const ExperimentOptions& options, const FrameObserver& observer) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::size_t n = route.frames.size();
  if (options.max_frames > 0) n = std::min(n, static_cast<std::size_t>(options.max_frames));
  if (n < 2 || route.T_w_c_gt.size() < n || route.sun_c_gt.size() < n || route.sun_w.size() < n) {
    return invalidArgument("experiment: route '" + route.name +
                           "' needs >= 2 frames with ground truth and sun for each");
  }
  pipeline::SunAidedOptions sao;
  sao.pipeline.vo = options.vo;
  sao.use_sun = spec.has_value();
  sao.every_n_frames = options.every_n_frames;
  sao.pipeline.self_calibration = options.self_calibration;
  sao.fusion = options.fusion;
  sao.fusion.world_up = route.world_up;
  std::optional<sunfusion::SimulatedSunSource> source;
  if (spec) {
    sao.fusion.gate = spec->gate;
    SUNVO_RETURN_IF_ERROR(spec->model.validate());
    source.emplace(spec->model);
  }
  const double kRad = M_PI / 180.0;
  const Eigen::Vector3d true_up_w = trueUpWorld(route, options);
  std::optional<sunfusion::SimulatedVerticalSource> vertical;
  if (options.vertical) {
    sao.vertical.enabled = true;
    vertical.emplace(*options.vertical);
  }
  const Isometry3 T_w_c0 = withStartTiltError(route.T_w_c_gt[0], options.start_pitch_error_deg,
                                              options.start_roll_error_deg);
  pipeline::SunAidedOdometry odometry;
  SUNVO_RETURN_IF_ERROR(
      odometry.init(sao, route.camera, T_w_c0, pipeline::OdometryInput::kFeatures));

  RunResult result;
  result.name = spec ? spec->name : "Pure VO";
  if (vertical) result.name = spec ? result.name + " +vertical-like" : "VO+vertical-like";
  result.T_w_c.reserve(n);
  std::vector<double> ms;
  ms.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const FrameFeatures& frame = route.frames[k];
    if (source && odometry.isSunFrame(frame.sequence)) {
      auto m = source->measure(frame.sequence, frame.time_ns, route.sun_c_gt[k]);
      if (m) odometry.addSun({*m, route.sun_w[k]});
    }
    if (vertical && odometry.isCueFrame(frame.sequence)) {
      const Eigen::Vector3d up_c = route.T_w_c_gt[k].linear().transpose() * true_up_w;
      auto m = vertical->measure(frame.sequence, frame.time_ns, up_c);
      if (m) odometry.addVertical({*m, route.world_up});
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto r = odometry.process(frame);
    const auto t1 = std::chrono::steady_clock::now();
    if (!r) return r.status();
    if (r->status == vo::TrackingStatus::kLost) ++result.lost_frames;
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    result.T_w_c.push_back(r->T_w_c);
    if (observer) observer(k, odometry);
  }
  result.gate = odometry.sunCounters();
  result.vertical_gate = odometry.verticalCounters();
  result.world_up_answers = odometry.sunTerm().worldUpAlignment().used();
  result.world_up_error_deg = angleBetween(odometry.worldUp(), true_up_w) / kRad;
  result.start_tilt_judged = odometry.sunTerm().startTiltJudged();
  result.start_levelled = odometry.sunTerm().startLevelled();
  if (result.start_tilt_judged)
    result.start_tilt_deg = odometry.sunTerm().worldUpAlignment().tiltDeg();
  result.selfcal_pitch_mrad = odometry.lastSelfCalibration().pitch_mrad;
  result.selfcal_roll_mrad = odometry.lastSelfCalibration().roll_mrad;
  result.selfcal_resets = odometry.lastSelfCalibration().resets;
  result.median_ms = metrics::percentile(ms, 0.5);
  result.p99_ms = metrics::percentile(ms, 0.99);
  const std::vector<Isometry3> gt(route.T_w_c_gt.begin(),
                                  route.T_w_c_gt.begin() + static_cast<std::ptrdiff_t>(n));
  metrics::EvaluationOptions eval_opt;
  eval_opt.plane = metrics::HorizontalPlane::kCameraXZ;
  auto ev = metrics::evaluate(gt, result.T_w_c, eval_opt);
  if (!ev) return ev.status();
  result.evaluation = *ev;
  auto tilt = metrics::computeTilt(gt, result.T_w_c, true_up_w);
  if (!tilt) return tilt.status();
  result.tilt = *tilt;
  return result;
}

Eigen::Vector3d trueUpWorld(const Route& route, const ExperimentOptions& options) {
  const double kRad = M_PI / 180.0;
  return Eigen::AngleAxisd(options.true_up_roll_deg * kRad, Eigen::Vector3d::UnitZ()) *
         (Eigen::AngleAxisd(options.true_up_pitch_deg * kRad, Eigen::Vector3d::UnitX()) *
          route.world_up);
}

std::vector<SunSourceSpec> defaultSunSources(std::uint32_t seed) {
  std::vector<SunSourceSpec> specs;
  {
    SunSourceSpec s;
    s.name = "VO+Sun (true vector)";
    s.model.azimuth_sigma_deg = 0.0;
    s.model.zenith_sigma_deg = 0.0;
    s.model.reported_sigma = 0.05;
    s.model.seed = seed;
    specs.push_back(s);
  }
  {
    SunSourceSpec s;  // hand-crafted cues: broad errors, shadow flips, skewed zenith
    s.name = "VO+Sun (Lalonde-like)";
    s.model.azimuth_sigma_deg = 20.0;
    s.model.zenith_sigma_deg = 10.0;
    s.model.zenith_bias_deg = 8.0;
    s.model.flip_share = 0.2;
    s.model.outlier_share = 0.2;
    s.model.reported_sigma = 0.35;
    s.model.seed = seed + 1;
    s.gate.max_vertical_error = 0.2;
    specs.push_back(s);
  }
  {
    SunSourceSpec s;  // the VO prior resolves most flips and gross errors
    s.name = "VO+Sun (Lalonde-VO-like)";
    s.model.azimuth_sigma_deg = 15.0;
    s.model.zenith_sigma_deg = 8.0;
    s.model.zenith_bias_deg = 4.0;
    s.model.flip_share = 0.05;
    s.model.outlier_share = 0.1;
    s.model.reported_sigma = 0.3;
    s.model.seed = seed + 2;
    s.gate.max_vertical_error = 0.2;
    specs.push_back(s);
  }
  {
    SunSourceSpec s;  // azimuth only
    s.name = "VO+Sun (Sun-CNN-like)";
    s.model.azimuth_only = true;
    s.model.azimuth_sigma_deg = 12.0;
    s.model.outlier_share = 0.1;
    s.model.reported_sigma = 0.25;
    s.model.seed = seed + 3;
    s.gate.plane = sunfusion::GatePlane::kXZ;
    specs.push_back(s);
  }
  return specs;
}

Expected<Route> loadRoute(const std::string& spec, const std::string& data_dir,
                          const SimulatedRouteOptions& options) {
  dataset::DatasetOptions dopt;
  std::string name;
  if (spec == "0020") {
    dopt.path = data_dir + "/kitti_tracks/2011_09_30_drive_0020";
    dopt.sun_csv = data_dir + "/kitti_odometry/06_sun_cam.csv";
    name = "2011_09_30_drive_0020";
  } else if (const auto drive = dataset::kittiOdometryDrive(spec)) {
    dopt.path = data_dir + "/kitti_odometry/" + spec;
    name = spec + " = " + *drive;
  } else {
    dopt.path = spec;
  }
  auto ds = dataset::Dataset::open(dopt);
  if (!ds) return ds.status();
  if (name.empty()) name = ds->name();
  if (!ds->hasGroundTruth()) return notFound(dopt.path + ": the experiment needs ground truth");
  if (!ds->sunKnown()) {
    return notFound(dopt.path + ": the experiment needs the true sun: " + ds->sunUnknownReason());
  }
  Route route;
  route.source = ds->describe();
  route.camera = ds->camera();
  route.T_w_c_gt = ds->groundTruth();
  route.times_ns = ds->timesNs();
  route.world_up = ds->worldUp();
  for (const dataset::TrueSun& s : ds->trueSun()) {
    route.sun_c_gt.push_back(s.sun_c);
    route.sun_w.push_back(s.sun_w);
  }
  if (ds->hasFeatures()) {
    route.name = name + " (real tracks)";
    route.frames = ds->features();
    return route;
  }
  simtracks::SimTrackOptions sim;
  sim.seed = options.seed;
  sim.pixel_noise_px = options.pixel_noise_px;
  sim.outlier_share = options.outlier_share;
  auto frames = simtracks::simulateTracks(route.T_w_c_gt, ds->timesNs(), route.camera, sim);
  if (!frames) return frames.status();
  route.name = name + " (simulated tracks)";
  route.frames = std::move(*frames);
  return route;
}

}  // namespace sunvo::experiment
