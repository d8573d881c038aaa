// sunvo_sun_eval: measures the image sun estimators against the true sun on image sets (any
// dataset with images and a true sun: a sunvo render, a KITTI raw drive with its UTC offset, a
// KITTI odometry folder with a sun file, or any of them as DIR:CSV with another sun file), all
// sets in one run. --help lists the options; metrics.hpp defines every statistic.
//
// For every estimator and image set: azimuth error (camera-frame azimuth atan2(x, z), estimate
// minus truth, wrapped) and zenith error (angle from the true "up", estimate minus truth); over the
// valid estimates their median and 90th percentile magnitudes, the signed azimuth median (bias),
// the gross share (|azimuth error| > 45 deg) and the share within 2 sigma; the share of gross
// estimates flagged invalid; the share kept by the default sun gate against the true-pose
// prediction; wall and process CPU time per call. For Lalonde estimators, each cue alone
// (lalonde_cues.hpp). The VO prior (for Lalonde-VO, and the "up" every estimator gets) is the true
// attitude perturbed by a random rotation per frame, each axis N(0, prior-error-deg),
// deterministic for the seed. Writes sun_eval.md, sun_eval.json, sun_eval.csv,
// hist/<estimator>_<set>_{azimuth,zenith}.png, frames/<estimator>_<set>.csv and, for the first N
// frames of each set, debug/ Fig.-1-style panels of the Lalonde estimators; --json and --csv
// write the summary to another file as well. Exit codes: 0 done, 1 an estimator or an input
// failed, 2 bad arguments.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "datasets.hpp"
#include "histogram.hpp"
#include "lalonde_cues.hpp"
#include "metrics.hpp"
#include "report.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/sunestimators/sun_estimators.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"
#include "sunvo/sunvision/lalonde_debug.hpp"

