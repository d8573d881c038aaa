// sunvo_track_stats: the error of a stereo feature-track folder against its ground truth (motion
// residuals per frame, the left/right vertical offset plane, disparity error vs depth,
// conditioning, the frames where the error jumps); see track_stats.hpp. --help lists the options.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/dataset/track_folder.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/track_stats/track_stats.hpp"
#include "sunvo/track_stats/window_bias.hpp"

namespace {
constexpr const char* kProgram = "sunvo_track_stats";
using sunvo::track_stats::FrameStats;

// p-quantile (0..1) of v by nearest rank.
double quantile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

void printDistribution(const char* name, const std::vector<double>& v, double scale = 1.0,
                       const char* unit = "px") {
  double m = 0.0;
  for (double x : v) m += x;
  m = v.empty() ? 0.0 : m / static_cast<double>(v.size());
  std::printf("  %-34s mean %+.4f  median %+.4f  p5 %+.4f  p95 %+.4f %s\n", name, m * scale,
              quantile(v, 0.5) * scale, quantile(v, 0.05) * scale, quantile(v, 0.95) * scale, unit);
}
bool oneSided(const FrameStats& f) {
  return f.tracks > 0 && (f.left_share < 0.15 || f.left_share > 0.85);
}

// The window's first-order rotation error at the true motion, summed over the one-sided frames
// and the others (window_bias.hpp), and how well it predicts the estimate's per-frame roll error.
void printWindowBias(const sunvo::track_stats::WindowBias& bias, const std::vector<FrameStats>& fs,
                     bool have_estimate) {
  const auto& wb = bias.frames;
  std::printf(
      "\nmotion residuals as a radial distortion of every image + a + c/z per axis: k1 %+.5f, a_u "
      "%+.3f "
      "px, c_u %+.3f px m, a_v %+.3f px, c_v %+.3f px m; rms %.4f -> %.4f px; injected k1 "
      "%+.5f\n",
      bias.fit_k1, bias.fit_a_u_px, bias.fit_c_u_pxm, bias.fit_a_v_px, bias.fit_c_v_pxm,
      bias.rms_before_px, bias.rms_after_px, bias.k1_used);
  std::printf("\nmotion residual under the true motion by uL column in k-1 (du / dv px, pairs):\n");
  for (const auto& c : bias.columns) {
    std::printf("  u %4.0f-%4.0f: %+.3f / %+.3f (%zu)\n", c.u_min, c.u_max, c.mean_du, c.mean_dv,
                c.n);
  }
  using sunvo::track_stats::FrameWindowBias;
  using V = Eigen::Vector3d;
  struct Term {
    const char* name;
    V FrameWindowBias::*field;
  };
  const Term terms[] = {{"all residuals", &FrameWindowBias::total},
                        {"  of it u rows", &FrameWindowBias::from_u},
                        {"  of it v rows", &FrameWindowBias::from_v},
                        {"  of it d rows", &FrameWindowBias::from_d},
                        {"injected vL shift alone", &FrameWindowBias::inject_v},
                        {"injected vL shift c/z alone", &FrameWindowBias::inject_v_z},
                        {"injected disparity bias alone", &FrameWindowBias::inject_d},
                        {"injected radial distortion alone", &FrameWindowBias::inject_k1}};
  std::printf(
      "\nwindow at the true motion (window_bias.hpp): one-step rotation error summed, deg "
      "(x pitch, y yaw, z roll)\n  %-31s %-26s %-26s\n",
      "", "one-sided frames", "the others");
  for (const Term& t : terms) {
    V one = V::Zero(), bal = V::Zero();
    for (std::size_t k = 1; k < wb.size(); ++k) (oneSided(fs[k]) ? one : bal) += wb[k].*t.field;
    std::printf("  %-31s %+7.2f %+7.2f %+7.2f    %+7.2f %+7.2f %+7.2f\n", t.name, one.x() * 1e-3,
                one.y() * 1e-3, one.z() * 1e-3, bal.x() * 1e-3, bal.y() * 1e-3, bal.z() * 1e-3);
  }
  {
    double pr = 0.0, pl = 0.0, er = 0.0, el = 0.0;
    int nr = 0, nl = 0;
    for (std::size_t k = 1; k < wb.size(); ++k) {
      if (!oneSided(fs[k])) continue;
      const bool right = fs[k].left_share < 0.15;
      (right ? pr : pl) += wb[k].total.z();
      (right ? er : el) += fs[k].rot_err_c_mdeg.z();
      ++(right ? nr : nl);
    }
    std::printf(
        "  roll, all residuals: tracks right of cu (%d frames) %+.2f deg, left of cu (%d) %+.2f "
        "deg",
        nr, pr * 1e-3, nl, pl * 1e-3);
    if (have_estimate) std::printf("; the estimate's: %+.2f and %+.2f deg", er * 1e-3, el * 1e-3);
    std::printf("\n");
  }
  std::vector<double> s_one, s_bal;
  for (std::size_t k = 1; k < wb.size(); ++k) {
    if (wb[k].landmarks == 0) continue;
    (oneSided(fs[k]) ? s_one : s_bal).push_back(wb[k].sigma_mdeg.z());
  }
  std::printf(
      "  marginal roll std (1 px noise): one-sided median %.1f mdeg p95 %.1f; others median "
      "%.1f p95 %.1f\n",
      quantile(s_one, 0.5), quantile(s_one, 0.95), quantile(s_bal, 0.5), quantile(s_bal, 0.95));
  if (!have_estimate) return;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t k = 1; k < wb.size(); ++k) {
    const double x = wb[k].total.z(), y = fs[k].rot_err_c_mdeg.z();
    sxy += x * y;
    sxx += x * x;
    syy += y * y;
  }
  std::printf(
      "  estimate's per-frame roll error vs the predicted one: correlation (uncentred) %.3f, "
      "slope %.3f\n",
      sxy / std::sqrt(sxx * syy + 1e-30), sxy / (sxx + 1e-30));
}
}  // namespace

