// sunvo_replay: replays a drive in the KITTI raw layout (e.g. one rendered by sunvo_render)
// through the whole chain — images, OXTS, ENU world, SPA sun, image VO with sun residuals — for
// pure VO and VO + each sun source, and prints the paper's Table 1 (East-North plane) with a
// top-view plot.
//
// Usage: sunvo_replay --drive DIR [--out DIR] [--frames N] [--every N] [--seed N]
//                     [--drift-deg D] [--max-drift-deg M] [--image-max-drift-deg M]
//                     [--paper-form] [--estimators a,b,...] [--poses]
//   --drift-deg   start value of the sun fusion's attitude random walk (deg/frame)
//   --max-drift-deg  upper bound of the adapted random walk (deg/frame), error-model sources
//   --image-max-drift-deg  the same for the image estimators (default 0.01)
//   --estimators  also VO + sun from these image estimators (lalonde, lalonde_vo, sun_cnn) run
//                 on the drive's colour images; "none" (default) runs the error-model sources
//   --poses       also writes each run's estimated T_w_c as a KITTI pose file,
//                 OUT/replay_poses_<run>.txt (run: pure_vo, vo_sun_true_vector, ...), for
//                 comparing replays across builds (scripts/test_arm64.sh: x86-64 vs aarch64)

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/replay/replay.hpp"
#include "sunvo/report/report_files.hpp"
#include "sunvo/sun_estimators/sun_estimators.hpp"

namespace {

int usage(const std::string& msg) {
  std::fprintf(stderr, "sunvo_replay: %s\n", msg.c_str());
  std::fprintf(stderr,
               "usage: sunvo_replay --drive DIR [--out DIR] [--frames N] [--every N] [--seed N] "
               "[--drift-deg D] [--max-drift-deg M] [--image-max-drift-deg M] [--paper-form] "
               "[--estimators a,b,...] [--poses]\n");
  return 2;
}

bool parseCount(const char* text, int& out) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < 0 || v > 10'000'000) return false;
  out = static_cast<int>(v);
  return true;
}

// "VO+Sun (true vector)" -> "vo_sun_true_vector": lower-case letters and digits, one '_' for
// each run of anything else, none at the ends.
std::string fileSlug(const std::string& name) {
  std::string slug;
  for (const char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) != 0) {
      slug += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!slug.empty() && slug.back() != '_') {
      slug += '_';
    }
  }
  while (!slug.empty() && slug.back() == '_') slug.pop_back();
  return slug;
}

}  // namespace

