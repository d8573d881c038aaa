// sunvo_vertical_eval: measures the vertical vanishing-point cue (estimator/vertical) against the
// true "up" of image sets (sunvo renders, KITTI raw or odometry folders; the sets of
// sunvo_sun_eval, read by the same loader, gray camera 0). The prior given to the estimator is
// the level camera's up, (0, -1, 0): what a rover knows before VO has run, and a test that the
// cue needs no attitude. Per set: frames, valid share, over the valid frames the median and
// 90th percentile of the angle between the estimated and true up, the median signed roll (about
// the optical axis) and pitch (about the camera's x) of that error, the share within 2 sigma,
// the median angle of the level prior itself, and CPU ms per call. One Markdown row per set on
// stdout; --csv FILE writes one line per frame; --segments-csv FILE one line per candidate segment
// of a valid frame: whether it is an inlier of the estimate, its interpretation plane's signed
// angle from the true up and from the estimate (deg: a segment that leans toward the image's
// centre at its top reads as a pitch), x0 = the plane's column at the principal row (normalised,
// (u - cu) / fu) and its end points in pixels. Exit codes: 0 done, 1 a set or image failed,
// 2 bad arguments.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "datasets.hpp"
#include "metrics.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/vertical/vertical_estimator.hpp"

namespace {
namespace se = sunvo::suneval;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr const char* kProgram = "sunvo_vertical_eval";

double cpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> sets;
  std::string csv_path, segments_path;
  int max_frames = 0, every = 1;
  sunvo::vertical::VerticalOptions options;
  CLI::App app{"Vertical vanishing point (gravity cue) against the true up, per image set.",
               kProgram};
  app.add_option("sets", sets, "image sets: DIR (a render, a KITTI raw or odometry folder)")
      ->required();
  app.add_option("--frames", max_frames, "first N frames of each set (0 = all)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--every", every, "every N-th frame")->check(CLI::Range(1, 100000));
  app.add_option("--csv", csv_path, "per-frame CSV");
  app.add_option("--segments-csv", segments_path, "per-segment CSV of the valid frames");
  app.add_option("--max-width-px", options.max_width_px,
                 "wider images are downscaled to this width first, px");
  app.add_option("--inlier-angle-deg", options.inlier_angle_deg, "inlier bound, deg");
  app.add_option("--line-sigma-deg", options.line_sigma_deg, "one segment's angle error, deg");
  app.add_option("--min-segment-rows-share", options.min_segment_rows_share,
                 "shortest segment, as a share of the image's rows");
  sunvo::cli::addEnumOption(app, "--detector", options.detector,
                            "segment detector (default edge_chains; lsd: OpenCV's)");
  app.add_option("--min-gradient", options.min_gradient,
                 "weakest edge for edge_chains, gray levels / px");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (auto s = options.validate(); !s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.toString().c_str());
    return sunvo::cli::kExitUsage;
  }
  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    if (!csv) return sunvo::cli::fail(kProgram, "cannot write '" + csv_path + "'");
    csv << "set,frame,valid,reason,candidates,inliers,error_deg,roll_deg,pitch_deg,sigma_deg,"
           "level_deg,cpu_ms,sigma_strong_deg,error_strong_deg,error_weak_deg,true_roll_deg,"
           "true_pitch_deg\n";
  }
  std::ofstream seg_csv;
  if (!segments_path.empty()) {
    seg_csv.open(segments_path);
    if (!seg_csv) return sunvo::cli::fail(kProgram, "cannot write '" + segments_path + "'");
    seg_csv << "set,frame,inlier,true_deg,est_deg,x0,length_px,ua,va,ub,vb\n";
  }
  std::printf(
      "| set | frames | valid | median error [deg] | p90 [deg] | roll / pitch median [deg] | "
      "< 2 sigma | better / worse axis: sigma median [deg], |error| < 2 sigma | level prior median "
      "[deg] | CPU ms median |\n|---|---|---|---|---|---|---|---|---|---|\n");
  const Eigen::Vector3d level(0.0, -1.0, 0.0);
  for (const std::string& dir : sets) {
    se::EvalSetOptions eo;
    eo.max_frames = max_frames;
    eo.camera = se::CameraChoice::kGray;
    auto ds = se::loadEvalDataset(dir, eo);
    if (!ds) return sunvo::cli::fail(kProgram, ds.status());
    sunvo::vertical::VerticalEstimator estimator;
    if (auto s = estimator.init(options, ds->camera); !s.isOk()) {
      return sunvo::cli::fail(kProgram, dir + ": " + s.toString());
    }
    std::vector<double> err, roll, pitch, lev, ms, sig_strong, sig_weak;
    int n = 0, within = 0, within_strong = 0, within_weak = 0;
    for (std::size_t k = 0; k < ds->frames.size(); k += static_cast<std::size_t>(every)) {
      const se::EvalFrame& f = ds->frames[k];
      const cv::Mat gray = cv::imread(f.image_path, cv::IMREAD_GRAYSCALE);
      if (gray.empty()) return sunvo::cli::fail(kProgram, f.image_path + ": cannot read image");
      const double t0 = cpuMs();
      auto m = estimator.estimate(gray, level);
      const double dt = cpuMs() - t0;
      if (!m) return sunvo::cli::fail(kProgram, f.image_path + ": " + m.status().toString());
      ++n;
      ms.push_back(dt);
      const Eigen::Vector3d truth = f.true_up_c.normalized();
      lev.push_back(angleDeg(level, truth));
      // The camera's own tilt, the small rotation taking the level up to the truth (same axes).
      const Eigen::Vector3d tilt = level.cross(truth);
      // Small rotation taking the truth to the estimate, camera axes: z = roll, x = pitch.
      const Eigen::Vector3d e = truth.cross(m->up_c);
      const double a = angleDeg(m->up_c, truth);
      // The error along the estimate's better tangent axis and along the worse one (rad).
      const Eigen::Vector3d d = m->up_c - truth;
      const Eigen::Vector3d weak_axis = m->up_c.cross(m->strong_axis_c).normalized();
      const double e_strong = d.dot(m->strong_axis_c), e_weak = d.dot(weak_axis);
      if (m->valid) {
        sig_strong.push_back(m->sigma_strong_rad / kDeg);
        sig_weak.push_back(m->sigma_rad / kDeg);
        if (std::abs(e_strong) < 2.0 * m->sigma_strong_rad) ++within_strong;
        if (std::abs(e_weak) < 2.0 * m->sigma_rad) ++within_weak;
        err.push_back(a);
        roll.push_back(e.z() / kDeg);
        pitch.push_back(e.x() / kDeg);
        if (a * kDeg < 2.0 * m->sigma_rad) ++within;
      }
      if (seg_csv.is_open() && m->valid) {
        const double inlier_bound = std::sin(options.inlier_angle_deg * kDeg);
        for (const auto& p : estimator.candidates()) {
          // The normal's sign: n.x > 0, so that the signed angles compare across segments.
          const Eigen::Vector3d nu = p.n.x() < 0.0 ? Eigen::Vector3d(-p.n) : p.n;
          const double x0 = std::abs(nu.x()) > 1e-12 ? -nu.z() / nu.x() : 0.0;
          seg_csv << ds->name << ',' << k << ',' << (std::abs(nu.dot(m->up_c)) < inlier_bound)
                  << ',' << std::asin(std::clamp(nu.dot(truth), -1.0, 1.0)) / kDeg << ','
                  << std::asin(std::clamp(nu.dot(m->up_c), -1.0, 1.0)) / kDeg << ',' << x0 << ','
                  << p.w << ',' << p.a.x() << ',' << p.a.y() << ',' << p.b.x() << ',' << p.b.y()
                  << '\n';
        }
      }
      if (csv.is_open()) {
        csv << ds->name << ',' << k << ',' << (m->valid ? 1 : 0) << ',' << m->reason << ','
            << m->candidates << ',' << m->inliers << ',' << a << ',' << e.z() / kDeg << ','
            << e.x() / kDeg << ',' << m->sigma_rad / kDeg << ',' << lev.back() << ',' << dt << ','
            << m->sigma_strong_rad / kDeg << ',' << e_strong / kDeg << ',' << e_weak / kDeg << ','
            << tilt.z() / kDeg << ',' << tilt.x() / kDeg << '\n';
      }
    }
    // A render or raw drive is <set>/<date>/<date>_drive_NNNN_sync: name it by <set>.
    std::string name = ds->name;
    const std::filesystem::path path(dir);
    if (name.ends_with("_sync") && path.has_parent_path() && path.parent_path().has_parent_path()) {
      const std::string set = path.parent_path().parent_path().filename().string();
      if (!set.empty() && set != ".") name = set + "/" + name;
    }
    const double valid_share = n > 0 ? static_cast<double>(err.size()) / n : 0.0;
    const auto share = [&](int k) {
      return err.empty() ? se::kNaN : 100.0 * static_cast<double>(k) / err.size();
    };
    std::printf(
        "| %s%s | %d | %.0f %% | %.2f | %.2f | %+.2f / %+.2f | %.0f %% | %.2f, %.0f %% / %.2f, "
        "%.0f %% | %.2f | %.1f |\n",
        name.c_str(), ds->level_assumed ? " (up: level rig assumed)" : "", n, 100.0 * valid_share,
        se::quantile(err, 0.5), se::quantile(err, 0.9), se::quantile(roll, 0.5),
        se::quantile(pitch, 0.5), share(within), se::quantile(sig_strong, 0.5),
        share(within_strong), se::quantile(sig_weak, 0.5), share(within_weak),
        se::quantile(lev, 0.5), se::quantile(ms, 0.5));
  }
  return 0;
}
