// sunvo_experiment: the paper's experiment in one command. Pure VO against VO + sun from several
// sun sources (the true vector and error models emulating Lalonde, Lalonde-VO and Sun-CNN), on the
// real 2011_09_30_drive_0020 feature tracks and on simulated tracks along the real routes 00 and
// 06. Per route: a Table-1-style markdown table and JSON, and a top-view plot (PNG).
//
// Usage: sunvo_experiment [--data DIR] [--out DIR] [--routes 0020,00,06] [--frames N]
//                         [--every N] [--seed N] [--drift-deg D] [--sun-loss S] [--paper-form]
//                         [--write-poses] [--fixed-drift] [--drift-rule R]
//                         [--innovation-gate X] [--initial-sigma-deg S] [--max-drift-deg M]
//   --drift-deg   attitude random walk of VO per frame for the sun fusion (deg; the start value
//                 when it adapts)
//   --sun-loss    Cauchy scale on the whitened sun residual (0 = none)
//   --paper-form  hold the base attitude fixed, as the paper did
//   --fixed-drift keep the attitude random walk at --drift-deg instead of adapting it
//   --drift-rule  how the random walk adapts: persistence (default), median or fixed
//   --innovation-gate  chi-square bound of the innovation gate (0 = off)
//   --max-drift-deg  upper bound of the adapted random walk (deg/frame)
//   --initial-sigma-deg  prior sigma of the first pose's attitude (deg; default 0.1, since VO
//                 starts at the ground-truth pose)
//   --write-poses also write every run's poses and the ground truth as KITTI pose files
//                 (route_<id>_gt.txt, route_<id>_run<i>.txt; run 0 is pure VO, then the sources)

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/experiment/experiment.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/report/report_files.hpp"

namespace {

using sunvo::experiment::Route;
using sunvo::experiment::RunResult;

int usage(const std::string& msg) {
  std::fprintf(stderr, "sunvo_experiment: %s\n", msg.c_str());
  std::fprintf(stderr,
               "usage: sunvo_experiment [--data DIR] [--out DIR] [--routes 0020,00,06] "
               "[--frames N] [--every N] [--seed N] [--drift-deg D] [--sun-loss S] [--paper-form] "
               "[--write-poses] [--fixed-drift] [--drift-rule persistence|median|fixed] "
               "[--innovation-gate X] [--initial-sigma-deg S] [--max-drift-deg M]\n");
  return 2;
}

bool parseInt(const char* text, int& out) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < 0 || v > 1'000'000) return false;
  out = static_cast<int>(v);
  return true;
}

