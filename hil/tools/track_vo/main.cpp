// sunvo_track_vo: runs StereoOdometry over a feature-track folder (tracks.csv, calib.txt,
// times.txt, optional gt_poses.txt), writes the estimated camera poses relative to frame 0 as a
// KITTI pose file, and prints timing and a minimal accuracy summary against gt_poses.txt.
//
// Usage: sunvo_track_vo <track_folder> <out_poses.txt> [--frames N] [--window N] [--no-window]
//          [--sigma-uv px] [--sigma-d px] [--loss none|huber|cauchy] [--loss-scale s]
//          [--ransac-thr px] [--ransac-iters n] [--min-inliers n] [--max-iters n]
//          [--max-time s] [--min-disparity px] [--seed n] [--prior-rot-deg s] [--prior-trans-m s]
//          [--log per_frame.csv] [--self-calib] [--self-calib-log per_frame.csv]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sunvo/dataset/track_folder.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/selfcal/stereo_self_calibration.hpp"
#include "sunvo/vo/stereo_odometry.hpp"

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

int usage(const char* msg) {
  std::fprintf(stderr, "sunvo_track_vo: %s\n", msg);
  std::fprintf(stderr,
               "usage: sunvo_track_vo <track_folder> <out_poses.txt> [--frames N] [--window N] "
               "[--no-window] [--sigma-uv px] [--sigma-d px] [--loss none|huber|cauchy] "
               "[--loss-scale s] [--ransac-thr px] [--ransac-iters n] [--min-inliers n] "
               "[--max-iters n] [--max-time s] [--min-disparity px] [--seed n] [--prior-rot-deg s] "
               "[--prior-trans-m s] [--log per_frame.csv] [--self-calib] "
               "[--self-calib-log per_frame.csv]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage("missing arguments");
  const std::string folder = argv[1];
  const std::string out_path = argv[2];
  sunvo::vo::VoOptions opt;
  long max_frames = -1;
  std::string log_path;
  sunvo::selfcal::StereoSelfCalibrationOptions selfcal_opt;  // issue 15: off unless --self-calib
  std::string selfcal_log_path;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](double& v) {
      if (i + 1 >= argc) return false;
      char* end = nullptr;
      v = std::strtod(argv[++i], &end);
      return end != nullptr && *end == '\0';
    };
    double v = 0.0;
    if (a == "--log") {
      if (i + 1 >= argc) return usage("--log needs a path");
      log_path = argv[++i];
    } else if (a == "--self-calib") {
      selfcal_opt.enabled = true;
    } else if (a == "--self-calib-log") {
      if (i + 1 >= argc) return usage("--self-calib-log needs a path");
      selfcal_log_path = argv[++i];
    } else if (a == "--no-window") {
      opt.use_window = false;
    } else if (a == "--loss") {
      if (i + 1 >= argc) return usage("--loss needs a value");
      const std::string l = argv[++i];
      if (l == "none")
        opt.window.loss = sunvo::backend::RobustLoss::kNone;
      else if (l == "huber")
        opt.window.loss = sunvo::backend::RobustLoss::kHuber;
      else if (l == "cauchy")
        opt.window.loss = sunvo::backend::RobustLoss::kCauchy;
      else
        return usage("--loss must be none, huber or cauchy");
    } else if (!next(v)) {
      return usage(("bad or missing value for " + a).c_str());
    } else if (a == "--frames") {
      max_frames = static_cast<long>(v);
    } else if (a == "--window") {
      opt.window.window_size = static_cast<int>(v);
    } else if (a == "--sigma-uv") {
      opt.window.sigma_u_px = opt.window.sigma_v_px = v;
    } else if (a == "--sigma-d") {
      opt.window.sigma_d_px = v;
    } else if (a == "--loss-scale") {
      opt.window.loss_scale = v;
    } else if (a == "--ransac-thr") {
      opt.ransac.inlier_threshold_px = v;
    } else if (a == "--ransac-iters") {
      opt.ransac.max_iterations = static_cast<int>(v);
    } else if (a == "--min-inliers") {
      opt.ransac.min_inliers = static_cast<int>(v);
    } else if (a == "--max-iters") {
      opt.window.max_num_iterations = static_cast<int>(v);
    } else if (a == "--max-time") {
      opt.window.max_solver_time_in_seconds = v;
    } else if (a == "--min-disparity") {
      opt.ransac.min_disparity_px = opt.window.min_disparity_px = v;
    } else if (a == "--prior-rot-deg") {
      opt.window.motion_prior_sigma_rot_deg = v;
    } else if (a == "--prior-trans-m") {
      opt.window.motion_prior_sigma_trans_m = v;
    } else if (a == "--seed") {
      opt.seed = static_cast<std::uint64_t>(v);
    } else {
      return usage(("unknown option " + a).c_str());
    }
  }
  if (auto s = opt.validate(); !s.isOk()) return usage(s.toString().c_str());

  static constexpr const char* kLoss[] = {"none", "huber", "cauchy"};
  std::printf(
      "options: window %d%s, ransac thr %.2f px iters %d min_inliers %d, sigma u/v/d "
      "%.2f/%.2f/%.2f px, loss %s scale %.2f, solver max_iter %d max_time %.3f s, "
      "min_disparity %.2f px, motion prior %.3f deg / %.3f m, seed %llu\n",
      opt.window.window_size, opt.use_window ? "" : " (disabled)", opt.ransac.inlier_threshold_px,
      opt.ransac.max_iterations, opt.ransac.min_inliers, opt.window.sigma_u_px,
      opt.window.sigma_v_px, opt.window.sigma_d_px, kLoss[static_cast<int>(opt.window.loss)],
      opt.window.loss_scale, opt.window.max_num_iterations, opt.window.max_solver_time_in_seconds,
      opt.ransac.min_disparity_px, opt.window.motion_prior_sigma_rot_deg,
      opt.window.motion_prior_sigma_trans_m, static_cast<unsigned long long>(opt.seed));
  auto seq = sunvo::dataset::readTrackFolder(folder, sunvo::files::TrackReadOptions{});
  if (!seq) {
    std::fprintf(stderr, "sunvo_track_vo: %s\n", seq.status().toString().c_str());
    return 1;
  }
  std::printf(
      "tracks: image %dx%d from %s; %zu observations dropped past the border (max %.3f px)\n",
      seq->camera.width, seq->camera.height, seq->image_size_source.c_str(),
      seq->dropped_past_border, seq->max_outside_px);
  std::size_t n = seq->frames.size();
  if (max_frames > 0) n = std::min(n, static_cast<std::size_t>(max_frames));

  sunvo::vo::StereoOdometry vo;
  if (auto s = vo.init(opt, seq->camera, Isometry3::Identity()); !s.isOk()) {
    std::fprintf(stderr, "sunvo_track_vo: %s\n", s.toString().c_str());
    return 1;
  }
  sunvo::selfcal::StereoSelfCalibration selfcal;
  if (auto s = selfcal.init(selfcal_opt, seq->camera); !s.isOk())
    return usage(s.toString().c_str());
  sunvo::FrameFeatures corrected;
  std::FILE* selfcal_log =
      selfcal_log_path.empty() ? nullptr : std::fopen(selfcal_log_path.c_str(), "w");
  if (selfcal_log != nullptr) {
    std::fprintf(selfcal_log, "frame,pitch_mrad,roll_mrad,scale,roll_sigma_mrad,used,reset\n");
  }
  std::vector<double> selfcal_ms;
  std::vector<Isometry3> poses;
  poses.reserve(n);
  std::FILE* log = log_path.empty() ? nullptr : std::fopen(log_path.c_str(), "w");
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
    const sunvo::FrameFeatures* frame = &seq->frames[k];
    if (selfcal.enabled()) {
      const auto rep = selfcal.process(*frame, &corrected);
      frame = &corrected;
      selfcal_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (selfcal_log != nullptr) {
        std::fprintf(selfcal_log, "%zu,%.5f,%.5f,%.7f,%.5f,%d,%d\n", k, rep.pitch_mrad,
                     rep.roll_mrad, rep.scale, rep.roll_sigma_mrad, rep.used, rep.reset ? 1 : 0);
      }
    }
    auto r = vo.process(*frame);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      std::fprintf(stderr, "sunvo_track_vo: frame %zu: %s\n", k, r.status().toString().c_str());
      return 1;
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
  if (selfcal.enabled()) {
    std::printf(
        "self-calibration: right camera pitch %.4f mrad, roll %.4f mrad, vertical scale "
        "%.6f at the end; %llu resets; %.4f ms/frame median\n",
        selfcal.state()[0] * 1e3, selfcal.state()[1] * 1e3, selfcal.state()[2],
        static_cast<unsigned long long>(selfcal.resets()), percentile(selfcal_ms, 50));
  }
  sunvo::files::Trajectory out_traj;
  out_traj.T_w_c = poses;
  for (std::size_t k = 0; k < poses.size(); ++k) out_traj.t_ns.push_back(seq->frames[k].time_ns);
  if (auto s = sunvo::files::writeKittiPoses(out_path, out_traj); !s.isOk()) {
    std::fprintf(stderr, "sunvo_track_vo: %s\n", s.toString().c_str());
    return 1;
  }
  std::printf(
      "frames %zu  lost %d  recovered %d  window fallbacks %d  mean solver iterations %.2f\n", n,
      lost, recovered, window_fallbacks,
      n > 1 ? static_cast<double>(iterations) / static_cast<double>(n - 1) : 0.0);
  auto timing = [](const char* name, const std::vector<double>& v) {
    std::printf("timing %-8s ms/frame: median %.3f  p95 %.3f  p99 %.3f  max %.3f\n", name,
                percentile(v, 50), percentile(v, 95), percentile(v, 99), percentile(v, 100));
  };
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
