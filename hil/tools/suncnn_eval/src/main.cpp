// sunvo_sun_cnn_eval: runs the Sun-CNN estimator over image sets with known sun and prints the
// azimuth error (median, p90, share > 45 deg), the reported sigma and the time per call.
//   sunvo_sun_cnn_eval --model config/sun_cnn.onnx [--threads 1] [--mc N] [--sigma-scale S]
//       [--grey]                           feed every image as grey (CV_8UC1)
//       [--drive <..._sync dir>]...        rendered/KITTI raw layout: image_02/data +
//       gt/sun_cam0.csv
//       [--odometry <frames dir> --sun-csv <file>]   KITTI odometry: grey image_0/*.png +
//       frame,sx,sy,sz
//       [--every N]                        every Nth frame of each drive
//       [--csv out.csv]                    one line per image
// The options come from the model's JSON beside it (when there is one), then --mc and
// --sigma-scale. Images are fed as read (grey or BGR; the estimator takes either). Exit status
// (firmware_app/cli): 0 ok, 2 a bad command line or option value, 1 any other error.
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/suncnn/sun_cnn_estimator.hpp"

namespace fs = std::filesystem;
using sunvo::Expected;
using sunvo::Status;

namespace {
struct Item {
  std::string image;
  Eigen::Vector3d sun_c;
};

// frame,sx,sy,sz (header line first) -> frame -> unit sun vector.
Expected<std::map<int, Eigen::Vector3d>> readSunCsv(const std::string& path) {
  std::ifstream f(path);
  if (!f) return sunvo::notFound("cannot open " + path);
  std::map<int, Eigen::Vector3d> out;
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (n == 1 || line.empty()) continue;
    std::stringstream ss(line);
    std::string tok;
    std::vector<double> v;
    while (std::getline(ss, tok, ',')) {
      char* end = nullptr;
      v.push_back(std::strtod(tok.c_str(), &end));
      if (end == tok.c_str())
        return sunvo::parseError(path + " line " + std::to_string(n) + ": not a number");
    }
    if (v.size() != 4)
      return sunvo::parseError(path + " line " + std::to_string(n) + ": expected frame,sx,sy,sz");
    out[static_cast<int>(v[0])] = Eigen::Vector3d(v[1], v[2], v[3]);
  }
  return out;
}

// CPU time of this thread, ms: with --threads 1 the cost of a call without the other
// processes' share of the (loaded, 2-core) machine.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double azimuthDeg(const Eigen::Vector3d& s) {
  return std::atan2(s.x(), s.z()) * 180.0 / std::numbers::pi;
}

