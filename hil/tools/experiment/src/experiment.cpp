#include "sunvo/experiment/experiment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/simtracks/simulated_tracks.hpp"

namespace sunvo::experiment {
namespace {

// The first camera frame of KITTI is level to within a few degrees: up is its -y axis.
const Eigen::Vector3d kCameraWorldUp(0.0, -1.0, 0.0);

}  // namespace

Status ExperimentOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(vo.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("experiment.every_n_frames out of range [1, 1000]");
  }
  if (max_frames < 0) return invalidArgument("experiment.max_frames must be >= 0");
  return Status::ok();
}

Expected<RunResult> runRoute(const Route& route, const std::optional<SunSourceSpec>& spec,
                             const ExperimentOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::size_t n = route.frames.size();
  if (options.max_frames > 0) n = std::min(n, static_cast<std::size_t>(options.max_frames));
  if (n < 2 || route.T_w_c_gt.size() < n || route.sun_c_gt.size() < n) {
    return invalidArgument("experiment: route '" + route.name +
                           "' needs >= 2 frames with ground truth and sun for each");
  }
  vo::StereoOdometry odometry;
  SUNVO_RETURN_IF_ERROR(odometry.init(options.vo, route.camera, route.T_w_c_gt[0]));
  sunfusion::SunWindowTerm sun_term;
  std::optional<sunfusion::SimulatedSunSource> source;
  if (spec) {
    sunfusion::SunFusionOptions fusion = options.fusion;
    fusion.gate = spec->gate;
    fusion.world_up = kCameraWorldUp;
    SUNVO_RETURN_IF_ERROR(spec->model.validate());
    SUNVO_RETURN_IF_ERROR(sun_term.init(fusion));
    sun_term.attach(odometry.window());
    source.emplace(spec->model);
  }

  RunResult result;
  result.name = spec ? spec->name : "Pure VO";
  result.T_w_c.reserve(n);
  std::vector<double> ms;
  ms.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const FrameFeatures& frame = route.frames[k];
    if (source && k > 0 && k % static_cast<std::size_t>(options.every_n_frames) == 0) {
      auto m = source->measure(frame.sequence, frame.time_ns, route.sun_c_gt[k]);
      if (m) {
        sunfusion::SunObservation obs;
        obs.measurement = *m;
        obs.sun_w = (route.T_w_c_gt[k].linear() * route.sun_c_gt[k]).normalized();
        sun_term.addObservation(obs);
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto r = odometry.process(frame);
    const auto t1 = std::chrono::steady_clock::now();
    if (!r) return r.status();
    if (r->status == vo::TrackingStatus::kLost) ++result.lost_frames;
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    result.T_w_c.push_back(r->T_w_c);
  }
  result.gate = sun_term.counters();
  result.median_ms = metrics::percentile(ms, 0.5);
  result.p99_ms = metrics::percentile(ms, 0.99);
  const std::vector<Isometry3> gt(route.T_w_c_gt.begin(),
                                  route.T_w_c_gt.begin() + static_cast<std::ptrdiff_t>(n));
  metrics::EvaluationOptions eval_opt;
  eval_opt.plane = metrics::HorizontalPlane::kCameraXZ;
  auto ev = metrics::evaluate(gt, result.T_w_c, eval_opt);
  if (!ev) return ev.status();
  result.evaluation = *ev;
  return result;
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

Expected<Route> loadRealTrackRoute0020(const std::string& data_dir) {
  const std::string dir = data_dir + "/kitti_tracks/2011_09_30_drive_0020";
  auto seq = files::readTrackFolder(dir, files::TrackReadOptions{});
  if (!seq) return seq.status();
  if (seq->gt_T_0_k.size() != seq->frames.size()) {
    return notFound(dir + "/gt_poses.txt: ground truth required for the experiment");
  }
  auto sun = files::readSunCsv(data_dir + "/kitti_odometry/06_sun_cam.csv");
  if (!sun) return sun.status();
  if (sun->sun_c.size() < seq->frames.size()) {
    return invalidArgument("06_sun_cam.csv has fewer rows than the 0020 tracks have frames");
  }
  Route route;
  route.name = "2011_09_30_drive_0020 (real tracks)";
  route.camera = seq->camera;
  route.frames = std::move(seq->frames);
  route.T_w_c_gt = std::move(seq->gt_T_0_k);
  route.sun_c_gt.assign(sun->sun_c.begin(),
                        sun->sun_c.begin() + static_cast<std::ptrdiff_t>(route.frames.size()));
  return route;
}

Expected<Route> loadSimulatedKittiRoute(const std::string& data_dir, const std::string& seq,
                                        const SimulatedRouteOptions& options) {
  StereoCamera camera;
  std::string drive;
  if (seq == "00") {
    auto calib =
        kitti::readOdometryCalibration(data_dir + "/kitti_odometry/00_first_frames/calib.txt");
    if (!calib) return calib.status();
    auto cam = kitti::odometryStereoCamera(*calib, 0, 1, 1241, 376);
    if (!cam) return cam.status();
    camera = *cam;
    drive = "2011_10_03_drive_0027";
  } else if (seq == "06") {
    // Sequence 06 is raw drive 2011_09_30_drive_0020: the track folder holds its calibration.
    auto file = files::TextFile::open(data_dir + "/kitti_tracks/2011_09_30_drive_0020/calib.txt");
    if (!file) return file.status();
    auto cam = files::parseTrackCalib(*file, 1226, 370);
    if (!cam) return cam.status();
    camera = *cam;
    drive = "2011_09_30_drive_0020";
  } else {
    return invalidArgument("experiment: unknown simulated route '" + seq + "' (00 or 06)");
  }
  const std::string base = data_dir + "/kitti_odometry/" + seq;
  auto gt = files::loadTrajectory(base + "_gt_poses.txt", base + "_times.txt");
  if (!gt) return gt.status();
  auto sun = files::readSunCsv(base + "_sun_cam.csv");
  if (!sun) return sun.status();
  if (sun->sun_c.size() != gt->size()) {
    return invalidArgument(base + "_sun_cam.csv: row count differs from the ground truth");
  }
  simtracks::SimTrackOptions sim;
  sim.seed = options.seed;
  sim.pixel_noise_px = options.pixel_noise_px;
  sim.outlier_share = options.outlier_share;
  auto frames = simtracks::simulateTracks(gt->T_w_c, gt->t_ns, camera, sim);
  if (!frames) return frames.status();
  Route route;
  route.name = seq + " = " + drive + " (simulated tracks)";
  route.camera = camera;
  route.frames = std::move(*frames);
  route.T_w_c_gt = gt->T_w_c;
  route.sun_c_gt = sun->sun_c;
  return route;
}

}  // namespace sunvo::experiment
