// sunvo_track_vo: pure VO (pipeline::SunAidedOdometry with the sun off, feature input) over a
// feature-track folder (tracks.csv, calib.txt, times.txt, optional gt_poses.txt). Writes the
// camera poses relative to frame 0 as KITTI and TUM pose files, and prints timing and a minimal
// accuracy summary against gt_poses.txt. Options: sunvo_track_vo --help.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/dataset/track_folder.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/selfcal/stereo_self_calibration.hpp"

namespace {

using sunvo::Isometry3;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  const double f = pos - static_cast<double>(lo);
  return v[lo] * (1.0 - f) + v[hi] * f;
}

struct Args {
  std::string folder, out_path, log_path, selfcal_log_path;
  long max_frames = -1;
};

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_track_vo";
  Args args;
  sunvo::pipeline::SunAidedOptions options;
  options.use_sun = false;
  sunvo::vo::VoOptions& opt = options.pipeline.vo;
  sunvo::backend::WindowOptions& win = opt.window;
  CLI::App app{
      "Pure stereo VO over a feature-track folder; KITTI and TUM poses out. VO assumes the KITTI "
      "car (the sideways non-holonomic row with a 0.88 m lever arm; --lateral-prior 0 for none).",
      kProgram};
  app.add_option("track_folder", args.folder, "tracks.csv, calib.txt, times.txt[, gt_poses.txt]")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("out_poses", args.out_path, "KITTI pose file to write (TUM next to it: _tum.txt)")
      ->required();
  app.add_option("--frames", args.max_frames, "first N frames (default: all)")
      ->check(CLI::Range(1L, 100000000L));
  app.add_option("--window", win.window_size, "window poses")->check(CLI::Range(2, 8));
  app.add_flag("!--no-window", opt.use_window, "RANSAC motion only (no Ceres refinement)");
  double sigma_uv = win.sigma_u_px;
  app.add_option("--sigma-uv", sigma_uv, "pixel noise of u and v, px")->check(CLI::PositiveNumber);
  app.add_option("--sigma-d", win.sigma_d_px, "disparity noise, px")->check(CLI::PositiveNumber);
  std::string loss = "huber";
  app.add_option("--loss", loss, "robust loss (default: the window's)")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}));
  app.add_option("--loss-scale", win.loss_scale, "robust loss scale");
  app.add_option("--ransac-thr", opt.ransac.inlier_threshold_px, "RANSAC inlier threshold, px");
  app.add_option("--ransac-iters", opt.ransac.max_iterations, "RANSAC iterations");
  app.add_option("--min-inliers", opt.ransac.min_inliers, "RANSAC minimum inliers");
  app.add_option("--max-iters", win.max_num_iterations, "Ceres iterations per frame");
  app.add_option("--max-time", win.max_solver_time_in_seconds, "Ceres time per frame, s");
  double min_disparity = opt.ransac.min_disparity_px;
  app.add_option("--min-disparity", min_disparity, "smallest disparity used, px");
  app.add_option("--seed", opt.seed, "RANSAC seed");
  sunvo::cli::setKittiCarVehicle(win);  // the KITTI car's lever arm (cli.hpp)
  sunvo::cli::addWindowPriorOptions(app, win);
  app.add_option("--log", args.log_path, "per-frame CSV log");
  sunvo::selfcal::StereoSelfCalibrationOptions selfcal_opt;  // issue 15: off unless --self-calib
  app.add_flag("--self-calib", selfcal_opt.enabled,
               "online stereo self-calibration of the right camera before the odometry");
  sunvo::cli::addSelfCalibrationOptions(app, selfcal_opt);
  app.add_option("--self-calib-log", args.selfcal_log_path,
                 "per-frame CSV of the self-calibration (pitch, roll, scale, resets)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (app.count("--loss") > 0) {
    win.loss = loss == "none"    ? sunvo::backend::RobustLoss::kNone
               : loss == "huber" ? sunvo::backend::RobustLoss::kHuber
                                 : sunvo::backend::RobustLoss::kCauchy;
  }
  if (app.count("--sigma-uv") > 0) win.sigma_u_px = win.sigma_v_px = sigma_uv;
  if (app.count("--min-disparity") > 0) {
    opt.ransac.min_disparity_px = win.min_disparity_px = min_disparity;
  }
  if (auto s = options.validate(); !s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.toString().c_str());
    return sunvo::cli::kExitUsage;
  }

  static constexpr const char* kLoss[] = {"none", "huber", "cauchy"};
  std::printf(
      "options: window %d%s, ransac thr %.2f px iters %d min_inliers %d, sigma u/v/d "
      "%.2f/%.2f/%.2f px, loss %s scale %.2f, solver max_iter %d max_time %.3f s, "
      "min_disparity %.2f px, motion prior %.3f deg / %.3f m / %.2f m/s^2, rate prior %s "
      "(pitch/yaw/roll %.2f/%.2f/%.2f deg/s, adapted over %d frames), non-holonomic rows "
      "lateral %.3f m/s (lever %.2f m, near %.1f m) vertical %.3f m/s (near %.1f m), mount "
      "%.2f deg, disparity bias %.3f px, seed %llu\n",
      win.window_size, opt.use_window ? "" : " (disabled)", opt.ransac.inlier_threshold_px,
      opt.ransac.max_iterations, opt.ransac.min_inliers, win.sigma_u_px, win.sigma_v_px,
      win.sigma_d_px, kLoss[static_cast<int>(win.loss)], win.loss_scale, win.max_num_iterations,
      win.max_solver_time_in_seconds, opt.ransac.min_disparity_px, win.motion_prior_sigma_rot_deg,
      win.motion_prior_sigma_trans_m, win.motion_prior_sigma_accel_m_s2,
      win.rotation_rate_prior ? "on" : "off", win.rate_prior_pitch_deg_s, win.rate_prior_yaw_deg_s,
      win.rate_prior_roll_deg_s, win.rate_prior_adapt_frames, win.lateral_prior_sigma_m_s,
      win.lateral_lever_m, win.lateral_prior_near_m, win.vertical_prior_sigma_m_s,
      win.vertical_prior_near_m, win.lateral_mount_sigma_deg, selfcal_opt.disparity_bias_px,
      static_cast<unsigned long long>(opt.seed));
  auto seq = sunvo::dataset::readTrackFolder(args.folder, sunvo::files::TrackReadOptions{});
  if (!seq) return sunvo::cli::fail(kProgram, seq.status());
  std::printf(
      "tracks: image %dx%d from %s; %zu observations dropped past the border (max %.3f "
      "px)\n",
      seq->camera.width, seq->camera.height, seq->image_size_source.c_str(),
      seq->dropped_past_border, seq->max_outside_px);
  std::size_t n = seq->frames.size();
  if (args.max_frames > 0) n = std::min(n, static_cast<std::size_t>(args.max_frames));

  options.pipeline.self_calibration = selfcal_opt;
  sunvo::pipeline::SunAidedOdometry vo;
  if (auto s = vo.init(options, seq->camera, Isometry3::Identity(),
                       sunvo::pipeline::OdometryInput::kFeatures);
      !s.isOk()) {
    return sunvo::cli::fail(kProgram, s);
  }
  std::FILE* selfcal_log =
      args.selfcal_log_path.empty() ? nullptr : std::fopen(args.selfcal_log_path.c_str(), "w");
  if (!args.selfcal_log_path.empty() && selfcal_log == nullptr) {
    return sunvo::cli::fail(kProgram, args.selfcal_log_path + ": cannot open for writing");
  }
  if (selfcal_log != nullptr) {
    std::fputs(sunvo::selfcal::kReportCsvHeader, selfcal_log);
  }
  std::vector<double> selfcal_ms;
  std::vector<Isometry3> poses;
  poses.reserve(n);
  std::FILE* log = args.log_path.empty() ? nullptr : std::fopen(args.log_path.c_str(), "w");
  if (!args.log_path.empty() && log == nullptr) {
    return sunvo::cli::fail(kProgram, args.log_path + ": cannot open for writing");
  }
  if (log != nullptr) {
    std::fprintf(log,
                 "frame,status,matches,ransac_inliers,window_landmarks,window_residuals,"
                 "solver_iterations,window_used,ransac_ms,window_ms,reference_gap\n");
  }
  std::vector<double> total_ms, ransac_ms, window_ms;
  int lost = 0, recovered = 0, window_fallbacks = 0;
  long iterations = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = vo.process(seq->frames[k]);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      return sunvo::cli::fail(kProgram,
                              "frame " + std::to_string(k) + ": " + r.status().toString());
    }
    if (selfcal_opt.enabled) {
      const sunvo::selfcal::SelfCalibrationReport& rep = vo.lastSelfCalibration();
      selfcal_ms.push_back(vo.lastSelfCalibrationMs());
      if (selfcal_log != nullptr) {
        std::fputs(sunvo::selfcal::reportCsvRow(k, rep).c_str(), selfcal_log);
      }
    }
    poses.push_back(r->T_w_c);
    if (log != nullptr) {
      std::fprintf(log, "%zu,%s,%d,%d,%d,%d,%d,%d,%.4f,%.4f,%d\n", k,
                   sunvo::vo::toString(r->status), r->num_matches, r->ransac_inliers,
                   r->window_landmarks, r->window_residuals, r->solver_iterations,
                   r->window_used ? 1 : 0, r->ransac_ms, r->window_ms, r->reference_gap);
    }
    if (k == 0) continue;
    total_ms.push_back(ms);
    ransac_ms.push_back(r->ransac_ms);
    if (opt.use_window) window_ms.push_back(r->window_ms);
    if (r->status == sunvo::vo::TrackingStatus::kLost) ++lost;
    if (r->status == sunvo::vo::TrackingStatus::kRecovered) ++recovered;
    if (r->status != sunvo::vo::TrackingStatus::kLost && opt.use_window && !r->window_used) {
      ++window_fallbacks;
    }
    iterations += r->solver_iterations;
  }
  if (log != nullptr) std::fclose(log);
  if (selfcal_log != nullptr) std::fclose(selfcal_log);
  if (selfcal_opt.enabled) {
    const sunvo::selfcal::SelfCalibrationReport& rep = vo.lastSelfCalibration();
    std::printf(
        "self-calibration: right camera pitch %.4f mrad, roll %.4f mrad, vertical scale "
        "%.6f at the end; %llu resets; %.4f ms/frame median\n",
        rep.pitch_mrad, rep.roll_mrad, rep.scale, static_cast<unsigned long long>(rep.resets),
        percentile(selfcal_ms, 50));
  }
  sunvo::files::Trajectory out_traj;
  out_traj.T_w_c = poses;
  for (std::size_t k = 0; k < poses.size(); ++k) out_traj.t_ns.push_back(seq->frames[k].time_ns);
  // out_poses names the KITTI file; the TUM file goes next to it (<base>_tum.txt).
  std::string base = args.out_path;
  if (base.size() > 4 && base.compare(base.size() - 4, 4, ".txt") == 0)
    base.resize(base.size() - 4);
  if (base + ".txt" != args.out_path) {
    return sunvo::cli::fail(kProgram, args.out_path + ": the pose file's name must end in .txt");
  }
  if (auto s = sunvo::files::writeTrajectoryFiles(base, out_traj); !s.isOk()) {
    return sunvo::cli::fail(kProgram, s);
  }
  std::printf(
      "frames %zu  lost %d  recovered %d  window fallbacks %d  mean solver iterations %.2f\n", n,
      lost, recovered, window_fallbacks,
      n > 1 ? static_cast<double>(iterations) / static_cast<double>(n - 1) : 0.0);
  auto timing = [](const char* name, const std::vector<double>& v) {
    std::printf("timing %-8s ms/frame: median %.3f  p95 %.3f  p99 %.3f  max %.3f\n", name,
                percentile(v, 50), percentile(v, 95), percentile(v, 99), percentile(v, 100));
  };
  if (opt.use_window) {
    const Eigen::Vector3d& a = vo.window().yawAxis();
    std::printf("yaw axis estimate (camera frame): %+.4f %+.4f %+.4f (%.2f deg from y)\n", a.x(),
                a.y(), a.z(), std::acos(std::min(1.0, a.y())) * 180.0 / M_PI);
  }
  timing("total", total_ms);
  timing("ransac", ransac_ms);
  if (opt.use_window) timing("window", window_ms);

  if (seq->gt_T_0_k.size() >= n && n > 1) {
    // Minimal summary (the metrics library does the full evaluation): translational ARMSE =
    // mean over frames of sqrt(|p_est - p_gt|^2 / 3); final drift |p_N - p_gt,N| in m and in % of
    // the ground-truth path length. Both trajectories start at the identity (frame 0).
    double armse = 0.0, path = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d dp = poses[k].translation() - seq->gt_T_0_k[k].translation();
      armse += std::sqrt(dp.squaredNorm() / 3.0);
      if (k > 0) {
        path += (seq->gt_T_0_k[k].translation() - seq->gt_T_0_k[k - 1].translation()).norm();
      }
    }
    armse /= static_cast<double>(n);
    const double drift = (poses[n - 1].translation() - seq->gt_T_0_k[n - 1].translation()).norm();
    const double rot_err_deg =
        sunvo::rotationAngle(poses[n - 1].linear().transpose() * seq->gt_T_0_k[n - 1].linear()) *
        180.0 / M_PI;
    std::printf(
        "minimal summary vs gt_poses.txt (not the metrics library): path %.2f m  "
        "translational ARMSE %.3f m  final drift %.3f m (%.3f %%)  final rotation error "
        "%.3f deg\n",
        path, armse, drift, 100.0 * drift / path, rot_err_deg);
  }
  return 0;
}
