// sunvo_experiment: the paper's experiment in one command. Pure VO against VO + sun from several
// sun sources (the true vector and error models emulating Lalonde, Lalonde-VO and Sun-CNN), on the
// real 2011_09_30_drive_0020 feature tracks and on simulated tracks along the real routes 00 and
// 06 (any route by --routes: a KITTI odometry sequence id or a dataset path, see loadRoute). Per
// route: a Table-1-style markdown table and JSON, and a top-view plot (PNG). --help lists the
// options.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/experiment/attitude_oracle.hpp"
#include "sunvo/experiment/experiment.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/report/report_files.hpp"

namespace {

using sunvo::experiment::Route;
using sunvo::experiment::RunResult;
constexpr const char* kProgram = "sunvo_experiment";

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

// A file-name-safe id of a route spec: "0020", "00", or the last path component.
std::string routeId(const std::string& spec) {
  std::string id = std::filesystem::path(spec).filename().string();
  if (id.empty()) id = std::filesystem::path(spec).parent_path().filename().string();
  for (char& c : id) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) c = '_';
  }
  return id;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = SUNVO_DEFAULT_DATA_DIR;
  std::string out_dir = "experiment_out";
  std::string routes_arg = "0020,00,06";
  int frames = 0, every = 5, seed = 1;
  std::optional<double> drift_deg, sun_loss, initial_sigma_deg, max_drift_deg, innovation_gate;
  std::optional<double> evidence_sigmas, evidence_correlation, max_correction_deg;
  double sun_bias_deg = 0.0, sun_bias_length = 50.0, sun_offset_deg = 0.0;
  bool paper_form = false;
  bool write_poses = false;
  bool fixed_drift = false;
  bool self_calib = false;
  sunvo::experiment::ExperimentOptions options;
  std::string drift_rule = "persistence";
  std::string forms_arg = "sunvo";
  CLI::App app{
      "The paper's experiment: pure VO against VO + sun from several sun sources, per route. "
      "VO assumes the KITTI car (the sideways non-holonomic row with a 0.88 m lever arm; "
      "--lateral-prior 0 for none).",
      kProgram};
  app.add_option("--data", data_dir, "folder of the real data (shared/data layout)");
  app.add_option("--out", out_dir, "output folder (created)");
  app.add_option("--routes", routes_arg,
                 "comma-separated routes: 0020 (real tracks), a KITTI odometry id (00..10: "
                 "DATA/kitti_odometry/NN_*), or a dataset path");
  app.add_option("--frames", frames, "first N frames of each route (0 = all)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--every", every, "a sun measurement every N-th frame")
      ->check(CLI::Range(1, 1000));
  app.add_option("--seed", seed, "seed of the simulated tracks and the error models")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--drift-deg", drift_deg,
                 "attitude random walk per frame, deg (its start value when it adapts)")
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--sun-loss", sun_loss, "Cauchy scale on the whitened sun residual (0 = none)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_flag("--paper-form", paper_form,
               "hold the base attitude fixed, as the paper did (same as --forms paper)");
  app.add_option("--forms", forms_arg,
                 "comma-separated fusion forms, each a column per source: sunvo (the base "
                 "attitude is estimated), paper (held fixed, as the paper did)");
  app.add_flag("--fixed-drift", fixed_drift, "keep the random walk at --drift-deg");
  sunvo::cli::setKittiCarVehicle(options.vo.window);  // the KITTI car's lever arm (cli.hpp)
  sunvo::cli::addWindowPriorOptions(app, options.vo.window);
  bool vertical = false;
  // The vertical-like source (docs/vertical.md): 1 deg per axis, as the cue's spread on real
  // KITTI frames; 10 % of 8 deg outliers; half the cue frames without an answer.
  sunvo::sunfusion::VerticalErrorModel vertical_model;
  vertical_model.outlier_share = 0.1;
  vertical_model.dropout_share = 0.5;
  app.add_flag("--vertical", vertical,
               "also every run with a simulated \"up\" cue on the every-n frames (the vertical "
               "vanishing point's error model, docs/vertical.md)");
  app.add_option("--vertical-sigma-deg", vertical_model.sigma_deg, "its per-axis error, deg")
      ->check(CLI::Range(0.0, 30.0));
  app.add_option("--vertical-reported-sigma-deg", vertical_model.reported_sigma_deg,
                 "the sigma written into its measurements, deg")
      ->check(CLI::Range(0.0, 30.0));
  app.add_option("--vertical-outliers", vertical_model.outlier_share,
                 "share of its measurements turned by 8 deg instead")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--vertical-dropout", vertical_model.dropout_share,
                 "share of its frames without a measurement")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--true-up-pitch-deg", options.true_up_pitch_deg,
                 "the route's gravity turned from its first camera's -y about x, deg: what the "
                 "simulated \"up\" measures (the fusion is told -y)")
      ->check(CLI::Range(-30.0, 30.0));
  app.add_option("--true-up-roll-deg", options.true_up_roll_deg, "the same about z, deg")
      ->check(CLI::Range(-30.0, 30.0));
  // The simulated "up" is the first camera's -y unless --true-up-* say otherwise, so by default
  // there is nothing to align (sunvo_replay aligns a first-camera world's images by default).
  app.add_option("--world-up-alignment-frames", options.fusion.world_up_alignment_frames,
                 "the \"up\" answers of the first N frames measure the world's up (default 0: "
                 "the first camera's -y is up; 50: sunvo_replay's for a first-camera world)")
      ->check(CLI::Range(0, 100000));
  bool level_start = false;
  sunvo::cli::addStartTiltOptions(app, options.start_pitch_error_deg, options.start_roll_error_deg,
                                  level_start);
  app.add_flag("--self-calib", self_calib,
               "online stereo self-calibration of the right camera before the odometry");
  sunvo::cli::addSelfCalibrationOptions(app, options.self_calibration);
  app.add_option("--drift-rule", drift_rule, "how the random walk adapts")
      ->check(CLI::IsMember({"persistence", "median", "fixed", "evidence"}));
  sunvo::cli::addEnumOption(app, "--vertical-drift-rule", options.fusion.vertical_drift_adaptation,
                            "how the tilt's walk follows the \"up\" (persistence rule, split): "
                            "likelihood (default), persistence or evidence (docs/vertical.md)");
  sunvo::cli::addEnumOption(app, "--heading-drift-rule", options.fusion.heading_drift_adaptation,
                            "how the heading's walk follows the sun (split): persistence (default) "
                            "or likelihood (a walk bank, docs/vertical.md)");
  sunvo::cli::addTiltWalkRangeOptions(app, options.fusion);
  app.add_flag("!--no-split-drift", options.fusion.split_drift_by_gravity,
               "persistence rule: one random walk for all axes (before 2026-11-26), not one for "
               "the tilt and one for the heading");
  app.add_option("--evidence-sigmas", evidence_sigmas,
                 "evidence rule: sigmas an error must reach before P covers it")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--evidence-correlation", evidence_correlation,
                 "evidence rule: the sources' error correlation length, measurements")
      ->check(CLI::Range(1.0, 1000.0));
  app.add_option("--sun-bias-deg", sun_bias_deg,
                 "give the estimator-like sources a correlated azimuth error of this std, deg "
                 "(a Gauss-Markov process, docs/fusion_bias.md)")
      ->check(CLI::Range(0.0, 90.0));
  app.add_option("--sun-bias-length", sun_bias_length,
                 "its correlation length, measurements (50 = 250 frames at --every 5)")
      ->check(CLI::Range(1.0, 1e6));
  app.add_option("--sun-offset-deg", sun_offset_deg,
                 "give the estimator-like sources a constant azimuth error, deg (a source biased "
                 "for a whole drive)")
      ->check(CLI::Range(-180.0, 180.0));
  sunvo::cli::addBiasStateOptions(app, options.fusion);
  app.add_option("--max-correction-deg", max_correction_deg,
                 "refuse a measurement that would turn the attitude more, deg (0 = off)")
      ->check(CLI::Range(0.0, 180.0));
  app.add_option("--innovation-gate", innovation_gate,
                 "chi-square bound of the innovation gate (0 = off)")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--initial-sigma-deg", initial_sigma_deg,
                 "prior sigma of the first pose's attitude, deg (default 0.1: VO starts at the "
                 "ground-truth pose)")
      ->check(CLI::Range(0.0, 45.0));
  app.add_option("--max-drift-deg", max_drift_deg,
                 "upper bound of the adapted random walk, deg/frame")
      ->check(CLI::Range(0.0, 5.0));
  app.add_flag(
      "--write-poses", write_poses,
      "also write every run's poses and the ground truth as KITTI and TUM files "
      "(route_<id>_gt, route_<id>_run<i>; run 0 is pure VO, then the sources, each in every form)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec)
    return sunvo::cli::fail(kProgram,
                            "cannot create output folder '" + out_dir + "': " + ec.message());

  options.every_n_frames = every;
  options.max_frames = frames;
  options.self_calibration.enabled = self_calib;
  // A replay is bounded by solver iterations only: a wall-clock limit would make the result
  // depend on the machine's load. (The onboard program keeps its time budget.)
  options.vo.window.max_solver_time_in_seconds = 60.0;
  if (drift_deg) options.fusion.attitude_drift_deg_per_frame = *drift_deg;
  if (sun_loss) options.fusion.loss_scale = *sun_loss;
  if (paper_form) forms_arg = "paper";
  const std::vector<std::string> forms = splitComma(forms_arg);
  for (const std::string& f : forms) {
    if (f != "sunvo" && f != "paper") {
      std::fprintf(stderr, "%s: --forms: unknown form '%s' (sunvo, paper)\n", kProgram, f.c_str());
      return sunvo::cli::kExitUsage;
    }
  }
  if (forms.empty()) {
    std::fprintf(stderr, "%s: --forms: no form given\n", kProgram);
    return sunvo::cli::kExitUsage;
  }
  if (initial_sigma_deg) options.fusion.initial_attitude_sigma_deg = *initial_sigma_deg;
  if (level_start) {
    options.fusion.world_up_alignment_use = sunvo::sunfusion::WorldUpAlignmentUse::kStartTilt;
    if (options.fusion.world_up_alignment_frames == 0) {
      options.fusion.world_up_alignment_frames = sunvo::sunfusion::kStartTiltFrames;
    }
  }
  if (max_drift_deg) options.fusion.max_drift_deg_per_frame = *max_drift_deg;
  if (drift_rule == "persistence") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kPersistence;
  } else if (drift_rule == "median") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kInnovationMedian;
  } else if (drift_rule == "fixed") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kFixed;
  } else if (drift_rule == "evidence") {
    options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kEvidence;
  }
  if (fixed_drift) options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kFixed;
  if (evidence_sigmas) options.fusion.evidence_sigmas = *evidence_sigmas;
  if (evidence_correlation) options.fusion.evidence_correlation = *evidence_correlation;
  if (max_correction_deg) options.fusion.max_correction_deg = *max_correction_deg;
  if (innovation_gate) options.fusion.innovation_gate_chi2 = *innovation_gate;
  if (auto s = options.validate(); !s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.toString().c_str());
    return sunvo::cli::kExitUsage;
  }
  auto sources = sunvo::experiment::defaultSunSources(static_cast<std::uint32_t>(seed));
  for (auto& src : sources) {
    if (src.model.azimuth_sigma_deg == 0.0) continue;  // the true vector stays exact
    src.model.azimuth_bias_deg = sun_bias_deg;
    src.model.azimuth_bias_length = sun_bias_length;
    src.model.azimuth_offset_deg = sun_offset_deg;
  }
  vertical_model.seed = static_cast<std::uint32_t>(seed) + 10;  // the sun sources use seed..seed+3

  std::string summary =
      "| route | source | final drift [m] | change | rot. ARMSE [1e-3] | change | "
      "sun accepted / offered | tilt RMS [deg] | change |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const std::string& route_spec : splitComma(routes_arg)) {
    const std::string id = routeId(route_spec);
    sunvo::experiment::SimulatedRouteOptions sim;
    sim.seed = static_cast<std::uint32_t>(seed) + 6;
    sunvo::Expected<Route> route = sunvo::experiment::loadRoute(route_spec, data_dir, sim);
    if (!route)
      return sunvo::cli::fail(kProgram, "route " + route_spec + ": " + route.status().toString());
    std::fprintf(stderr, "route %s: %zu frames; %s\n", route->name.c_str(), route->frames.size(),
                 route->source.c_str());
    std::vector<RunResult> runs;
    // Pure VO, then every source in every form (the paper's columns marked when both are shown).
    // With --vertical, each run once more with the simulated "up" cue.
    struct Planned {
      std::optional<sunvo::experiment::SunSourceSpec> spec;
      bool paper = false;
      bool vertical = false;
    };
    std::vector<Planned> plan = {{std::nullopt, false, false}};
    if (vertical) plan.push_back({std::nullopt, false, true});
    for (const auto& src : sources) {
      for (const std::string& f : forms) {
        sunvo::experiment::SunSourceSpec spec = src;
        if (f == "paper" && forms.size() > 1) spec.name += " paper form";
        plan.push_back({spec, f == "paper", false});
        if (vertical) plan.push_back({spec, f == "paper", true});
      }
    }
    for (const auto& [spec, paper, with_vertical] : plan) {
      sunvo::experiment::ExperimentOptions run_options = options;
      run_options.fusion.estimate_base_attitude = !paper;
      // An exact source has no correlated error to model.
      if (spec && spec->model.azimuth_sigma_deg == 0.0) run_options.fusion.sun_bias_sigma_deg = 0.0;
      if (with_vertical) run_options.vertical = vertical_model;
      auto run = sunvo::experiment::runRoute(*route, spec, run_options);
      if (!run) return sunvo::cli::fail(kProgram, route->name + ": " + run.status().toString());
      std::fprintf(stderr, "  %-28s done (%.2f ms/frame median, %d lost)\n", run->name.c_str(),
                   run->median_ms, run->lost_frames);
      if (with_vertical) {
        const sunvo::sunfusion::GateCounters& g = run->vertical_gate;
        std::fprintf(stderr,
                     "    \"up\": %llu accepted, refused %llu by the gate, %llu by the innovation "
                     "gate\n",
                     static_cast<unsigned long long>(g.accepted),
                     static_cast<unsigned long long>(g.rejected_cosine + g.rejected_vertical +
                                                     g.rejected_invalid),
                     static_cast<unsigned long long>(g.rejected_innovation));
      }
      if (run->start_tilt_judged) {
        std::fprintf(stderr, "    start tilt error %.3f deg measured from %d answers %s\n",
                     run->start_tilt_deg, run->world_up_answers,
                     sunvo::sunfusion::startTiltOutcome(run->start_levelled));
      } else if (run->world_up_answers > 0) {
        std::fprintf(stderr, "    world's up from %d answers: %.3f deg from the true one\n",
                     run->world_up_answers, run->world_up_error_deg);
      }
      if (self_calib) {
        std::fprintf(stderr,
                     "    self-calibration: right camera roll %.4f mrad, pitch %.4f mrad, "
                     "%llu resets\n",
                     run->selfcal_roll_mrad, run->selfcal_pitch_mrad,
                     static_cast<unsigned long long>(run->selfcal_resets));
      }
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
        t.t_ns.assign(route->times_ns.begin(),
                      route->times_ns.begin() + static_cast<std::ptrdiff_t>(T.size()));
        return sunvo::files::writeTrajectoryFiles(out_dir + "/route_" + id + "_" + name, t);
      };
      if (auto s = write("gt", gt); !s.isOk()) return sunvo::cli::fail(kProgram, s);
      for (std::size_t i = 0; i < runs.size(); ++i) {
        if (auto s = write("run" + std::to_string(i), runs[i].T_w_c); !s.isOk()) {
          return sunvo::cli::fail(kProgram, s);
        }
      }
    }
    auto table = sunvo::report::writeRouteReport(out_dir + "/route_" + id, input, gt, series);
    if (!table) return sunvo::cli::fail(kProgram, table.status());
    std::printf("\n### %s (%zu frames, %.0f m)\n\n%s", route->name.c_str(), input.num_poses,
                runs.front().evaluation.table1.gt_path_length_m, table->c_str());
    const auto& base = runs.front().evaluation.table1;
    const double base_tilt = runs.front().tilt.tilt_rms_rad;
    // One summary row: the change of each number against pure VO's.
    const auto addRow = [&](const std::string& name, const sunvo::metrics::Table1Metrics& t,
                            const std::string& sun_counts, double tilt_rms_rad) {
      constexpr double kToDeg = 180.0 / 3.141592653589793;
      char line[512];
      std::snprintf(line, sizeof(line),
                    "| %s | %s | %.2f | %+.0f %% | %.2f | %+.0f %% | %s | %.3f | %+.0f %% |\n",
                    id.c_str(), name.c_str(), t.final_drift_m,
                    pctChange(base.final_drift_m, t.final_drift_m), t.rot_armse_rad * 1e3,
                    pctChange(base.rot_armse_rad, t.rot_armse_rad), sun_counts.c_str(),
                    tilt_rms_rad * kToDeg, pctChange(base_tilt, tilt_rms_rad));
      summary += line;
    };
    for (const RunResult& r : runs) {
      addRow(r.name, r.evaluation.table1,
             std::to_string(r.gate.accepted) + " / " + std::to_string(r.gate.total()),
             r.tilt.tilt_rms_rad);
    }
    // What any attitude source could gain here: pure VO's steps re-chained with the true attitude,
    // its tilt or its heading (docs/fusion_ceiling.md); rot. ARMSE and tilt of the re-chained
    // poses.
    const Eigen::Vector3d true_up_w = sunvo::experiment::trueUpWorld(*route, options);
    for (const auto which : {sunvo::experiment::AttitudeOracle::kTrueAttitude,
                             sunvo::experiment::AttitudeOracle::kTrueTilt,
                             sunvo::experiment::AttitudeOracle::kTrueHeading}) {
      auto T = sunvo::experiment::withTrueAttitude(runs.front().T_w_c, gt, true_up_w, which);
      if (!T) return sunvo::cli::fail(kProgram, T.status());
      sunvo::metrics::EvaluationOptions eval_opt;
      eval_opt.plane = sunvo::metrics::HorizontalPlane::kCameraXZ;
      auto ev = sunvo::metrics::evaluate(gt, *T, eval_opt);
      if (!ev) return sunvo::cli::fail(kProgram, ev.status());
      auto tilt = sunvo::metrics::computeTilt(gt, *T, true_up_w);
      if (!tilt) return sunvo::cli::fail(kProgram, tilt.status());
      addRow(sunvo::experiment::attitudeOracleName(which), ev->table1, "-", tilt->tilt_rms_rad);
    }
  }
  std::printf("\n### Summary (change against pure VO on the same tracks)\n\n%s", summary.c_str());
  if (auto s = sunvo::files::writeWholeFile(out_dir + "/summary.md", summary); !s.isOk()) {
    return sunvo::cli::fail(kProgram, s);
  }
  std::printf(
      "\nwrote %s/{route_*_table1.md, route_*_metrics.json, route_*_topview.png, summary.md}\n",
      out_dir.c_str());
  return 0;
}
