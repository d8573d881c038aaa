// sunvo_replay: replays a drive with images (a KITTI raw drive, a sunvo render, a KITTI odometry
// sequence; see drivers/dataset) through the whole chain — images, ground truth, world, SPA sun,
// image VO with sun residuals — for pure VO and VO + each sun source, and prints the paper's
// Table 1 with a top-view plot. --help lists the options.

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/replay/replay.hpp"
#include "sunvo/report/report_files.hpp"
#include "sunvo/sunestimators/sun_estimators.hpp"

namespace {

constexpr const char* kProgram = "sunvo_replay";

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
  std::string model = SUNVO_DEFAULT_SUN_CNN_MODEL;
  int seed = 1;
  int frames = 0;
  bool write_poses = false;
  bool error_models = true;
  std::vector<std::string> estimator_names;
  CLI::App app{"Replays a drive through the whole chain: pure VO against VO + sun, Table 1.",
               kProgram};
  app.add_option("--drive", options.dataset.path,
                 "the drive: KITTI raw drive, sunvo_render output or KITTI odometry sequence")
      ->required();
  app.add_option("--utc-offset-s", options.dataset.utc_offset_s,
                 "offset of the drive's timestamps to UTC, s (KITTI raw names no zone: e.g. 7200 "
                 "for CEST; a render writes UTC)")
      ->check(CLI::Range(-50400, 50400));
  app.add_option("--out", out_dir, "output folder (created)");
  app.add_option("--frames", frames, "first N frames (0 = all)")->check(CLI::Range(0, 10000000));
  app.add_option("--every", options.every_n_frames, "a sun measurement every N-th frame")
      ->check(CLI::Range(1, 1000));
  app.add_option("--seed", seed, "seed of the error-model sun sources")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--drift-deg", options.fusion.attitude_drift_deg_per_frame,
                 "start value of the attitude random walk, deg/frame")
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--max-drift-deg", options.fusion.max_drift_deg_per_frame,
                 "cap of the adapted random walk, deg/frame (error-model sources)")
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--image-max-drift-deg", options.image_max_drift_deg_per_frame,
                 "the same for the image estimators")
      ->check(CLI::Range(0.0, 5.0));
  sunvo::cli::addBiasStateOptions(
      app, options.image_sun_bias_sigma_deg, options.image_sun_bias_length_frames, "image-",
      "the image estimators' azimuth bias state: its std, deg (0 = none)");
  sunvo::cli::addBiasStateOptions(app, options.fusion);
  app.add_option("--max-bad-frames", options.max_consecutive_bad_frames,
                 "bad frames (missing or corrupt image) dropped in a row before the run stops; "
                 "0 = stop at the first")
      ->check(CLI::Range(0, 100000));
  bool paper_form = false;
  app.add_flag("--paper-form", paper_form, "hold the base attitude fixed, as the paper did");
  bool vertical = false;
  app.add_flag("--vertical", vertical,
               "also a run with the vertical vanishing-point cue alone (\"VO+vertical\", no sun), "
               "and each image estimator once more with it");
  sunvo::cli::addEnumOption(app, "--vertical-detector", options.vertical.estimator.detector,
                            "the cue's segment detector (default edge_chains; lsd: OpenCV's, the "
                            "baseline)");
  app.add_option("--vertical-line-sigma-deg", options.vertical.estimator.line_sigma_deg,
                 "the cue's error of one segment's plane angle, which sets its reported sigma, deg")
      ->check(CLI::Range(0.001, 10.0));
  bool isotropic_vertical = false;
  app.add_flag("--vertical-isotropic", isotropic_vertical,
               "the cue reports its worse direction's sigma for both (per_axis_sigma off, as "
               "before 2026-11-28)");
  sunvo::cli::addEnumOption(
      app, "--vertical-drift-rule", options.fusion.vertical_drift_adaptation,
      "how the tilt's walk follows the cue: likelihood (default), persistence or "
      "evidence (docs/vertical.md)");
  sunvo::cli::addEnumOption(app, "--heading-drift-rule", options.fusion.heading_drift_adaptation,
                            "how the heading's walk follows the sun: persistence (default) or "
                            "likelihood (a walk bank, docs/vertical.md)");
  sunvo::cli::addTiltWalkRangeOptions(app, options.fusion);
  app.add_option("--world-up-alignment-frames", options.world_up_alignment_frames,
                 "the cue's answers of the first N frames measure the world's up (-1: 50 when the "
                 "world is the first camera, which nobody levelled; 0 in ENU)")
      ->check(CLI::Range(-1, 100000));
  bool level_start = false;
  sunvo::cli::addStartTiltOptions(app, options.start_pitch_error_deg, options.start_roll_error_deg,
                                  level_start);
  app.add_option("--initial-sigma-deg", options.fusion.initial_attitude_sigma_deg,
                 "the start attitude's std, deg (0.1: the first OXTS record's; the rover's 1)")
      ->check(CLI::Range(0.001, 45.0));
  bool self_calib = false;
  app.add_flag("--self-calib", self_calib,
               "online stereo self-calibration of the right camera (measures the right rows); its "
               "estimate per frame in OUT/self_calibration_<run>.csv");
  sunvo::cli::addSelfCalibrationOptions(app, options.pipeline.self_calibration);
  app.add_flag("--measure-right-rows", options.pipeline.frontend.measure_v_right,
               "the front end measures each match's right row and column by a 2-D step "
               "(frontend.measure_v_right; on with --self-calib), without the self-calibration");
  app.add_flag("--correct-edge-columns", options.pipeline.frontend.correct_edge_columns,
               "matches along edges get their column moved by the rig's row offset there "
               "(frontend.correct_edge_columns; needs --measure-right-rows or --self-calib)");
  sunvo::cli::addWindowPriorOptions(app, options.pipeline.vo.window);
  app.add_option("--estimators", estimator_names,
                 "also VO + sun from these image estimators: lalonde, lalonde_vo, sun_cnn")
      ->delimiter(',')
      ->check(CLI::IsMember({"lalonde", "lalonde_vo", "sun_cnn", "none"}));
  app.add_flag("!--no-error-models", error_models,
               "skip the error-model sun sources (pure VO and the image estimators only)");
  app.add_option("--model", model, "the Sun-CNN ONNX model");
  std::string tracks_dir;
  app.add_option("--write-tracks", tracks_dir,
                 "also write the pure VO run's front-end tracks (before any self-calibration) as a "
                 "track folder DIR (calib.txt, times.txt, tracks.csv, gt_poses.txt, and "
                 "sun_cam.csv when the drive knows the sun) for the track-mode tools "
                 "(sunvo_track_vo, sunvo_track_stats, sunvo_experiment)");
  app.add_flag(
      "--poses", write_poses,
      "also write each run's poses, OUT/replay_poses_<run>.txt (KITTI) and _tum.txt (TUM)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  options.fusion.estimate_base_attitude = !paper_form;
  if (isotropic_vertical) options.vertical.estimator.per_axis_sigma = false;
  if (level_start) {
    options.fusion.world_up_alignment_use = sunvo::sunfusion::WorldUpAlignmentUse::kStartTilt;
  }
  if (self_calib) {
    options.pipeline.frontend.measure_v_right = true;
    options.pipeline.self_calibration.enabled = true;
  }
  if (frames > 0) options.dataset.last_frame = frames - 1;
  std::erase(estimator_names, "none");
  if (auto s = options.validate(); !s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.toString().c_str());
    return sunvo::cli::kExitUsage;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return sunvo::cli::fail(kProgram, "cannot create '" + out_dir + "': " + ec.message());

  auto data = sunvo::replay::openReplayDataset(options);
  if (!data) return sunvo::cli::fail(kProgram, data.status());
  std::fprintf(stderr, "%s\n", data->describe().c_str());
  if (!data->hasGroundTruth()) {
    return sunvo::cli::fail(kProgram,
                            options.dataset.path + ": no ground truth to evaluate against");
  }
  std::vector<std::optional<sunvo::experiment::SunSourceSpec>> specs{std::nullopt};
  if (error_models && data->sunKnown()) {
    for (const auto& s : sunvo::experiment::defaultSunSources(static_cast<std::uint32_t>(seed))) {
      specs.emplace_back(s);
    }
  } else if (error_models) {
    std::fprintf(stderr, "%s: no error-model sun sources: %s\n", kProgram,
                 data->sunUnknownReason().c_str());
  }
  sunvo::report::ReportInput input;
  input.gt_path = data->folder() + " (" + sunvo::dataset::toString(data->kind()) + " ground truth)";
  input.gt_times_source = "the drive's frame times";
  input.plane = data->world() == sunvo::dataset::WorldFrame::kEnu
                    ? sunvo::metrics::HorizontalPlane::kEastNorth
                    : sunvo::metrics::HorizontalPlane::kCameraXZ;
  std::vector<sunvo::report::PlotSeries> series;
  std::vector<sunvo::Isometry3> gt;
  auto estimators = sunvo::sunestimators::makeSunEstimators(estimator_names, model);
  if (!estimators) return sunvo::cli::fail(kProgram, estimators.status());
  // Runs: pure VO, then with --vertical VO+vertical, the error-model sources, the image
  // estimators, and with --vertical each image estimator once more with the vertical cue.
  struct Planned {
    const sunvo::experiment::SunSourceSpec* spec = nullptr;
    sunvo::sunfusion::ImageSunEstimator* image = nullptr;
    bool vertical = false;
  };
  std::vector<Planned> plan = {{}};
  if (vertical) plan.push_back({nullptr, nullptr, true});
  for (std::size_t i = 1; i < specs.size(); ++i) plan.push_back({&*specs[i], nullptr, false});
  for (const auto& e : *estimators) plan.push_back({nullptr, e.get(), false});
  if (vertical) {
    for (const auto& e : *estimators) plan.push_back({nullptr, e.get(), true});
  }
  sunvo::replay::ReplayOptions vertical_options = options;
  vertical_options.vertical.enabled = true;
  const Eigen::Vector3d up_w = data->worldUp();
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const Planned& p = plan[i];
    sunvo::replay::ReplayOptions run_options = p.vertical ? vertical_options : options;
    run_options.record_features = i == 0 && !tracks_dir.empty();
    std::optional<sunvo::experiment::SunSourceSpec> spec;
    if (p.spec != nullptr) spec = *p.spec;
    auto run = sunvo::replay::replayDrive(*data, run_options, spec, p.image);
    if (!run) return sunvo::cli::fail(kProgram, run.status());
    // The ground truth of the frames processed (dropped frames have no pose).
    gt.clear();
    for (const std::size_t k : run->frame_index) gt.push_back(data->groundTruth()[k]);
    if (run_options.record_features) {
      std::filesystem::create_directories(tracks_dir, ec);
      if (ec) {
        return sunvo::cli::fail(kProgram, "cannot create '" + tracks_dir + "': " + ec.message());
      }
      const sunvo::Isometry3 T_0_w = gt.front().inverse();
      std::vector<sunvo::Isometry3> gt_T_0_k;
      for (const sunvo::Isometry3& T_w_k : gt) gt_T_0_k.push_back(T_0_w * T_w_k);
      if (auto s =
              sunvo::files::writeTrackFolder(tracks_dir, data->camera(), run->features, gt_T_0_k);
          !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
      // The true sun of the same frames (when the drive knows it): the folder is then a route of
      // sunvo_experiment.
      if (data->sunKnown() && data->trueSun().size() == data->size()) {
        sunvo::files::SunCsv sun;
        for (const std::size_t k : run->frame_index) sun.sun_c.push_back(data->trueSun()[k].sun_c);
        if (auto s = sunvo::files::writeSunCsv(tracks_dir + "/sun_cam.csv", sun); !s.isOk()) {
          return sunvo::cli::fail(kProgram, s);
        }
      }
      std::fprintf(stderr,
                   "wrote %s/{calib.txt,times.txt,tracks.csv,gt_poses.txt[,sun_cam.csv]} (%zu "
                   "frames)\n",
                   tracks_dir.c_str(), run->features.size());
    }
    sunvo::metrics::EvaluationOptions eval_opt;
    eval_opt.plane = input.plane;
    auto ev = sunvo::metrics::evaluate(gt, run->T_w_c, eval_opt);
    if (!ev) return sunvo::cli::fail(kProgram, ev.status());
    std::fprintf(stderr,
                 "  %-28s %zu frames, %.1f ms/frame median, %.1f p99, %d lost, %d dropped (bad "
                 "image), sun %llu/%llu (%llu with the sun down)\n",
                 run->name.c_str(), run->T_w_c.size(), run->median_ms, run->p99_ms,
                 run->lost_frames, run->dropped_frames,
                 static_cast<unsigned long long>(run->gate.accepted),
                 static_cast<unsigned long long>(run->gate.total()),
                 static_cast<unsigned long long>(run->gate.rejected_sun_down));
    if (auto tilt = sunvo::metrics::computeTilt(gt, run->T_w_c, up_w)) {
      constexpr double kToDeg = 180.0 / 3.141592653589793;
      std::fprintf(stderr,
                   "  %-28s attitude error: tilt (roll/pitch) %.3f deg RMS, %.3f final; heading "
                   "%.3f deg RMS, %.3f final\n",
                   "", tilt->tilt_rms_rad * kToDeg, tilt->tilt_final_rad * kToDeg,
                   tilt->heading_rms_rad * kToDeg, tilt->heading_final_rad * kToDeg);
    }
    if (run->vertical_stats.calls > 0) {
      std::fprintf(stderr,
                   "  %-28s vertical cue: %llu calls, %llu valid, %llu accepted, %llu errors\n", "",
                   static_cast<unsigned long long>(run->vertical_stats.calls),
                   static_cast<unsigned long long>(run->vertical_stats.valid),
                   static_cast<unsigned long long>(run->vertical_gate.accepted),
                   static_cast<unsigned long long>(run->vertical_stats.errors));
    }
    if (run->start_tilt_judged) {
      std::fprintf(stderr, "  %-28s start tilt error %.3f deg measured from %d cue answers %s\n",
                   "", run->world_up_tilt_deg, run->world_up_answers,
                   sunvo::sunfusion::startTiltOutcome(run->start_levelled));
    } else if (run->world_up_answers > 0) {
      std::fprintf(stderr,
                   "  %-28s world's up (%.4f, %.4f, %.4f) from %d cue answers: %.3f deg off the "
                   "assumed one\n",
                   "", run->world_up.x(), run->world_up.y(), run->world_up.z(),
                   run->world_up_answers, run->world_up_tilt_deg);
    }
    if (self_calib) {
      // Per frame: OUT/self_calibration_<run>.csv (the right camera's estimate after each frame).
      std::string csv = sunvo::selfcal::kReportCsvHeader;
      for (std::size_t f = 0; f < run->self_calibration_log.size(); ++f) {
        csv += sunvo::selfcal::reportCsvRow(run->frame_index[f], run->self_calibration_log[f]);
      }
      const std::string path = out_dir + "/self_calibration_" + fileSlug(run->name) + ".csv";
      if (auto s = sunvo::files::writeWholeFile(path, csv); !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
      const auto& sc = run->self_calibration;
      std::fprintf(stderr,
                   "  %-28s self-calibration: right pitch %+.4f deg, roll %+.4f deg (sigma "
                   "%.4f), scale %+.2e, %llu resets\n",
                   "", sc.pitch_mrad * 0.180 / 3.141592653589793,
                   sc.roll_mrad * 0.180 / 3.141592653589793,
                   sc.roll_sigma_mrad * 0.180 / 3.141592653589793, sc.scale,
                   static_cast<unsigned long long>(sc.resets));
    }
    if (!run->walk_log.empty()) {
      // Per frame: OUT/attitude_walk_<run>.csv (the fusion's walks and the cue's bias state after
      // each frame).
      std::string csv =
          "frame,tilt_walk_deg_per_frame,heading_walk_deg_per_frame,bank_tilt_walk_deg_per_frame,"
          "cue_noise_scale,up_bias_x_deg,up_bias_z_deg\n";
      char line[200];
      for (std::size_t f = 0; f < run->walk_log.size(); ++f) {
        const auto& w = run->walk_log[f];
        std::snprintf(line, sizeof(line), "%zu,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f\n",
                      run->frame_index[f], w.tilt_deg, w.heading_deg, w.bank_tilt_deg,
                      w.noise_scale, w.up_bias_x_deg, w.up_bias_z_deg);
        csv += line;
      }
      const std::string path = out_dir + "/attitude_walk_" + fileSlug(run->name) + ".csv";
      if (auto s = sunvo::files::writeWholeFile(path, csv); !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
    }
    if (run->sun_calls > 0) {
      std::fprintf(stderr, "  %-28s %d estimator calls, %.1f ms median, %.1f ms p90\n", "",
                   run->sun_calls, sunvo::metrics::percentile(run->sun_ms, 0.5),
                   sunvo::metrics::percentile(run->sun_ms, 0.9));
    }
    if (write_poses) {
      sunvo::files::Trajectory trajectory;
      trajectory.T_w_c = run->T_w_c;
      trajectory.t_ns = run->times_ns;
      const std::string base = out_dir + "/replay_poses_" + fileSlug(run->name);
      if (auto s = sunvo::files::writeTrajectoryFiles(base, trajectory); !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
      if (i == 0) {
        trajectory.T_w_c = gt;
        if (auto s = sunvo::files::writeTrajectoryFiles(out_dir + "/replay_poses_ground_truth",
                                                        trajectory);
            !s.isOk()) {
          return sunvo::cli::fail(kProgram, s);
        }
      }
    }
    input.num_poses = run->T_w_c.size();
    input.estimates.push_back({run->name, "", *ev});
    series.push_back({run->name, run->T_w_c});
  }
  auto table = sunvo::report::writeRouteReport(out_dir + "/replay", input, gt, series);
  if (!table) return sunvo::cli::fail(kProgram, table.status());
  std::printf(
      "\n### Replay of %s (%zu frames, %.0f m%s)\n\n%s", options.dataset.path.c_str(),
      input.num_poses, input.estimates.front().evaluation.table1.gt_path_length_m,
      specs.size() > 1 ? "; sun measurements from the ground truth through error models" : "",
      table->c_str());
  std::printf("\nwrote %s/replay_{table1.md,metrics.json,topview.png}\n", out_dir.c_str());
  return 0;
}