int main(int argc, char** argv) {
  sunvo::replay::ReplayOptions options;
  std::string out_dir = "replay_out";
  int seed = 1;
  bool write_poses = false;
  std::vector<std::string> estimator_names;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--drive" && has_value) {
      options.drive_dir = argv[++i];
    } else if (a == "--out" && has_value) {
      out_dir = argv[++i];
    } else if (a == "--frames" && has_value) {
      if (!parseCount(argv[++i], options.max_frames)) return usage("--frames needs a count");
    } else if (a == "--every" && has_value) {
      if (!parseCount(argv[++i], options.every_n_frames)) return usage("--every needs a count");
    } else if (a == "--seed" && has_value) {
      if (!parseCount(argv[++i], seed)) return usage("--seed needs a number >= 0");
    } else if (a == "--drift-deg" && has_value) {
      options.fusion.attitude_drift_deg_per_frame = std::strtod(argv[++i], nullptr);
    } else if (a == "--max-drift-deg" && has_value) {
      options.fusion.max_drift_deg_per_frame = std::strtod(argv[++i], nullptr);
    } else if (a == "--image-max-drift-deg" && has_value) {
      options.image_max_drift_deg_per_frame = std::strtod(argv[++i], nullptr);
    } else if (a == "--paper-form") {
      options.fusion.estimate_base_attitude = false;
    } else if (a == "--poses") {
      write_poses = true;
    } else if (a == "--estimators" && has_value) {
      std::string list = argv[++i];
      for (std::size_t p = 0; p <= list.size();) {
        const std::size_t q = std::min(list.find(',', p), list.size());
        if (q > p && list.substr(p, q - p) != "none")
          estimator_names.push_back(list.substr(p, q - p));
        p = q + 1;
      }
    } else {
      return usage("unknown or incomplete argument '" + a + "'");
    }
  }
  if (auto s = options.validate(); !s.isOk()) return usage(s.toString());
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return usage("cannot create output folder '" + out_dir + "': " + ec.message());

  auto data = sunvo::replay::loadReplayData(options);
  if (!data) return usage(data.status().toString());
  std::vector<std::optional<sunvo::experiment::SunSourceSpec>> specs{std::nullopt};
  for (const auto& s : sunvo::experiment::defaultSunSources(static_cast<std::uint32_t>(seed))) {
    specs.emplace_back(s);
  }
  sunvo::report::ReportInput input;
  input.gt_path = options.drive_dir + "/gt/poses_cam0_enu.txt";
  input.gt_times_source = "image_00/timestamps.txt";
  input.plane = sunvo::metrics::HorizontalPlane::kEastNorth;
  std::vector<sunvo::report::PlotSeries> series;
  std::vector<sunvo::Isometry3> gt;
  auto estimators = sunvo::suneval::makeSunEstimators(estimator_names);
  if (!estimators) return usage(estimators.status().toString());
  const std::size_t num_runs = specs.size() + estimators->size();
  for (std::size_t i = 0; i < num_runs; ++i) {
    const bool image = i >= specs.size();
    auto run = image ? sunvo::replay::replayDrive(options, std::nullopt,
                                                  (*estimators)[i - specs.size()].get())
                     : sunvo::replay::replayDrive(options, specs[i]);
    if (!run) {
      std::fprintf(stderr, "sunvo_replay: %s\n", run.status().toString().c_str());
      return 1;
    }
    gt.assign(data->T_w_c_gt.begin(),
              data->T_w_c_gt.begin() + static_cast<std::ptrdiff_t>(run->T_w_c.size()));
    sunvo::metrics::EvaluationOptions eval_opt;
    eval_opt.plane = input.plane;
    auto ev = sunvo::metrics::evaluate(gt, run->T_w_c, eval_opt);
    if (!ev) return usage(ev.status().toString());
    std::fprintf(stderr,
                 "  %-28s %zu frames, %.1f ms/frame median, %.1f p99, %d lost, sun %llu/%llu\n",
                 run->name.c_str(), run->T_w_c.size(), run->median_ms, run->p99_ms,
                 run->lost_frames, static_cast<unsigned long long>(run->gate.accepted),
                 static_cast<unsigned long long>(run->gate.total()));
    if (run->sun_calls > 0) {
      std::fprintf(stderr, "  %-28s %d estimator calls, %.1f ms median, %.1f ms p90\n", "",
                   run->sun_calls, sunvo::metrics::percentile(run->sun_ms, 0.5),
                   sunvo::metrics::percentile(run->sun_ms, 0.9));
    }
    if (write_poses) {
      const std::string path = out_dir + "/replay_poses_" + fileSlug(run->name) + ".txt";
      sunvo::files::Trajectory trajectory;
      trajectory.T_w_c = run->T_w_c;
      if (auto s = sunvo::files::writeKittiPoses(path, trajectory); !s.isOk()) {
        std::fprintf(stderr, "sunvo_replay: %s\n", s.toString().c_str());
        return 1;
      }
    }
    input.num_poses = run->T_w_c.size();
    input.estimates.push_back({run->name, "", *ev});
    series.push_back({run->name, run->T_w_c});
  }
  auto table = sunvo::report::writeRouteReport(out_dir + "/replay", input, gt, series);
  if (!table) return usage(table.status().toString());
  std::printf(
      "\n### Replay of %s (%zu frames, %.0f m; sun measurements from the ground truth "
      "through error models%s)\n\n%s",
      options.drive_dir.c_str(), input.num_poses,
      input.estimates.front().evaluation.table1.gt_path_length_m,
      estimators->empty() ? "" : " and from the image estimators", table->c_str());
  std::printf("\nwrote %s/replay_{table1.md,metrics.json,topview.png}\n", out_dir.c_str());
  return 0;
}
