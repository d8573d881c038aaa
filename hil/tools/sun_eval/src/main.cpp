// sunvo_sun_eval: measures the image sun estimators against the true sun on image sets (any
// dataset with images and a true sun: a sunvo render, a KITTI raw drive with its UTC offset, a
// KITTI odometry folder with a sun file). --help lists the options.
//
// For every estimator and image set: azimuth error (camera-frame azimuth atan2(x, z), estimate
// minus truth, wrapped) and zenith error (angle from the true "up", estimate minus truth) over the
// valid estimates; median and 90th percentile of their magnitudes; share of gross errors
// (|azimuth error| > 45 deg, over the valid estimates); share kept by the default sun gate
// against the true-pose prediction (over all frames: an invalid estimate is not kept); time per
// call (wall, and CPU time of the calling thread). The VO prior (for Lalonde-VO, and the "up" every
// estimator gets) is the true attitude perturbed by a random rotation per frame, each axis N(0,
// prior-error-deg), deterministic for the seed. Writes sun_eval.md, sun_eval.json,
// hist/<estimator>_<set>_{azimuth,zenith}.png, frames/<estimator>_<set>.csv and, for the first N
// frames of each set, debug/ Fig.-1-style panels of the Lalonde estimators. Exit codes: 0 done, 1
// an estimator or an input failed, 2 bad arguments.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
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
#include "sunvo/cli/cli.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/report/json_writer.hpp"
#include "sunvo/sunestimators/sun_estimators.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"
#include "sunvo/sunvision/lalonde_debug.hpp"

namespace {
namespace fs = std::filesystem;
using sunvo::Expected;
using sunvo::Status;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kExitOk = 0, kExitFailed = 1;
constexpr const char* kProgram = "sunvo_sun_eval";

struct Args {
  std::vector<std::string> images;
  std::string out;
  std::vector<std::string> estimators;
  std::string model = SUNVO_DEFAULT_SUN_CNN_MODEL;
  std::optional<std::int64_t> utc_offset_s;
  int frames = 0;
  double prior_error_deg = 5.0;
  unsigned long long seed = 1;
  int debug = 2;
  int threads = 1;
};

struct Stats {
  std::string estimator, dataset;
  int frames = 0, valid = 0, gross = 0, kept = 0;
  std::vector<double> az_err_deg, zen_err_deg, time_ms, cpu_ms;
};

double absPercentile(const std::vector<double>& v, double q) {
  if (v.empty()) return std::nan("");
  std::vector<double> a;
  a.reserve(v.size());
  for (double x : v) a.push_back(std::abs(x));
  return sunvo::metrics::percentile(a, q);
}

// CPU time of the calling thread, ms: the cost of a call on one core, whatever else runs.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double share(int n, int d) {
  return d > 0 ? static_cast<double>(n) / d : 0.0;
}