int main(int argc, char** argv) {
  std::string folder, estimate_path, csv_path, gt_path;
  int image_width = 0, image_height = 0, max_jumps = 40;
  sunvo::track_stats::TrackStatsOptions opt;
  CLI::App app{"The error of stereo feature tracks against ground-truth poses.", kProgram};
  app.add_option("folder", folder, "track folder (calib.txt, times.txt, tracks.csv, gt_poses.txt)")
      ->required();
  app.add_option("--gt", gt_path, "ground-truth poses (KITTI or TUM) instead of gt_poses.txt");
  app.add_option("--estimate", estimate_path,
                 "estimated poses (KITTI, one per frame, e.g. sunvo_track_vo's output): per-frame "
                 "rotation error and its jumps");
  app.add_option("--csv", csv_path, "write the per-frame statistics to this CSV file");
  app.add_option("--image-width", image_width, "px; 0 = from the data")
      ->check(CLI::Range(0, 16384));
  app.add_option("--image-height", image_height, "px; 0 = from the data")
      ->check(CLI::Range(0, 16384));
  app.add_option("--block-frames", opt.block_frames, "frames per block of the plane fits")
      ->check(CLI::Range(10, 100000));
  app.add_option("--min-parallax-deg", opt.min_parallax_deg,
                 "ray span of the monocular triangulation, deg")
      ->check(CLI::Range(0.01, 89.0));
  app.add_option("--jump-sigmas", opt.jump_sigmas, "robust sigmas of a residual jump")
      ->check(CLI::Range(0.1, 100.0));
  app.add_option("--jump-min-px", opt.jump_min_px, "and at least this far from the median, px")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--jump-rotation-mdeg", opt.jump_rotation_mdeg,
                 "per-frame rotation error of a jump, mdeg")
      ->check(CLI::Range(0.001, 1e6));
  app.add_option("--max-jumps", max_jumps, "jumps listed")->check(CLI::Range(0, 100000));
  bool window_bias = false;
  sunvo::track_stats::WindowBiasOptions wbo;
  app.add_flag("--window-bias", window_bias,
               "the two-frame window's first-order rotation error at the true motion, by "
               "measurement and for injected error fields (window_bias.hpp)");
  std::string window_bias_csv;
  app.add_option("--window-bias-csv", window_bias_csv,
                 "per-frame CSV of --window-bias (rotation errors in mdeg, camera k)");
  app.add_option("--inject-v-px", wbo.inject_v_px, "injected constant vL shift, px");
  app.add_option("--inject-v-z-pxm", wbo.inject_v_z_pxm, "injected vL shift c / z, px m");
  app.add_option("--inject-d-px", wbo.inject_d_px, "injected disparity bias, px");
  app.add_option("--inject-k1", wbo.inject_k1,
                 "injected radial distortion k1 (0 = the one fitted to the motion residuals)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;

  sunvo::files::TrackReadOptions tro;
  tro.image_width = image_width;
  tro.image_height = image_height;
  auto seq = sunvo::dataset::readTrackFolder(folder, tro);
  if (!seq) return sunvo::cli::fail(kProgram, seq.status());
  if (!gt_path.empty()) {
    auto gt = sunvo::files::loadTrajectory(gt_path);
    if (!gt) return sunvo::cli::fail(kProgram, gt.status());
    seq->gt_T_0_k = gt->T_w_c;
  }
  if (seq->gt_T_0_k.empty()) return sunvo::cli::fail(kProgram, folder + ": no ground truth");
  std::vector<sunvo::Isometry3> estimate;
  if (!estimate_path.empty()) {
    auto e = sunvo::files::loadTrajectory(estimate_path);
    if (!e) return sunvo::cli::fail(kProgram, e.status());
    estimate = e->T_w_c;
  }
  const sunvo::StereoCamera& cam = seq->camera;
  auto stats =
      sunvo::track_stats::computeTrackStats(cam, seq->frames, seq->gt_T_0_k, estimate, opt);
  if (!stats) return sunvo::cli::fail(kProgram, stats.status());

  std::printf(
      "tracks %s: %zu frames, image %dx%d from %s, %zu observations dropped past the "
      "border; fu %.3f cu %.3f cv %.3f b %.4f m\n",
      folder.c_str(), seq->frames.size(), cam.width, cam.height, seq->image_size_source.c_str(),
      seq->dropped_past_border, cam.fu, cam.cu, cam.cv, cam.baseline_m);
  std::vector<double> tracks, pairs, left, cells, mdu, mdv, medu, medv, mdd, offs;
  int few = 0, one_sided = 0, narrow = 0;
  for (std::size_t k = 0; k < stats->frames.size(); ++k) {
    const FrameStats& f = stats->frames[k];
    tracks.push_back(f.tracks);
    left.push_back(f.left_share);
    cells.push_back(f.cells);
    offs.push_back(f.mean_offset);
    few += f.tracks < 20;
    one_sided += f.tracks > 0 && (f.left_share < 0.15 || f.left_share > 0.85);
    narrow += f.cells <= 3;
    if (k == 0 || f.pairs == 0) continue;
    pairs.push_back(f.pairs);
    mdu.push_back(f.mean_du);
    mdv.push_back(f.mean_dv);
    medu.push_back(f.median_du);
    medv.push_back(f.median_dv);
    mdd.push_back(f.mean_dd);
  }
  std::printf("\nconditioning (per frame):\n");
  printDistribution("tracks", tracks, 1.0, "");
  printDistribution("residual pairs (seen in k-1, inlier)", pairs, 1.0, "");
  printDistribution("share of tracks left of cu", left, 1.0, "");
  printDistribution("occupied grid cells", cells, 1.0, "");
  std::printf(
      "  frames with < 20 tracks: %d; one-sided (left share < 0.15 or > 0.85): %d; "
      "<= 3 of %d cells occupied: %d\n",
      few, one_sided, opt.grid_cols * opt.grid_rows, narrow);
  std::printf(
      "\nmotion residuals under the ground-truth motion (observed - predicted, per frame):"
      "\n");
  printDistribution("mean du", mdu);
  printDistribution("mean dv", mdv);
  printDistribution("median du", medu);
  printDistribution("median dv", medv);
  printDistribution("mean d(disparity)", mdd);
  printDistribution("mean du / fu (yaw-like)", mdu, 1e3 / cam.fu, "mrad");
  printDistribution("mean dv / fv (pitch-like)", mdv, 1e3 / cam.fv, "mrad");
  printDistribution("mean vL - vR", offs);

  auto plane = [&](const sunvo::track_stats::OffsetPlane& p) {
    const double left_edge = p.a_px + p.b * (0.0 - cam.cu);
    const double right_edge = p.a_px + p.b * (cam.width - 1 - cam.cu);
    std::printf(
        "  frames %4d-%4d: vL - vR = %+.4f %+.4fe-3 (u - cu) %+.4fe-3 (v - cv) px; rms "
        "%.3f px, %zu used, %zu rejected; left edge %+.3f, right edge %+.3f px\n",
        p.first_frame, p.last_frame, p.a_px, p.b * 1e3, p.c * 1e3, p.rms_px, p.used, p.rejected,
        left_edge, right_edge);
  };
  std::printf("\nleft/right vertical offset plane (robust least squares):\n");
  plane(stats->plane);
  std::printf(
      "  read as a right-camera rotation: roll about z %.3f mrad, pitch about x %.3f mrad "
      "(a / fv), vertical scale %+.4f %%\n",
      -stats->plane.b * 1e3, stats->plane.a_px / cam.fv * 1e3, -stats->plane.c * 100.0);
  for (const auto& b : stats->blocks) plane(b);

  std::printf(
      "\ndisparity error vs depth (d - fu b / z, z from a left-only triangulation with the "
      "true poses; %zu landmarks):\n",
      stats->mono_landmarks);
  for (const auto& b : stats->depth_bins) {
    std::printf("  z [%3.0f, %3.0f) m: %6zu obs  mean %+.3f  median %+.3f px\n", b.z_min_m,
                std::min(b.z_max_m, 999.0), b.n, b.mean_px, b.median_px);
  }

  std::printf(
      "\ndisparity error vs the disparity's fractional part f = d - round(d) (same "
      "landmarks):\n");
  for (const auto& b : stats->fraction_bins) {
    std::printf("  f [%+.1f, %+.1f) px: %6zu obs  mean %+.3f  median %+.3f px\n", b.f_min, b.f_max,
                b.n, b.mean_px, b.median_px);
  }

  std::printf("\nmotion residual by stereo depth in k-1:\n");
  for (const auto& b : stats->residual_depths) {
    std::printf("  z [%3.0f, %3.0f) m: %6zu pairs  du %+.4f  dv %+.4f px\n", b.z_min_m,
                std::min(b.z_max_m, 999.0), b.n, b.mean_du, b.mean_dv);
  }
  std::printf("\nby track age (frames since the track's first observation):\n");
  for (const auto& a : stats->ages) {
    std::printf("  age %3d-%-7d %6zu pairs  du %+.4f  dv %+.4f px   %6zu obs  vL - vR %+.4f px\n",
                a.age_min, a.age_max, a.n, a.mean_du, a.mean_dv, a.n_offset, a.mean_offset);
  }
  std::printf(
      "  residual = g * true image motion + (ou, ov): g %+.5f, ou %+.4f px, ov %+.4f px "
      "(%zu pairs)\n",
      stats->flow.gain, stats->flow.offset_u_px, stats->flow.offset_v_px, stats->flow.n);

  if (!estimate.empty()) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum_jumps = Eigen::Vector3d::Zero();
    Eigen::Vector3d sum_one = Eigen::Vector3d::Zero(), sum_bal = Eigen::Vector3d::Zero();
    std::vector<double> abs_one, abs_bal;
    std::vector<double> rot;
    for (std::size_t k = 1; k < stats->frames.size(); ++k) {
      const FrameStats& f = stats->frames[k];
      sum += f.rot_err_c_mdeg;
      rot.push_back(f.rot_err_mdeg);
      if (f.rot_err_mdeg > opt.jump_rotation_mdeg) sum_jumps += f.rot_err_c_mdeg;
      const bool one = f.tracks > 0 && (f.left_share < 0.15 || f.left_share > 0.85);
      (one ? sum_one : sum_bal) += f.rot_err_c_mdeg;
      (one ? abs_one : abs_bal).push_back(f.rot_err_mdeg);
    }
    std::printf("\nestimate %s: per-frame rotation error\n", estimate_path.c_str());
    printDistribution("|rotation error|", rot, 1.0, "mdeg");
    std::printf(
        "  summed per axis (camera x pitch, y yaw, z roll): %+.1f %+.1f %+.1f deg; of it in "
        "frames over %.0f mdeg: %+.1f %+.1f %+.1f deg\n",
        sum.x() * 1e-3, sum.y() * 1e-3, sum.z() * 1e-3, opt.jump_rotation_mdeg,
        sum_jumps.x() * 1e-3, sum_jumps.y() * 1e-3, sum_jumps.z() * 1e-3);
    std::printf(
        "  one-sided frames (%zu): summed %+.1f %+.1f %+.1f deg, median |error| %.1f mdeg; "
        "the others (%zu): %+.1f %+.1f %+.1f deg, median %.1f mdeg\n",
        abs_one.size(), sum_one.x() * 1e-3, sum_one.y() * 1e-3, sum_one.z() * 1e-3,
        quantile(abs_one, 0.5), abs_bal.size(), sum_bal.x() * 1e-3, sum_bal.y() * 1e-3,
        sum_bal.z() * 1e-3, quantile(abs_bal, 0.5));
  }
  if (window_bias) {
    auto wb = sunvo::track_stats::computeWindowBias(cam, seq->frames, seq->gt_T_0_k, wbo);
    if (!wb) return sunvo::cli::fail(kProgram, wb.status());
    printWindowBias(*wb, stats->frames, !estimate.empty());
    if (!window_bias_csv.empty()) {
      std::string csv =
          "frame,landmarks,left_share,total_x,total_y,total_z,u_z,v_z,d_z,inject_v_z,"
          "inject_vz_z,inject_d_z,sigma_x,sigma_y,sigma_z,est_x,est_y,est_z\n";
      char line[512];
      for (std::size_t k = 0; k < wb->frames.size(); ++k) {
        const auto& w = wb->frames[k];
        const FrameStats& f = stats->frames[k];
        std::snprintf(line, sizeof(line),
                      "%zu,%d,%.4f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,"
                      "%.3f,%.3f,%.3f\n",
                      k, w.landmarks, f.left_share, w.total.x(), w.total.y(), w.total.z(),
                      w.from_u.z(), w.from_v.z(), w.from_d.z(), w.inject_v.z(), w.inject_v_z.z(),
                      w.inject_d.z(), w.sigma_mdeg.x(), w.sigma_mdeg.y(), w.sigma_mdeg.z(),
                      f.rot_err_c_mdeg.x(), f.rot_err_c_mdeg.y(), f.rot_err_c_mdeg.z());
        csv += line;
      }
      if (auto s = sunvo::files::writeWholeFile(window_bias_csv, csv); !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
    }
  }
  std::printf(
      "\njumps: %zu (residual: mean du or dv more than %.1f robust sigmas from the "
      "median%s)\n",
      stats->jumps.size(), opt.jump_sigmas,
      estimate.empty() ? "" : "; rotation: per-frame rotation error above the bound");
  for (std::size_t i = 0; i < stats->jumps.size() && static_cast<int>(i) < max_jumps; ++i) {
    const auto& j = stats->jumps[i];
    const FrameStats& f = stats->frames[static_cast<std::size_t>(j.frame)];
    std::printf(
        "  frame %4d %-8s tracks %3d pairs %3d left %.2f cells %2d  du %+.3f dv %+.3f px"
        "  rot err %.1f mdeg (x %+.1f y %+.1f z %+.1f)\n",
        j.frame, j.residual ? (j.rotation ? "both" : "residual") : "rotation", f.tracks, f.pairs,
        f.left_share, f.cells, f.mean_du, f.mean_dv, f.rot_err_mdeg, f.rot_err_c_mdeg.x(),
        f.rot_err_c_mdeg.y(), f.rot_err_c_mdeg.z());
  }
  if (!csv_path.empty()) {
    std::string csv =
        "frame,tracks,pairs,mean_du,mean_dv,median_du,median_dv,mean_dd,mean_offset,"
        "left_share,cells,rot_err_x_mdeg,rot_err_y_mdeg,rot_err_z_mdeg\n";
    char line[512];
    for (std::size_t k = 0; k < stats->frames.size(); ++k) {
      const FrameStats& f = stats->frames[k];
      std::snprintf(line, sizeof(line),
                    "%zu,%d,%d,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.4f,%d,%.3f,%.3f,"
                    "%.3f\n",
                    k, f.tracks, f.pairs, f.mean_du, f.mean_dv, f.median_du, f.median_dv, f.mean_dd,
                    f.mean_offset, f.left_share, f.cells, f.rot_err_c_mdeg.x(),
                    f.rot_err_c_mdeg.y(), f.rot_err_c_mdeg.z());
      csv += line;
    }
    if (auto s = sunvo::files::writeWholeFile(csv_path, csv); !s.isOk()) {
      return sunvo::cli::fail(kProgram, s);
    }
  }
  return 0;
}