namespace {
namespace fs = std::filesystem;
namespace se = sunvo::suneval;
using sunvo::Expected;
using sunvo::Status;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kExitOk = 0, kExitFailed = 1;
constexpr const char* kProgram = "sunvo_sun_eval";

struct Args {
  std::vector<std::string> images;  // DIR or DIR:CSV (datasets.hpp)
  std::string out;
  std::string json;  // "" = only <out>/sun_eval.json
  std::string csv;   // "" = only <out>/sun_eval.csv
  std::vector<std::string> estimators;
  std::string model = SUNVO_DEFAULT_SUN_CNN_MODEL;
  std::optional<std::int64_t> utc_offset_s;
  int frames = 0;
  double prior_error_deg = 5.0;
  unsigned long long seed = 1;
  int debug = 2;
  int threads = 1;
  se::CameraChoice camera = se::CameraChoice::kAuto;
};

// CPU time of the whole process, ms: with one OpenCV thread (the default) the cost of a call on
// one core; with more, the sum over the threads that worked for it.
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// The VO attitude error of one frame: a rotation with each axis-angle component N(0, sigma).
// Seeded from the set's name (FNV-1a), so a set gets the same errors in any order.
Eigen::Matrix3d priorError(unsigned long long seed, const std::string& set, std::size_t frame,
                           double sigma_deg) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : set) h = (h ^ c) * 1099511628211ULL;
  std::mt19937_64 rng(seed * 1000003ULL + h + frame);
  std::normal_distribution<double> n(0.0, sigma_deg * kDeg);
  const Eigen::Vector3d w(n(rng), n(rng), n(rng));
  if (w.norm() < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

Status writePng(const fs::path& path, const cv::Mat& image) {
  try {
    if (!cv::imwrite(path.string(), image)) return sunvo::ioError(path.string() + ": cannot write");
  } catch (const cv::Exception& e) {
    return sunvo::ioError(path.string() + ": " + e.what());
  }
  return Status::ok();
}

// The sets, each named once: a second set of the same folder name gets "_2", and so on.
Expected<std::vector<se::EvalDataset>> loadSets(const Args& args) {
  std::vector<se::EvalDataset> sets;
  for (const std::string& text : args.images) {
    const se::SetSpec spec = se::parseSetSpec(text);
    se::EvalSetOptions o;
    o.max_frames = args.frames;
    o.utc_offset_s = args.utc_offset_s;
    o.sun_csv = spec.sun_csv;
    o.camera = args.camera;
    Expected<se::EvalDataset> ds = se::loadEvalDataset(spec.dir, o);
    if (!ds) return ds.status();
    const std::string base = ds->name;
    for (int k = 2;; ++k) {
      bool taken = false;
      for (const se::EvalDataset& s : sets) taken = taken || s.name == ds->name;
      if (!taken) break;
      ds->name = base + "_" + std::to_string(k);
    }
    sets.push_back(std::move(*ds));
  }
  return sets;
}

// Histograms and the per-frame CSV of one estimator on one set.
Status writePerSet(const fs::path& out, const se::SetResult& r, const std::string& frames_csv) {
  const std::string stem = r.estimator + "_" + r.set;
  std::vector<double> az, zen;
  for (const se::FrameResult& f : r.frames) {
    if (!f.valid) continue;
    if (std::isfinite(f.azimuth_error_deg)) az.push_back(f.azimuth_error_deg);
    if (std::isfinite(f.zenith_error_deg)) zen.push_back(f.zenith_error_deg);
  }
  SUNVO_RETURN_IF_ERROR(
      sunvo::files::writeWholeFile((out / "frames" / (stem + ".csv")).string(), frames_csv));
  SUNVO_RETURN_IF_ERROR(
      writePng(out / "hist" / (stem + "_azimuth.png"),
               se::drawErrorHistogram(az, -180.0, 180.0, 5.0, stem + " azimuth")));
  return writePng(out / "hist" / (stem + "_zenith.png"),
                  se::drawErrorHistogram(zen, -90.0, 90.0, 5.0, stem + " zenith"));
}

int run(const Args& args) {
  cv::setNumThreads(args.threads);
  auto estimators = sunvo::sunestimators::makeSunEstimators(args.estimators, args.model);
  if (!estimators) return sunvo::cli::fail(kProgram, estimators.status());
  Expected<std::vector<se::EvalDataset>> sets = loadSets(args);
  if (!sets) return sunvo::cli::fail(kProgram, sets.status());
  const fs::path out(args.out);
  std::error_code ec;
  for (const char* sub : {"hist", "frames", "debug"}) fs::create_directories(out / sub, ec);
  if (ec) return sunvo::cli::fail(kProgram, args.out + ": " + ec.message());

  const sunvo::sunfusion::SunGateOptions gate;
  std::vector<se::SetResult> all;
  for (const se::EvalDataset& ds : *sets) {
    const std::size_t n_est = estimators->size();
    std::vector<se::SetResult> per(n_est);
    std::vector<std::vector<double>> sky_err(n_est), shadow_err(n_est);
    std::vector<std::ostringstream> csv(n_est);
    for (std::size_t ei = 0; ei < n_est; ++ei) {
      per[ei].estimator = (*estimators)[ei]->name();
      per[ei].set = ds.name;
      per[ei].camera = ds.color ? "color" : "gray";
      csv[ei] << "frame,valid,azimuth_deg,zenith_deg,true_azimuth_deg,true_zenith_deg,"
                 "azimuth_error_deg,zenith_error_deg,sigma,azimuth_sigma_deg,confidence,gate,"
                 "time_ms,cpu_ms\n";
    }
    for (std::size_t k = 0; k < ds.frames.size(); ++k) {
      const se::EvalFrame& f = ds.frames[k];
      const cv::Mat image = cv::imread(f.image_path, cv::IMREAD_UNCHANGED);
      if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
        return sunvo::cli::fail(kProgram, f.image_path + ": cannot read as 8-bit gray/BGR");
      }
      const Eigen::Matrix3d C_err = priorError(args.seed, ds.name, k, args.prior_error_deg);
      sunvo::sunfusion::ImageSunInput in;
      in.color = image;
      in.camera = ds.camera;
      in.prior = sunvo::sunfusion::SunPrior{C_err * f.true_sun_c, C_err * f.true_up_c};
      const double true_az = se::azimuthDeg(f.true_sun_c);
      const double true_zen =
          std::acos(std::clamp(f.true_sun_c.dot(f.true_up_c), -1.0, 1.0)) / kDeg;
      // An estimator that takes colour only (Sun-CNN) gets a gray frame (the KITTI odometry
      // cameras 0/1) as three equal channels; one that acceptsGray() (Lalonde) gets it as it is.
      sunvo::sunfusion::ImageSunInput in_bgr = in;
      if (image.type() == CV_8UC1) cv::cvtColor(image, in_bgr.color, cv::COLOR_GRAY2BGR);
      for (std::size_t ei = 0; ei < n_est; ++ei) {
        sunvo::sunfusion::ImageSunEstimator& est = *(*estimators)[ei];
        const double cpu0 = processCpuMs();
        Expected<sunvo::sunfusion::ImageSunEstimate> e =
            est.estimate(est.acceptsGray() ? in : in_bgr);
        const double cpu_ms = processCpuMs() - cpu0;
        if (!e) {
          std::fprintf(stderr, "sunvo_sun_eval: %s on %s: %s\n", est.name(), f.image_path.c_str(),
                       e.status().toString().c_str());
          return kExitFailed;
        }
        se::FrameResult r;
        r.valid = e->valid;
        r.cpu_ms = cpu_ms;
        r.wall_ms = e->time_ms;
        const Eigen::Vector3d& sun = e->measurement.sun_c;
        if (sun.allFinite() && sun.norm() > 1e-9) {
          r.azimuth_error_deg = se::wrapDeg(se::azimuthDeg(sun) - true_az);
          // An azimuth-only estimate (Sun-CNN) says nothing about the zenith.
          if (e->measurement.kind == sunvo::sunfusion::SunMeasurementKind::kFull3d) {
            r.zenith_error_deg =
                std::acos(std::clamp(sun.normalized().dot(f.true_up_c), -1.0, 1.0)) / kDeg -
                true_zen;
          }
        }
        r.azimuth_sigma_deg =
            se::azimuthSigmaDeg(e->measurement.kind, e->measurement.sigma, f.true_sun_c);
        const char* gate_result = "invalid";
        if (e->valid) {
          const auto g = sunvo::sunfusion::gateSunMeasurement(
              gate, f.true_sun_c, f.true_sun_c.dot(f.true_up_c), e->measurement);
          gate_result = sunvo::sunfusion::toString(g);
          r.kept_by_gate = g == sunvo::sunfusion::GateResult::kAccepted;
        }
        per[ei].frames.push_back(r);
        csv[ei] << k << ',' << (e->valid ? 1 : 0) << ',' << se::formatNumber(e->azimuth_deg, 2)
                << ',' << se::formatNumber(e->zenith_deg, 2) << ',' << se::formatNumber(true_az, 2)
                << ',' << se::formatNumber(true_zen, 2) << ','
                << se::formatNumber(r.azimuth_error_deg, 2) << ','
                << se::formatNumber(r.zenith_error_deg, 2) << ','
                << se::formatNumber(e->measurement.sigma, 4) << ','
                << se::formatNumber(r.azimuth_sigma_deg, 2) << ','
                << se::formatNumber(e->confidence, 3) << ',' << gate_result << ','
                << se::formatNumber(e->time_ms, 2) << ',' << se::formatNumber(cpu_ms, 2) << '\n';
        const auto* lalonde = dynamic_cast<const sunvo::sunvision::LalondeEstimator*>(&est);
        if (!lalonde) continue;
        const se::CueErrors cue = se::lalondeCueErrors(*lalonde, f.true_sun_c);
        sky_err[ei].push_back(cue.sky_deg);
        shadow_err[ei].push_back(cue.shadow_deg);
        if (static_cast<int>(k) < args.debug) {
          auto dbg =
              sunvo::sunvision::renderLalondeDebug(*lalonde, in, *e, Eigen::Vector3d(f.true_sun_c));
          if (dbg) {
            const Status st = writePng(
                out / "debug" /
                    (std::string(est.name()) + "_" + ds.name + "_" + std::to_string(k) + ".png"),
                dbg->panel);
            if (!st) return sunvo::cli::fail(kProgram, st);
          }
        }
      }
    }
    for (std::size_t ei = 0; ei < n_est; ++ei) {
      se::SetResult& r = per[ei];
      r.summary = se::summarize(r.frames);
      if (!sky_err[ei].empty()) {
        r.cues = se::CueResults{se::summarizeCue(sky_err[ei]), se::summarizeCue(shadow_err[ei])};
      }
      const Status st = writePerSet(out, r, csv[ei].str());
      if (!st) return sunvo::cli::fail(kProgram, st);
      all.push_back(std::move(r));
    }
  }
  const se::ReportMeta meta{args.prior_error_deg, args.seed, args.threads};
  const std::string md = se::markdownReport(all, meta);
  const std::string json = se::jsonReport(all, meta);
  const std::string csv = se::csvReport(all);
  Status st = sunvo::files::writeWholeFile((out / "sun_eval.md").string(), md);
  if (st) st = sunvo::files::writeWholeFile((out / "sun_eval.json").string(), json);
  if (st) st = sunvo::files::writeWholeFile((out / "sun_eval.csv").string(), csv);
  if (st && !args.json.empty()) st = sunvo::files::writeWholeFile(args.json, json);
  if (st && !args.csv.empty()) st = sunvo::files::writeWholeFile(args.csv, csv);
  if (!st) return sunvo::cli::fail(kProgram, st);
  std::fputs(md.c_str(), stdout);
  return kExitOk;
}