std::string fmt(double v, int digits = 1) {
  if (!std::isfinite(v)) return "–";
  char b[32];
  std::snprintf(b, sizeof(b), "%.*f", digits, v);
  return b;
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

std::string markdown(const std::vector<Stats>& all, const Args& args) {
  std::ostringstream md;
  md << "# Image sun estimators: errors against the true sun\n\n"
     << "Errors over the valid estimates; gross = |azimuth error| > 45 deg; kept = accepted by "
        "the default sun gate against the true-pose prediction, over all frames; VO prior "
        "attitude error "
     << fmt(args.prior_error_deg) << " deg per axis (1 sigma), seed " << args.seed
     << "; OpenCV threads " << args.threads << ".\n\n"
     << "| estimator | set | frames | valid | az. median | az. p90 | zen. median | zen. p90 | "
        "gross | kept by gate | wall ms/call median | p90 | CPU ms/call median | p90 |\n"
     << "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
        "| "
        "---: |\n";
  for (const Stats& s : all) {
    md << "| " << s.estimator << " | " << s.dataset << " | " << s.frames << " | "
       << fmt(100.0 * share(s.valid, s.frames), 0) << " % | "
       << fmt(absPercentile(s.az_err_deg, 0.5)) << "° | " << fmt(absPercentile(s.az_err_deg, 0.9))
       << "° | " << fmt(absPercentile(s.zen_err_deg, 0.5)) << "° | "
       << fmt(absPercentile(s.zen_err_deg, 0.9)) << "° | "
       << fmt(100.0 * share(s.gross, s.valid), 0) << " % | "
       << fmt(100.0 * share(s.kept, s.frames), 0) << " % | " << fmt(absPercentile(s.time_ms, 0.5))
       << " | " << fmt(absPercentile(s.time_ms, 0.9)) << " | " << fmt(absPercentile(s.cpu_ms, 0.5))
       << " | " << fmt(absPercentile(s.cpu_ms, 0.9)) << " |\n";
  }
  return md.str();
}

std::string json(const std::vector<Stats>& all, const Args& args) {
  sunvo::report::JsonWriter w;
  w.beginObject().key("prior_error_deg").value(args.prior_error_deg);
  w.key("seed").value(static_cast<std::uint64_t>(args.seed)).key("threads").value(args.threads);
  w.key("results").beginArray();
  for (const Stats& s : all) {
    w.beginObject()
        .key("estimator")
        .value(s.estimator)
        .key("dataset")
        .value(s.dataset)
        .key("frames")
        .value(s.frames)
        .key("valid")
        .value(s.valid)
        .key("gross_errors")
        .value(s.gross)
        .key("gross_share")
        .value(share(s.gross, s.valid))
        .key("kept_by_gate")
        .value(s.kept)
        .key("kept_share")
        .value(share(s.kept, s.frames));
    for (const auto& [name, values] : {std::pair<std::string, const std::vector<double>*>{
                                           "azimuth_abs_error_deg", &s.az_err_deg},
                                       {"zenith_abs_error_deg", &s.zen_err_deg},
                                       {"time_ms", &s.time_ms},
                                       {"cpu_ms", &s.cpu_ms}}) {
      w.key(name + "_median").value(absPercentile(*values, 0.5));
      w.key(name + "_p90").value(absPercentile(*values, 0.9));
    }
    w.key("azimuth_errors_deg").beginArray();
    for (double v : s.az_err_deg) w.value(v);
    w.endArray().key("zenith_errors_deg").beginArray();
    for (double v : s.zen_err_deg) w.value(v);
    w.endArray().endObject();
  }
  w.endArray().endObject();
  return w.str() + "\n";
}

int run(const Args& args) {
  cv::setNumThreads(args.threads);
  auto estimators = sunvo::sunestimators::makeSunEstimators(args.estimators, args.model);
  if (!estimators) return sunvo::cli::fail(kProgram, estimators.status());
  std::vector<sunvo::suneval::EvalDataset> sets;
  for (const std::string& dir : args.images) {
    Expected<sunvo::suneval::EvalDataset> ds =
        sunvo::suneval::loadEvalDataset(dir, args.frames, args.utc_offset_s);
    if (!ds) return sunvo::cli::fail(kProgram, ds.status());
    sets.push_back(std::move(*ds));
  }
  const fs::path out(args.out);
  std::error_code ec;
  for (const char* sub : {"hist", "frames", "debug"}) fs::create_directories(out / sub, ec);
  if (ec) return sunvo::cli::fail(kProgram, args.out + ": " + ec.message());

  const sunvo::sunfusion::SunGateOptions gate;
  std::vector<Stats> all;
  for (std::size_t si = 0; si < sets.size(); ++si) {
    const sunvo::suneval::EvalDataset& ds = sets[si];
    std::vector<Stats> per(estimators->size());
    std::vector<std::ostringstream> csv(estimators->size());
    for (std::size_t ei = 0; ei < estimators->size(); ++ei) {
      per[ei].estimator = (*estimators)[ei]->name();
      per[ei].dataset = ds.name;
      csv[ei] << "frame,valid,azimuth_deg,zenith_deg,true_azimuth_deg,true_zenith_deg,"
                 "azimuth_error_deg,zenith_error_deg,sigma,confidence,gate,time_ms\n";
    }
    for (std::size_t k = 0; k < ds.frames.size(); ++k) {
      const sunvo::suneval::EvalFrame& f = ds.frames[k];
      const cv::Mat image = cv::imread(f.image_path, cv::IMREAD_UNCHANGED);
      if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
        return sunvo::cli::fail(kProgram, f.image_path + ": cannot read as 8-bit gray/BGR");
      }
      const Eigen::Matrix3d C_err = priorError(args.seed, ds.name, k, args.prior_error_deg);
      sunvo::sunfusion::ImageSunInput in;
      in.color = image;
      in.camera = ds.camera;
      in.prior = sunvo::sunfusion::SunPrior{C_err * f.true_sun_c, C_err * f.true_up_c};
      const double true_az = std::atan2(f.true_sun_c.x(), f.true_sun_c.z()) / kDeg;
      const double true_zen =
          std::acos(std::clamp(f.true_sun_c.dot(f.true_up_c), -1.0, 1.0)) / kDeg;
      // An estimator that takes colour only (Sun-CNN) gets a gray frame (the KITTI odometry
      // sample) as three equal channels; one that acceptsGray() (Lalonde) gets it as it is.
      sunvo::sunfusion::ImageSunInput in_bgr = in;
      if (image.type() == CV_8UC1) cv::cvtColor(image, in_bgr.color, cv::COLOR_GRAY2BGR);
      for (std::size_t ei = 0; ei < estimators->size(); ++ei) {
        sunvo::sunfusion::ImageSunEstimator& est = *(*estimators)[ei];
        const double cpu0 = threadCpuMs();
        Expected<sunvo::sunfusion::ImageSunEstimate> e =
            est.estimate(est.acceptsGray() ? in : in_bgr);
        const double cpu_ms = threadCpuMs() - cpu0;
        if (!e) {
          std::fprintf(stderr, "sunvo_sun_eval: %s on %s: %s\n", est.name(), f.image_path.c_str(),
                       e.status().toString().c_str());
          return kExitFailed;
        }
        Stats& s = per[ei];
        ++s.frames;
        s.time_ms.push_back(e->time_ms);
        s.cpu_ms.push_back(cpu_ms);
        double az_err = std::nan(""), zen_err = std::nan("");
        const char* gate_result = "invalid";
        if (e->valid) {
          ++s.valid;
          const Eigen::Vector3d& sun = e->measurement.sun_c;
          az_err = sunvo::sunvision::wrapPi((std::atan2(sun.x(), sun.z()) - true_az * kDeg)) / kDeg;
          s.az_err_deg.push_back(az_err);
          // An azimuth-only estimate (Sun-CNN) says nothing about the zenith.
          if (e->measurement.kind == sunvo::sunfusion::SunMeasurementKind::kFull3d) {
            zen_err = std::acos(std::clamp(sun.normalized().dot(f.true_up_c), -1.0, 1.0)) / kDeg -
                      true_zen;
            s.zen_err_deg.push_back(zen_err);
          }
          if (std::abs(az_err) > 45.0) ++s.gross;
          const auto g = sunvo::sunfusion::gateSunMeasurement(
              gate, f.true_sun_c, f.true_sun_c.dot(f.true_up_c), e->measurement);
          gate_result = sunvo::sunfusion::toString(g);
          if (g == sunvo::sunfusion::GateResult::kAccepted) ++s.kept;
        }
        csv[ei] << k << ',' << (e->valid ? 1 : 0) << ',' << fmt(e->azimuth_deg, 2) << ','
                << fmt(e->zenith_deg, 2) << ',' << fmt(true_az, 2) << ',' << fmt(true_zen, 2) << ','
                << fmt(az_err, 2) << ',' << fmt(zen_err, 2) << ',' << fmt(e->measurement.sigma, 4)
                << ',' << fmt(e->confidence, 3) << ',' << gate_result << ',' << fmt(e->time_ms, 2)
                << '\n';
        const auto* lalonde = dynamic_cast<const sunvo::sunvision::LalondeEstimator*>(&est);
        if (lalonde && static_cast<int>(k) < args.debug) {
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
    for (std::size_t ei = 0; ei < per.size(); ++ei) {
      const std::string stem = per[ei].estimator + "_" + ds.name;
      Status st =
          sunvo::files::writeWholeFile((out / "frames" / (stem + ".csv")).string(), csv[ei].str());
      if (st) {
        st = writePng(out / "hist" / (stem + "_azimuth.png"),
                      sunvo::suneval::drawErrorHistogram(per[ei].az_err_deg, -180.0, 180.0, 5.0,
                                                         stem + " azimuth"));
      }
      if (st) {
        st = writePng(out / "hist" / (stem + "_zenith.png"),
                      sunvo::suneval::drawErrorHistogram(per[ei].zen_err_deg, -90.0, 90.0, 5.0,
                                                         stem + " zenith"));
      }
      if (!st) return sunvo::cli::fail(kProgram, st);
      all.push_back(std::move(per[ei]));
    }
  }
  const std::string md = markdown(all, args);
  Status st = sunvo::files::writeWholeFile((out / "sun_eval.md").string(), md);
  if (st) st = sunvo::files::writeWholeFile((out / "sun_eval.json").string(), json(all, args));
  if (!st) return sunvo::cli::fail(kProgram, st);
  std::fputs(md.c_str(), stdout);
  return kExitOk;
}
}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{"Measures the image sun estimators against the true sun on image sets.", kProgram};
  app.add_option("--images", args.images,
                 "an image set: a sunvo render, a KITTI raw drive (with --utc-offset-s) or a KITTI "
                 "odometry folder (true sun in DIR/sun_cam.csv or DIR/../<NN>_sun_cam.csv); repeat "
                 "for several")
      ->required()
      ->check(CLI::ExistingPath);
  app.add_option("--out", args.out, "output folder (created)")->required();
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
  app.add_option("--threads", args.threads, "OpenCV threads (1: time per call on one core)")
      ->check(CLI::Range(1, 64));
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (args.estimators.empty()) args.estimators = sunvo::sunestimators::knownSunEstimators();
  return run(args);
}