struct SetResult {
  std::vector<double> err_deg, sigma_deg, time_ms, cpu_ms;
  int valid = 0;
};

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_sun_cnn_eval";
  std::string model, odometry, sun_csv, csv_out;
  std::vector<std::string> drives;
  int threads = 1, every = 1;
  bool grey = false;
  std::optional<int> mc;
  std::optional<double> sigma_scale;
  CLI::App app{
      "Sun-CNN azimuth error, reported sigma and time per call on image sets with a known "
      "sun (rendered drives, KITTI odometry frames).",
      kProgram};
  app.add_option("--model", model, "the Sun-CNN ONNX model")->required();
  app.add_option("--threads", threads, "OpenCV threads")->check(CLI::Range(1, 1024));
  app.add_option("--mc", mc, "MC-dropout samples per image (0: none; default: the model's JSON)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sigma-scale", sigma_scale,
                 "calibration factor on the spread sigma (default: the model's JSON)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--grey", grey, "feed every image as grey (BT.601 luma)");
  app.add_option("--every", every, "every N-th frame of each set")->check(CLI::Range(1, 1000000));
  auto* drive = app.add_option("--drive", drives,
                               "a rendered or KITTI raw drive: image_02/data + gt/sun_cam0.csv "
                               "(repeatable)");
  auto* odo = app.add_option("--odometry", odometry, "KITTI odometry frames: grey image_0/*.png");
  app.add_option("--sun-csv", sun_csv, "frame,sx,sy,sz of the --odometry frames")->needs(odo);
  odo->needs("--sun-csv");
  app.add_option("--csv", csv_out, "one line per image");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (drive->count() == 0 && odo->count() == 0) {
    std::fprintf(stderr,
                 "%s: give at least one --drive or --odometry\nRun with --help for more "
                 "information.\n",
                 kProgram);
    return sunvo::cli::kExitUsage;
  }
  auto model_options = sunvo::suncnn::optionsForModel(model);
  if (!model_options) return sunvo::cli::fail(kProgram, model_options.status());
  sunvo::suncnn::SunCnnOptions options = *model_options;
  if (mc) options.mc_samples = *mc;
  if (sigma_scale) options.sigma_scale = *sigma_scale;
  if (const Status st = options.validate(); !st.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, st.toString().c_str());
    return sunvo::cli::kExitUsage;
  }
  cv::setNumThreads(threads);
  sunvo::suncnn::SunCnnEstimator est;
  if (Status st = est.init(options, model); !st.isOk()) return sunvo::cli::fail(kProgram, st);

  // The sets: one per drive, one for the odometry frames.
  std::vector<std::pair<std::string, std::vector<Item>>> sets;
  for (const std::string& d : drives) {
    auto sun = readSunCsv(d + "/gt/sun_cam0.csv");
    if (!sun) return sunvo::cli::fail(kProgram, sun.status());
    std::vector<Item> items;
    for (const auto& [k, s] : *sun) {
      if (k % every != 0) continue;
      char fn[32];
      std::snprintf(fn, sizeof fn, "%010d.png", k);
      items.push_back({d + "/image_02/data/" + fn, s});
    }
    // <renders>/<scenario>/<date>/<drive>: named by the scenario folder.
    sets.emplace_back(fs::path(d).parent_path().parent_path().filename().string(),
                      std::move(items));
  }
  if (!odometry.empty()) {
    auto sun = readSunCsv(sun_csv);
    if (!sun) return sunvo::cli::fail(kProgram, sun.status());
    std::vector<Item> items;
    std::error_code ec;
    const fs::directory_iterator frames(odometry + "/image_0", ec);
    if (ec) return sunvo::cli::fail(kProgram, odometry + "/image_0: " + ec.message());
    for (const auto& e : frames) {
      const int k = std::atoi(e.path().stem().string().c_str());
      if (auto it = sun->find(k); it != sun->end())
        items.push_back({e.path().string(), it->second});
    }
    std::sort(items.begin(), items.end(),
              [](const Item& x, const Item& y) { return x.image < y.image; });
    sets.emplace_back("kitti_odometry_" + fs::path(odometry).filename().string(), std::move(items));
  }

  std::FILE* csv = csv_out.empty() ? nullptr : std::fopen(csv_out.c_str(), "w");
  if (!csv_out.empty() && csv == nullptr) {
    return sunvo::cli::fail(kProgram, csv_out + ": cannot open for writing");
  }
  if (csv) std::fprintf(csv, "set,image,true_az_deg,est_az_deg,err_deg,sigma_deg,valid,time_ms\n");
  SetResult all;
  // Times per call, ms: wall (t_) and this thread's CPU (cpu_), median and p90.
  std::printf("%-36s %5s %8s %8s %7s %7s %9s %7s %7s %7s %7s\n", "set", "n", "med_deg", "p90_deg",
              "gt45", "valid", "sigma_med", "t_med", "t_p90", "cpu_med", "cpu_p90");
  auto print = [](const std::string& n, const SetResult& s) {
    if (s.err_deg.empty()) return;
    int gross = 0;
    for (double v : s.err_deg) gross += v > 45.0 ? 1 : 0;
    std::printf(
        "%-36s %5zu %8.2f %8.2f %6.1f%% %6.1f%% %9.2f %7.2f %7.2f %7.2f %7.2f\n", n.c_str(),
        s.err_deg.size(), sunvo::metrics::percentile(s.err_deg, 0.5),
        sunvo::metrics::percentile(s.err_deg, 0.9),
        100.0 * gross / static_cast<double>(s.err_deg.size()),
        100.0 * s.valid / static_cast<double>(s.err_deg.size()),
        sunvo::metrics::percentile(s.sigma_deg, 0.5), sunvo::metrics::percentile(s.time_ms, 0.5),
        sunvo::metrics::percentile(s.time_ms, 0.9), sunvo::metrics::percentile(s.cpu_ms, 0.5),
        sunvo::metrics::percentile(s.cpu_ms, 0.9));
  };
  for (const auto& [name, items] : sets) {
    SetResult r;
    for (const Item& it : items) {
      cv::Mat img = cv::imread(it.image, cv::IMREAD_UNCHANGED);
      if (img.empty()) return sunvo::cli::fail(kProgram, "cannot read " + it.image);
      if (grey && img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
      sunvo::sunfusion::ImageSunInput in;
      in.color = img;
      const double cpu0 = threadCpuMs();
      auto e = est.estimate(in);
      r.cpu_ms.push_back(threadCpuMs() - cpu0);
      if (!e) return sunvo::cli::fail(kProgram, it.image + ": " + e.status().toString());
      const double truth = azimuthDeg(it.sun_c);
      double err = std::fabs(std::remainder(e->azimuth_deg - truth, 360.0));
      const double sigma_deg = e->measurement.sigma * 180.0 / std::numbers::pi;
      // The azimuth is undefined for a sun within ~11 deg of the camera's y axis: not scored.
      if (std::hypot(it.sun_c.x(), it.sun_c.z()) > 0.2) {
        r.err_deg.push_back(err);
        r.sigma_deg.push_back(sigma_deg);
        r.valid += e->valid ? 1 : 0;
      }
      r.time_ms.push_back(e->time_ms);
      if (csv)
        std::fprintf(csv, "%s,%s,%.3f,%.3f,%.3f,%.3f,%d,%.3f\n", name.c_str(), it.image.c_str(),
                     truth, e->azimuth_deg, err, sigma_deg, e->valid ? 1 : 0, e->time_ms);
    }
    print(name, r);
    all.err_deg.insert(all.err_deg.end(), r.err_deg.begin(), r.err_deg.end());
    all.sigma_deg.insert(all.sigma_deg.end(), r.sigma_deg.begin(), r.sigma_deg.end());
    all.time_ms.insert(all.time_ms.end(), r.time_ms.begin(), r.time_ms.end());
    all.cpu_ms.insert(all.cpu_ms.end(), r.cpu_ms.begin(), r.cpu_ms.end());
    all.valid += r.valid;
  }
  if (sets.size() > 1) print("ALL", all);
  if (csv) std::fclose(csv);
  return sunvo::cli::kExitOk;
}