// --images: DIR or DIR:CSV, each an existing path.
std::string checkSetSpec(std::string& text) {
  const se::SetSpec spec = se::parseSetSpec(text);
  std::error_code ec;
  if (!fs::exists(spec.dir, ec)) return "set folder does not exist: " + spec.dir;
  if (!spec.sun_csv.empty() && !fs::is_regular_file(spec.sun_csv, ec)) {
    return "sun file does not exist: " + spec.sun_csv;
  }
  return "";
}
}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{"Measures the image sun estimators against the true sun on image sets.", kProgram};
  app.add_option("--images", args.images,
                 "an image set: a sunvo render drive, a KITTI raw drive (with --utc-offset-s) or "
                 "a KITTI odometry folder (true sun in DIR/sun_cam.csv or "
                 "DIR/../<NN>_sun_cam.csv), or DIR:CSV with the true sun (frame,sx,sy,sz, camera "
                 "0) in CSV; repeat for several (one table row per set and estimator)")
      ->required()
      ->check(CLI::Validator(checkSetSpec, "DIR[:CSV]"));
  app.add_option("--out", args.out, "output folder (created)")->required();
  app.add_option("--json", args.json, "also write the JSON summary (sun_eval.json) to this file");
  app.add_option("--csv", args.csv, "also write the CSV summary (sun_eval.csv) to this file");
  app.add_option("--estimators", args.estimators, "comma-separated (default: all known)")
      ->delimiter(',')
      ->check(CLI::IsMember(sunvo::sunestimators::knownSunEstimators()));
  app.add_option("--model", args.model, "the Sun-CNN ONNX model");
  app.add_option("--utc-offset-s", args.utc_offset_s,
                 "offset of a KITTI raw drive's timestamps to UTC, s (a render writes UTC)")
      ->check(CLI::Range(-50400, 50400));
  app.add_option("--frames", args.frames, "first N frames of each set (0 = all)")
      ->check(CLI::Range(0, 10000000));
  app.add_option("--prior-error-deg", args.prior_error_deg,
                 "per-axis 1-sigma attitude error of the VO prior, deg")
      ->check(CLI::Range(0.0, 90.0));
  app.add_option("--seed", args.seed, "seed of that error");
  app.add_option("--debug", args.debug, "debug panels for the first N frames of each set")
      ->check(CLI::Range(0, 1000000));
  const std::map<std::string, se::CameraChoice> cameras = {{"auto", se::CameraChoice::kAuto},
                                                           {"color", se::CameraChoice::kColor},
                                                           {"gray", se::CameraChoice::kGray}};
  app.add_option("--camera", args.camera,
                 "auto: the colour camera 2 where a set has it, else the gray camera 0; color: "
                 "camera 2 (a set without it fails); gray: camera 0 everywhere")
      ->transform(CLI::CheckedTransformer(cameras, CLI::ignore_case));
  app.add_option("--threads", args.threads,
                 "OpenCV threads (1: CPU time per call is the cost on one core)")
      ->check(CLI::Range(1, 64));
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (args.estimators.empty()) args.estimators = sunvo::sunestimators::knownSunEstimators();
  return run(args);
}
