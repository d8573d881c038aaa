#include "sunvo/experiment/experiment.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

namespace sunvo::experiment {
namespace {

const std::string kData = SUNVO_DATA_DIR;

TEST(Experiment, RealTracksRouteLoadsWithTruthAndSun) {
  auto route = loadRoute("0020", kData, {});
  ASSERT_TRUE(route) << route.status().toString();
  EXPECT_EQ(route->frames.size(), 1000u);
  EXPECT_EQ(route->T_w_c_gt.size(), 1000u);
  ASSERT_EQ(route->sun_c_gt.size(), 1000u);
  // The true sun, rotated into the world by the true poses, stays nearly constant (data README).
  const Eigen::Vector3d s0 = route->T_w_c_gt[0].linear() * route->sun_c_gt[0];
  const Eigen::Vector3d s999 = route->T_w_c_gt[999].linear() * route->sun_c_gt[999];
  EXPECT_LT(std::acos(std::clamp(s0.dot(s999), -1.0, 1.0)) * 180.0 / M_PI, 1.5);
}

TEST(Experiment, TrueSunCutsRotationDriftOnRealTracks) {
  auto route = loadRoute("0020", kData, {});
  ASSERT_TRUE(route);
  ExperimentOptions opt;
  opt.max_frames = 400;
  opt.fusion.attitude_drift_deg_per_frame = 0.2;
  opt.fusion.drift_adaptation = sunfusion::DriftAdaptation::kFixed;
  // Replay mode: bounded by iterations only. A wall-clock limit makes results depend on load.
  opt.vo.window.max_solver_time_in_seconds = 60.0;
  auto pure = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(pure) << pure.status().toString();
  const auto sources = defaultSunSources(1);
  auto sun = runRoute(*route, sources[0], opt);  // the true vector
  ASSERT_TRUE(sun) << sun.status().toString();
  // Measured on the first 400 frames (sunvo_experiment --routes 0020 --frames 400
  // --drift-deg 0.2 --fixed-drift, 2026-11-30, with the window's step prior): rot. ARMSE
  // 32.35e-3 rad pure, 25.46e-3 rad with the true sun (ratio 0.787); final drift 4.89 m -> 2.35 m.
  EXPECT_LT(sun->evaluation.table1.rot_armse_rad, 0.85 * pure->evaluation.table1.rot_armse_rad);
  EXPECT_LT(sun->evaluation.table1.final_drift_m, 0.7 * pure->evaluation.table1.final_drift_m);
  EXPECT_EQ(sun->gate.accepted, 79u);  // every fifth frame from frame 5 to 395
  for (const auto& T : sun->T_w_c) ASSERT_TRUE(allFinite(T));
  // Deterministic: the same run twice gives the same poses.
  auto again = runRoute(*route, sources[0], opt);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->T_w_c.back().matrix(), sun->T_w_c.back().matrix());
}

// Route 06 with the simulated tracks and sources of `sunvo_experiment --seed S`: pure VO, the
// Sun-CNN-like source with `error` applied to its model under the default fusion ("followed"),
// and the same with `bias_state` applied to the fusion options ("kept").
struct BiasRuns {
  RunResult pure, followed, kept;
};
void runBiasCase(int seed, const std::function<void(sunfusion::SunErrorModel&)>& error,
                 const std::function<void(sunfusion::SunFusionOptions&)>& bias_state,
                 BiasRuns* out) {
  SimulatedRouteOptions sim;
  sim.seed = static_cast<std::uint32_t>(seed + 6);  // as sunvo_experiment --seed S
  auto route = loadRoute("06", kData, sim);
  ASSERT_TRUE(route) << route.status().toString();
  ExperimentOptions opt;
  opt.vo.window.max_solver_time_in_seconds = 60.0;
  SunSourceSpec cnn = defaultSunSources(static_cast<std::uint32_t>(seed))[3];
  ASSERT_EQ(cnn.name, "VO+Sun (Sun-CNN-like)");
  error(cnn.model);
  auto pure = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(pure) << pure.status().toString();
  auto followed = runRoute(*route, cnn, opt);
  ASSERT_TRUE(followed) << followed.status().toString();
  bias_state(opt.fusion);
  auto kept = runRoute(*route, cnn, opt);
  ASSERT_TRUE(kept) << kept.status().toString();
  *out = {std::move(*pure), std::move(*followed), std::move(*kept)};
}

// Issue 19, deliverable 2: a Sun-CNN-like source whose azimuth error stays alike for 50
// measurements (5 deg std, Gauss-Markov) drags the default fusion along; the bias state does not
// follow it. `sunvo_experiment --seed 2 --sun-bias-deg 5 [--bias-state-deg 5]` measured final
// drift 2.08 m (pure VO), 5.25 m (+152 %) and 2.04 m (docs/fusion_bias.md).
TEST(Experiment, TheBiasStateDoesNotFollowACorrelatedSourceError) {
  BiasRuns r;
  runBiasCase(
      2,
      [](sunfusion::SunErrorModel& m) {
        m.azimuth_bias_deg = 5.0;
        m.azimuth_bias_length = 50.0;
      },
      [](sunfusion::SunFusionOptions& f) { f.sun_bias_sigma_deg = 5.0; }, &r);
  if (HasFatalFailure()) return;
  const double d_pure = r.pure.evaluation.table1.final_drift_m;
  EXPECT_GT(r.followed.evaluation.table1.final_drift_m, 1.5 * d_pure);
  EXPECT_LT(r.kept.evaluation.table1.final_drift_m, 1.05 * d_pure);
  EXPECT_LT(r.kept.evaluation.table1.rot_armse_rad, 1.05 * r.pure.evaluation.table1.rot_armse_rad);
  EXPECT_GT(r.kept.gate.accepted, 150u);  // the measurements are used, not refused
}

// A source biased by the same angle for the whole drive (the Sun-CNN at -66 deg on a foreign
// generator's drive, issue 14): the default fusion takes its innovations for a heading drift and
// follows it; the image estimators' bias state (30 deg, 2500 frames: sunvo_replay's and the
// rover's defaults) does not. `sunvo_experiment --seed 1 --sun-offset-deg -66 [--bias-state-deg
// 30 --bias-state-frames 2500]`: final drift 4.30 m pure VO, 21.25 m (+394 %), 4.35 m (+1 %).
TEST(Experiment, TheBiasStateDoesNotFollowASourceBiasedForTheWholeDrive) {
  BiasRuns r;
  runBiasCase(
      1, [](sunfusion::SunErrorModel& m) { m.azimuth_offset_deg = -66.0; },
      [](sunfusion::SunFusionOptions& f) {
        f.sun_bias_sigma_deg = 30.0;
        f.sun_bias_length_frames = 2500.0;
      },
      &r);
  if (HasFatalFailure()) return;
  const double d_pure = r.pure.evaluation.table1.final_drift_m;
  EXPECT_GT(r.followed.evaluation.table1.final_drift_m, 2.0 * d_pure);
  EXPECT_LT(r.kept.evaluation.table1.final_drift_m, 1.05 * d_pure);
  EXPECT_LT(r.kept.evaluation.table1.rot_armse_rad, 1.05 * r.pure.evaluation.table1.rot_armse_rad);
  EXPECT_GT(r.kept.gate.accepted, 100u);
}

// The simulated "up" of the vertical tests: 1 deg per axis, 10 % outliers of 8 deg, half the
// frames without an answer.
sunfusion::VerticalErrorModel verticalLikeUp() {
  sunfusion::VerticalErrorModel up;
  up.outlier_share = 0.1;
  up.dropout_share = 0.5;
  up.seed = 11;
  return up;
}

// The start-tilt tests: route 06 (seed 7) with that "up", the rover's 1 deg start sigma, its first
// `frames` frames started pitched by `pitch_deg`; `level`: the rover's start levelling.
ExperimentOptions tiltedStart(int frames, double pitch_deg, bool level) {
  ExperimentOptions opt;
  opt.vo.window.max_solver_time_in_seconds = 60.0;
  opt.max_frames = frames;
  opt.fusion.initial_attitude_sigma_deg = 1.0;
  opt.start_pitch_error_deg = pitch_deg;
  opt.vertical = verticalLikeUp();
  if (level) {
    opt.fusion.world_up_alignment_use = sunfusion::WorldUpAlignmentUse::kStartTilt;
    opt.fusion.world_up_alignment_frames = sunfusion::kStartTiltFrames;
  }
  return opt;
}
Expected<Route> route06Seed7() {
  SimulatedRouteOptions sim;
  sim.seed = 7;
  return loadRoute("06", kData, sim);
}

// A first camera that was not level (1.2 deg pitch, -1.4 deg roll, the vertical cue's reading on
// the 11 real KITTI 00 frames): route 06 with `sunvo_experiment --seed 1 --vertical
// --true-up-pitch-deg 1.2 --true-up-roll-deg -1.4 [--world-up-alignment-frames 0]`. Told that
// the first camera's -y is up, the fusion turns the trajectory toward it (rot. ARMSE 5.48e-3 pure
// VO, 17.8e-3 with the "up"); with the world's up measured from the first 50 frames it is
// 4.69e-3, the up 0.27 deg from the truth (measured 2026-11-27).
TEST(Experiment, AnUnlevelledFirstCameraIsAlignedNotFollowed) {
  SimulatedRouteOptions sim;
  sim.seed = 7;
  auto route = loadRoute("06", kData, sim);
  ASSERT_TRUE(route) << route.status().toString();
  ExperimentOptions opt;
  opt.vo.window.max_solver_time_in_seconds = 60.0;
  auto pure = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(pure) << pure.status().toString();
  opt.vertical = verticalLikeUp();
  opt.true_up_pitch_deg = 1.2;
  opt.true_up_roll_deg = -1.4;
  auto told = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(told) << told.status().toString();
  opt.fusion.world_up_alignment_frames = sunfusion::kWorldUpAlignmentFrames;
  auto aligned = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(aligned) << aligned.status().toString();
  const double rot_pure = pure->evaluation.table1.rot_armse_rad;
  EXPECT_EQ(told->world_up_answers, 0);
  EXPECT_NEAR(told->world_up_error_deg, 1.84, 0.01);
  EXPECT_GT(told->evaluation.table1.rot_armse_rad, 2.0 * rot_pure);
  EXPECT_GE(aligned->world_up_answers, 3);
  EXPECT_LT(aligned->world_up_error_deg, 0.6);
  EXPECT_LT(aligned->evaluation.table1.rot_armse_rad, rot_pure);
}

// A rover started 8 deg off in pitch (its configured start tilt is not the ground's), with the
// rover's 1 deg start sigma: route 06's first 300 frames with the simulated "up" (1 deg, 10 %
// outliers of 8 deg, half the frames without an answer). Unlevelled, the innovation gate refuses
// the answers that say so until an outlier lets one in and the walk widens (measured 2026-12-03:
// tilt RMS 4.46 deg, final 1.10 deg); levelled from the first three answers (kStartTilt, 15
// frames, however late) the error is gone from then on (RMS 2.96 deg, all of it before the
// levelling; final 0.38 deg; 7.95 deg measured). The levelling restarts the tilt's walk bank:
// without that, with the tilt walk's cap at 0.2 deg/frame, the walks chosen on the answers that
// saw the 8 deg kept the tilt noisy afterwards (final 1.07 deg).
TEST(Experiment, AWrongStartTiltIsLevelledFromTheUp) {
  auto route = route06Seed7();
  ASSERT_TRUE(route) << route.status().toString();
  auto stuck = runRoute(*route, std::nullopt, tiltedStart(300, 8.0, false));
  ASSERT_TRUE(stuck) << stuck.status().toString();
  EXPECT_FALSE(stuck->start_levelled);
  auto levelled = runRoute(*route, std::nullopt, tiltedStart(300, 8.0, true));
  ASSERT_TRUE(levelled) << levelled.status().toString();
  EXPECT_TRUE(levelled->start_tilt_judged);
  EXPECT_TRUE(levelled->start_levelled);
  EXPECT_GE(levelled->world_up_answers, 3);
  EXPECT_NEAR(levelled->start_tilt_deg, 8.0, 1.0);
  EXPECT_LT(levelled->tilt.tilt_final_rad * 180.0 / M_PI, 0.6);
  EXPECT_LT(levelled->tilt.tilt_final_rad, stuck->tilt.tilt_final_rad);
  EXPECT_LT(levelled->tilt.tilt_rms_rad * 180.0 / M_PI + 1.0,
            stuck->tilt.tilt_rms_rad * 180.0 / M_PI);
  EXPECT_LT(levelled->world_up_error_deg, 1e-9);  // the world's up stays the known one
  std::printf(
      "start pitched 8 deg: tilt RMS %.3f / %.3f deg, final %.3f / %.3f deg unlevelled / "
      "levelled (%.3f measured from %d answers)\n",
      stuck->tilt.tilt_rms_rad * 180.0 / M_PI, levelled->tilt.tilt_rms_rad * 180.0 / M_PI,
      stuck->tilt.tilt_final_rad * 180.0 / M_PI, levelled->tilt.tilt_final_rad * 180.0 / M_PI,
      levelled->start_tilt_deg, levelled->world_up_answers);
}

// A 3 deg start the filter takes in from the first answers itself (the innovation gate's bound is
// about 5.7 deg with the rover's 1 deg start sigma and the up's 1 deg): the answers, fused as
// they come, leave a tilt within their mean's noise after 15 frames, which is judged and left to
// the filter. The run is the unlevelled one to the bit.
TEST(Experiment, AStartTiltTheFilterTakesIsLeftToIt) {
  auto route = route06Seed7();
  ASSERT_TRUE(route) << route.status().toString();
  auto plain = runRoute(*route, std::nullopt, tiltedStart(150, 3.0, false));
  ASSERT_TRUE(plain) << plain.status().toString();
  auto judged = runRoute(*route, std::nullopt, tiltedStart(150, 3.0, true));
  ASSERT_TRUE(judged) << judged.status().toString();
  EXPECT_TRUE(judged->start_tilt_judged);
  EXPECT_FALSE(judged->start_levelled);
  EXPECT_GE(judged->world_up_answers, 3);
  EXPECT_LT(judged->start_tilt_deg, 1.5);  // what the filter left of the 3 deg
  EXPECT_EQ(judged->T_w_c.back().matrix(), plain->T_w_c.back().matrix());
  std::printf("start pitched 3 deg: %.3f deg left after %d answers; tilt RMS %.3f deg\n",
              judged->start_tilt_deg, judged->world_up_answers,
              judged->tilt.tilt_rms_rad * 180.0 / M_PI);
}

// A start 12 deg off, beyond the vertical channel's 10 deg gate: no answer is fused, and the
// levelling measures it only because it collects up to start_tilt_max_deg (15); with that bound
// at 10 it sees nothing either.
TEST(Experiment, AStartBeyondTheCueGateIsMeasuredUpToItsOwnBound) {
  auto route = route06Seed7();
  ASSERT_TRUE(route) << route.status().toString();
  ExperimentOptions opt = tiltedStart(150, 12.0, true);
  opt.fusion.start_tilt_max_deg = 10.0;
  auto blind = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(blind) << blind.status().toString();
  EXPECT_FALSE(blind->start_levelled);
  EXPECT_GT(blind->tilt.tilt_final_rad * 180.0 / M_PI, 10.0);
  opt.fusion.start_tilt_max_deg = 15.0;
  auto levelled = runRoute(*route, std::nullopt, opt);
  ASSERT_TRUE(levelled) << levelled.status().toString();
  EXPECT_TRUE(levelled->start_levelled);
  EXPECT_NEAR(levelled->start_tilt_deg, 12.0, 1.5);
  EXPECT_LT(levelled->tilt.tilt_final_rad * 180.0 / M_PI, 1.0);
  std::printf(
      "start pitched 12 deg: final tilt %.3f deg unmeasured, %.3f deg levelled (%.3f "
      "measured)\n",
      blind->tilt.tilt_final_rad * 180.0 / M_PI, levelled->tilt.tilt_final_rad * 180.0 / M_PI,
      levelled->start_tilt_deg);
}

TEST(Experiment, SimulatedRouteUsesTheRealGroundTruthAndSun) {
  SimulatedRouteOptions sim;
  auto route = loadRoute("06", kData, sim);
  ASSERT_TRUE(route) << route.status().toString();
  EXPECT_EQ(route->frames.size(), 1101u);
  EXPECT_EQ(route->sun_c_gt.size(), 1101u);
  EXPECT_NEAR(route->camera.fu, 707.0912, 1e-6);
  EXPECT_EQ(route->name, "06 = 2011_09_30_drive_0020 (simulated tracks)");
  // Sequence 07 has a known rig but no files here; a folder that is no dataset fails too.
  EXPECT_FALSE(loadRoute("07", kData, sim));
  EXPECT_FALSE(loadRoute(kData + "/kitti_raw_sample", kData, sim));
}

TEST(Experiment, OptionsValidationNamesTheKey) {
  ExperimentOptions opt;
  opt.every_n_frames = 0;
  EXPECT_NE(opt.validate().message().find("experiment.every_n_frames"), std::string::npos);
  opt.every_n_frames = 5;
  opt.start_pitch_error_deg = -31.0;
  EXPECT_NE(opt.validate().message().find("experiment.start_pitch_error_deg"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::experiment