std::vector<std::string> splitComma(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

double pctChange(double base, double value) {
  return 100.0 * (value - base) / base;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = SUNVO_DEFAULT_DATA_DIR;
  std::string out_dir = "experiment_out";
  std::string routes_arg = "0020,00,06";
  int frames = 0, every = 5, seed = 1;
  double drift_deg = -1.0, sun_loss = -1.0;
  bool paper_form = false;
  bool write_poses = false;
  bool fixed_drift = false;
  std::string drift_rule;
  double initial_sigma_deg = -1.0;
  double max_drift_deg = -1.0;
  double innovation_gate = -1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--help" || a == "-h") {
      usage("help");
      return 0;
    } else if (a == "--data" && has_value) {
      data_dir = argv[++i];
    } else if (a == "--out" && has_value) {
      out_dir = argv[++i];
    } else if (a == "--routes" && has_value) {
      routes_arg = argv[++i];
    } else if (a == "--frames" && has_value) {
      if (!parseInt(argv[++i], frames)) return usage("--frames needs a count >= 0");
    } else if (a == "--every" && has_value) {
      if (!parseInt(argv[++i], every) || every < 1) return usage("--every needs a count >= 1");
    } else if (a == "--drift-deg" && has_value) {
      drift_deg = std::strtod(argv[++i], nullptr);
    } else if (a == "--sun-loss" && has_value) {
      sun_loss = std::strtod(argv[++i], nullptr);
    } else if (a == "--paper-form") {
      paper_form = true;
    } else if (a == "--write-poses") {
      write_poses = true;
    } else if (a == "--max-drift-deg" && has_value) {
      max_drift_deg = std::strtod(argv[++i], nullptr);
    } else if (a == "--initial-sigma-deg" && has_value) {
      initial_sigma_deg = std::strtod(argv[++i], nullptr);
    } else if (a == "--drift-rule" && has_value) {
      drift_rule = argv[++i];
    } else if (a == "--fixed-drift") {
      fixed_drift = true;
    } else if (a == "--innovation-gate" && has_value) {
      innovation_gate = std::strtod(argv[++i], nullptr);
    } else if (a == "--seed" && has_value) {
      if (!parseInt(argv[++i], seed)) return usage("--seed needs a number >= 0");
    } else {
      return usage("unknown or incomplete argument '" + a + "'");
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return usage("cannot create output folder '" + out_dir + "': " + ec.message());

  sunvo::experiment::ExperimentOptions options;
  options.every_n_frames = every;
  options.max_frames = frames;
  // A replay is bounded by solver iterations only: a wall-clock limit would make the result
  // depend on the machine's load. (The onboard program keeps its time budget.)
  options.vo.window.max_solver_time_in_seconds = 60.0;
  if (drift_deg >= 0.0) options.fusion.attitude_drift_deg_per_frame = drift_deg;
  if (sun_loss >= 0.0) options.fusion.loss_scale = sun_loss;
  options.fusion.estimate_base_attitude = !paper_form;
  if (fixed_drift) options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kFixed;
  if (initial_sigma_deg >= 0.0) options.fusion.initial_attitude_sigma_deg = initial_sigma_deg;
  if (max_drift_deg >= 0.0) options.fusion.max_drift_deg_per_frame = max_drift_deg;
  if (drift_rule == "median") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kInnovationMedian;
  } else if (drift_rule == "fixed") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kFixed;
  } else if (drift_rule != "persistence" && !drift_rule.empty()) {
    return usage("--drift-rule needs persistence, median or fixed");
  }
  if (innovation_gate >= 0.0) options.fusion.innovation_gate_chi2 = innovation_gate;
  if (auto s = options.validate(); !s.isOk()) return usage(s.toString());
  const auto sources = sunvo::experiment::defaultSunSources(static_cast<std::uint32_t>(seed));

  std::string summary =
      "| route | source | final drift [m] | change | rot. ARMSE [1e-3] | change | "
      "sun accepted / offered |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& id : splitComma(routes_arg)) {
    sunvo::Expected<Route> route = [&]() -> sunvo::Expected<Route> {
      if (id == "0020") return sunvo::experiment::loadRealTrackRoute0020(data_dir);
      sunvo::experiment::SimulatedRouteOptions sim;
      sim.seed = static_cast<std::uint32_t>(seed) + 6;
      return sunvo::experiment::loadSimulatedKittiRoute(data_dir, id, sim);
    }();
    if (!route) {
      std::fprintf(stderr, "sunvo_experiment: route %s: %s\n", id.c_str(),
                   route.status().toString().c_str());
      return 2;
    }
    std::fprintf(stderr, "route %s: %zu frames\n", route->name.c_str(), route->frames.size());
    std::vector<RunResult> runs;
    for (std::size_t s = 0; s <= sources.size(); ++s) {
      std::optional<sunvo::experiment::SunSourceSpec> spec;
      if (s > 0) spec = sources[s - 1];
      auto run = sunvo::experiment::runRoute(*route, spec, options);
      if (!run) {
        std::fprintf(stderr, "sunvo_experiment: %s: %s\n", route->name.c_str(),
                     run.status().toString().c_str());
        return 1;
      }
      std::fprintf(stderr, "  %-28s done (%.2f ms/frame median, %d lost)\n", run->name.c_str(),
                   run->median_ms, run->lost_frames);
      runs.push_back(std::move(*run));
    }
    sunvo::report::ReportInput input;
    input.gt_path = route->name;
    input.num_poses = runs.front().T_w_c.size();
    input.gt_times_source = "recorded frame times";
    input.plane = sunvo::metrics::HorizontalPlane::kCameraXZ;
    std::vector<sunvo::report::PlotSeries> series;
    for (const RunResult& r : runs) {
      input.estimates.push_back({r.name, "", r.evaluation});
      series.push_back({r.name, r.T_w_c});
    }
    const std::vector<sunvo::Isometry3> gt(
        route->T_w_c_gt.begin(),
        route->T_w_c_gt.begin() + static_cast<std::ptrdiff_t>(input.num_poses));
    if (write_poses) {
      const auto write = [&](const std::string& name, const std::vector<sunvo::Isometry3>& T) {
        sunvo::files::Trajectory t;
        t.T_w_c = T;
        t.t_ns.resize(T.size());
        return sunvo::files::writeKittiPoses(out_dir + "/route_" + id + "_" + name + ".txt", t);
      };
      if (auto s = write("gt", gt); !s.isOk()) return usage(s.toString());
      for (std::size_t i = 0; i < runs.size(); ++i) {
        if (auto s = write("run" + std::to_string(i), runs[i].T_w_c); !s.isOk()) {
          return usage(s.toString());
        }
      }
    }
    auto table = sunvo::report::writeRouteReport(out_dir + "/route_" + id, input, gt, series);
    if (!table) return usage(table.status().toString());
    std::printf("\n### %s (%zu frames, %.0f m)\n\n%s", route->name.c_str(), input.num_poses,
                runs.front().evaluation.table1.gt_path_length_m, table->c_str());
    const auto& base = runs.front().evaluation.table1;
    for (const RunResult& r : runs) {
      const auto& t = r.evaluation.table1;
      char line[512];
      std::snprintf(line, sizeof(line),
                    "| %s | %s | %.2f | %+.0f %% | %.2f | %+.0f %% | %llu / %llu |\n", id.c_str(),
                    r.name.c_str(), t.final_drift_m, pctChange(base.final_drift_m, t.final_drift_m),
                    t.rot_armse_rad * 1e3, pctChange(base.rot_armse_rad, t.rot_armse_rad),
                    static_cast<unsigned long long>(r.gate.accepted),
                    static_cast<unsigned long long>(r.gate.total()));
      summary += line;
    }
  }
  std::printf("\n### Summary (change against pure VO on the same tracks)\n\n%s", summary.c_str());
  if (auto s = sunvo::files::writeWholeFile(out_dir + "/summary.md", summary); !s.isOk()) {
    return usage(s.toString());
  }
  std::printf(
      "\nwrote %s/{route_*_table1.md, route_*_metrics.json, route_*_topview.png, summary.md}\n",
      out_dir.c_str());
  return 0;
}
