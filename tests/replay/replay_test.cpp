#include "sunvo/replay/replay.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "sunvo/core/geometry.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/render/drive.hpp"
#include "sunvo/sunestimators/sun_estimators.hpp"

namespace sunvo::replay {
namespace {

// The CI drive's first `frames` frames, rendered afresh into test_render_cache/<folder>, through
// `camera` when given (another rig). Returns the drive's folder.
Expected<std::string> renderCiDrive(int frames, const std::string& folder,
                                    const std::optional<StereoCamera>& camera = std::nullopt) {
  auto scenario =
      render::loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/ci_short.yaml");
  if (!scenario) return scenario.status();
  scenario->frames = frames;
  if (camera) scenario->camera = *camera;
  const auto out = std::filesystem::path(SUNVO_BINARY_DIR) / "test_render_cache" / folder;
  std::filesystem::remove_all(out);
  return render::renderDrive(*scenario, out.string(), 2, {});
}

// Renders the first 20 frames of the CI drive with POV-Ray, then replays them through the whole
// chain (KITTI raw source, OXTS, ENU world, SPA, image VO, sun fusion) and checks the accuracy
// against the renderer's ground truth. This is the regression test of the replay path.
TEST(Replay, RenderedDriveThroughTheWholeChain) {
  auto drive = renderCiDrive(20, "replay_20");
  ASSERT_TRUE(drive) << drive.status().toString();

  ReplayOptions options;
  options.dataset.path = *drive;
  // Solves bounded by iterations only, so that the replay is the same natively and under an
  // emulator (qemu-aarch64 is 10-30x slower: the default 0.05 s limit binds there).
  options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;
  auto data = openReplayDataset(options);
  ASSERT_TRUE(data) << data.status().toString();
  EXPECT_EQ(data->kind(), dataset::DatasetKind::kSunvoRender);
  ASSERT_EQ(data->groundTruth().size(), 20u);
  const std::vector<Isometry3>& gt = data->groundTruth();

  options.record_features = true;  // what sunvo_replay --write-tracks writes
  auto pure = replayDrive(*data, options, std::nullopt);
  options.record_features = false;
  ASSERT_TRUE(pure) << pure.status().toString();
  ASSERT_EQ(pure->T_w_c.size(), 20u);
  EXPECT_EQ(pure->lost_frames, 0);
  ASSERT_EQ(pure->features.size(), 20u);
  EXPECT_GT(pure->features.back().observations.size(), 100u);
  metrics::EvaluationOptions eval;
  eval.plane = metrics::HorizontalPlane::kEastNorth;
  auto ev = metrics::evaluate(gt, pure->T_w_c, eval);
  ASSERT_TRUE(ev) << ev.status().toString();
  // The first pose comes from OXTS + calibration: it must match the truth closely.
  EXPECT_LT((pure->T_w_c[0].translation() - gt[0].translation()).norm(), 0.01);
  EXPECT_LT(rotationAngle(pure->T_w_c[0].linear() * gt[0].linear().transpose()), 0.001);
  // Measured on this drive (20 frames): final drift 0.0145 m, rot. ARMSE 0.30e-3 rad.
  EXPECT_LT(ev->table1.final_drift_m, 0.1);
  EXPECT_LT(ev->table1.rot_armse_rad, 2e-3);

  // With the true sun the fusion runs (measurements offered every fifth frame) and stays accurate.
  const auto sources = experiment::defaultSunSources(1);
  auto sun = replayDrive(*data, options, sources[0]);
  ASSERT_TRUE(sun) << sun.status().toString();
  EXPECT_EQ(sun->gate.total(), 3u);  // frames 5, 10, 15
  EXPECT_EQ(sun->gate.accepted, 3u);
  auto ev_sun = metrics::evaluate(gt, sun->T_w_c, eval);
  ASSERT_TRUE(ev_sun);
  EXPECT_LT(ev_sun->table1.rot_armse_rad, 2e-3);
  EXPECT_LT(ev_sun->table1.final_drift_m, 0.1);

  // An image estimator inside the pipeline: Sun-CNN on the colour images of frames 5, 10, 15.
  auto cnn = sunestimators::makeSunEstimator("sun_cnn", SUNVO_SOURCE_DIR "/config/sun_cnn.onnx");
  ASSERT_TRUE(cnn) << cnn.status().toString();
  auto image_sun = replayDrive(*data, options, std::nullopt, cnn->get());
  ASSERT_TRUE(image_sun) << image_sun.status().toString();
  EXPECT_EQ(image_sun->name, "VO+Sun (sun_cnn)");
  EXPECT_EQ(image_sun->sun_calls, 3);
  ASSERT_EQ(image_sun->T_w_c.size(), 20u);
  for (const Isometry3& T : image_sun->T_w_c) ASSERT_TRUE(T.matrix().allFinite());
  EXPECT_FALSE(replayDrive(*data, options, sources[0], cnn->get()));  // one source at a time

  // Deterministic replay.
  auto again = replayDrive(*data, options, std::nullopt);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->T_w_c.back().matrix(), pure->T_w_c.back().matrix());

  // A start attitude 5 deg off in pitch, as a rover started with the wrong configured tilt. With
  // the INS's 0.1 deg start sigma the innovation gate refuses every answer of the vertical cue
  // that says so; levelling the start (fusion.world_up_alignment_use start_tilt) measures the
  // error from the answers of frames 5, 10, 15 and turns VO's world before frame 16.
  const auto finalTiltDeg = [&](const ReplayRun& run) {
    const Eigen::Vector3d up = data->worldUp();
    return angleBetween(run.T_w_c.back().linear().transpose() * up,
                        gt.back().linear().transpose() * up) *
           180.0 / M_PI;
  };
  ReplayOptions tilted = options;
  tilted.vertical.enabled = true;
  tilted.start_pitch_error_deg = 5.0;
  auto refused = replayDrive(*data, tilted, std::nullopt);
  ASSERT_TRUE(refused) << refused.status().toString();
  EXPECT_GE(refused->vertical_stats.valid, 3u);
  EXPECT_EQ(refused->vertical_gate.accepted, 0u);
  EXPECT_FALSE(refused->start_levelled);
  EXPECT_GT(finalTiltDeg(*refused), 4.8);
  tilted.fusion.world_up_alignment_use = sunfusion::WorldUpAlignmentUse::kStartTilt;
  tilted.world_up_alignment_frames = 10;
  auto levelled = replayDrive(*data, tilted, std::nullopt);
  ASSERT_TRUE(levelled) << levelled.status().toString();
  EXPECT_TRUE(levelled->start_levelled);
  EXPECT_EQ(levelled->world_up_answers, 3);
  // Measured (x86-64): 5.23 deg measured from the three answers, final tilt 0.25 deg (4.98 deg
  // without the levelling).
  EXPECT_NEAR(levelled->world_up_tilt_deg, 5.0, 0.5);
  EXPECT_LT(finalTiltDeg(*levelled), 0.5);
  EXPECT_EQ(levelled->world_up, data->worldUp());  // the world's up stays the known one
  // The positions built before the levelling turn with it: the end is where the truth is.
  EXPECT_LT((levelled->T_w_c.back().translation() - gt.back().translation()).norm(),
            0.5 * (refused->T_w_c.back().translation() - gt.back().translation()).norm());
  std::printf(
      "start pitched 5 deg: final tilt %.3f deg refused, %.3f deg levelled (%.3f measured)\n",
      finalTiltDeg(*refused), finalTiltDeg(*levelled), levelled->world_up_tilt_deg);

  std::printf(
      "replay of 20 rendered frames: drift %.4f m (pure) %.4f m (true sun), rot ARMSE %.3g / %.3g "
      "rad\n",
      ev->table1.final_drift_m, ev_sun->table1.final_drift_m, ev->table1.rot_armse_rad,
      ev_sun->table1.rot_armse_rad);

  // The same drive as a plain KITTI raw drive (images, OXTS, calibration; no gt/ folder): the
  // ground truth comes from the OXTS records, the true sun from the ephemeris once the
  // recording's offset to UTC is stated.
  const auto raw_day = std::filesystem::path(SUNVO_BINARY_DIR) / "test_render_cache" / "raw_20";
  std::filesystem::remove_all(raw_day);
  const std::filesystem::path drive_path(*drive);
  const auto raw_drive = raw_day / drive_path.parent_path().filename() / drive_path.filename();
  std::filesystem::create_directories(raw_drive.parent_path());
  std::filesystem::copy(
      drive_path.parent_path(), raw_drive.parent_path(),
      std::filesystem::copy_options::recursive | std::filesystem::copy_options::overwrite_existing);
  std::filesystem::remove_all(raw_drive / "gt");
  ReplayOptions raw_options;
  raw_options.dataset.path = raw_drive.string();
  raw_options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;
  auto raw = openReplayDataset(raw_options);
  ASSERT_TRUE(raw) << raw.status().toString();
  EXPECT_EQ(raw->kind(), dataset::DatasetKind::kKittiRaw);
  EXPECT_FALSE(raw->sunKnown());  // no zone stated: pure VO only
  EXPECT_FALSE(replayDrive(*raw, raw_options, sources[0]));
  auto raw_pure = replayDrive(*raw, raw_options, std::nullopt);
  ASSERT_TRUE(raw_pure) << raw_pure.status().toString();
  EXPECT_EQ(raw_pure->T_w_c.back().matrix(), pure->T_w_c.back().matrix());
  auto ev_raw = metrics::evaluate(raw->groundTruth(), raw_pure->T_w_c, eval);
  ASSERT_TRUE(ev_raw);
  // OXTS ground truth against the renderer's: the same drive to the OXTS files' precision.
  EXPECT_NEAR(ev_raw->table1.final_drift_m, ev->table1.final_drift_m, 1e-3);
  raw_options.dataset.utc_offset_s = 0;  // the renderer writes UTC
  auto raw_sun = openReplayDataset(raw_options);
  ASSERT_TRUE(raw_sun && raw_sun->sunKnown());
  for (std::size_t k = 0; k < raw_sun->size(); ++k) {
    EXPECT_LT((raw_sun->trueSun()[k].sun_c - data->trueSun()[k].sun_c).norm(), 1e-3) << k;
  }
  auto raw_true = replayDrive(*raw_sun, raw_options, sources[0]);
  ASSERT_TRUE(raw_true) << raw_true.status().toString();
  EXPECT_EQ(raw_true->gate.accepted, 3u);

  // Injected image faults: each bad frame is dropped and counted, VO matches the next good frame
  // against the last good one and goes on; the run stops only past the configured limit.
  const auto image = [&](int camera, int frame) {
    char name[64];
    std::snprintf(name, sizeof(name), "image_%02d/data/%010d.png", camera, frame);
    return (raw_drive / name).string();
  };
  std::filesystem::remove(image(0, 7));  // missing
  std::filesystem::resize_file(image(1, 8), std::filesystem::file_size(image(1, 8)) / 3);
  ASSERT_TRUE(cv::imwrite(image(0, 12), cv::Mat(100, 200, CV_8UC1, cv::Scalar(90))));   // size
  ASSERT_TRUE(cv::imwrite(image(1, 13), cv::Mat(375, 1242, CV_8UC3, cv::Scalar(90))));  // chans
  auto faulty = openReplayDataset(raw_options);
  ASSERT_TRUE(faulty) << faulty.status().toString();
  auto dropped = replayDrive(*faulty, raw_options, std::nullopt);
  ASSERT_TRUE(dropped) << dropped.status().toString();
  EXPECT_EQ(dropped->dropped_frames, 4);
  ASSERT_EQ(dropped->T_w_c.size(), 16u);
  const std::vector<std::size_t> kept{0, 1, 2, 3, 4, 5, 6, 9, 10, 11, 14, 15, 16, 17, 18, 19};
  EXPECT_EQ(dropped->frame_index, kept);
  std::vector<Isometry3> gt_kept;
  for (const std::size_t k : kept) gt_kept.push_back(faulty->groundTruth()[k]);
  auto ev_dropped = metrics::evaluate(gt_kept, dropped->T_w_c, eval);
  ASSERT_TRUE(ev_dropped) << ev_dropped.status().toString();
  std::printf("replay with 4 bad frames dropped: drift %.4f m, rot ARMSE %.3g rad, %d lost\n",
              ev_dropped->table1.final_drift_m, ev_dropped->table1.rot_armse_rad,
              dropped->lost_frames);
  // Bridging the two 2-frame gaps costs accuracy but no gross error. Measured (2026-11-25): x86-64
  // 0.040 m, 0.25e-3 rad; aarch64 0.176 m, 0.57e-3 rad on its own render of the drive (the scene
  // numbers differ in the last digits: its pure run drifts 0.0175 m against 0.0145 m here).
  EXPECT_LT(ev_dropped->table1.final_drift_m, 0.25);
  EXPECT_LT(ev_dropped->table1.rot_armse_rad, 2e-3);
  // The sun still comes on frames 5, 10, 15 (their own frame numbers).
  auto dropped_sun = replayDrive(*faulty, raw_options, sources[0]);
  ASSERT_TRUE(dropped_sun) << dropped_sun.status().toString();
  EXPECT_EQ(dropped_sun->gate.total(), 3u);
  // Frames 7 and 8 are two bad frames in a row: a limit of 1 stops the run at frame 8.
  raw_options.max_consecutive_bad_frames = 1;
  auto stopped = replayDrive(*faulty, raw_options, std::nullopt);
  ASSERT_FALSE(stopped);
  EXPECT_NE(stopped.status().message().find("frame 8"), std::string::npos)
      << stopped.status().message();
  EXPECT_NE(stopped.status().message().find("max_consecutive_bad_frames 1"), std::string::npos);
  // 0: every image must be there, as before.
  raw_options.max_consecutive_bad_frames = 0;
  auto strict = openReplayDataset(raw_options);
  ASSERT_FALSE(strict);
  EXPECT_NE(strict.status().message().find("frame 7: image file missing"), std::string::npos)
      << strict.status().message();
  raw_options.max_consecutive_bad_frames = -1;
  EXPECT_NE(raw_options.validate().message().find("replay.max_consecutive_bad_frames"),
            std::string::npos);
  std::filesystem::remove_all(raw_day);
}

// A drive from another rig: 640x480 images (taller than KITTI's 376 rows, which the front end's
// default buffers take) load and replay; the front end is sized from the drive, as the rover
// sizes it from its cameras (a 1280x720 drive was refused before).
TEST(Replay, ADriveOfAnotherRigSizesTheFrontEnd) {
  auto drive =
      renderCiDrive(6, "replay_640x480", StereoCamera{500.0, 500.0, 322.0, 236.0, 0.25, 640, 480});
  ASSERT_TRUE(drive) << drive.status().toString();

  ReplayOptions options;
  options.dataset.path = *drive;
  options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;
  ASSERT_LT(options.pipeline.frontend.max_height, 480);  // what the drive needs more of
  auto data = openReplayDataset(options);
  ASSERT_TRUE(data) << data.status().toString();
  EXPECT_EQ(data->camera().width, 640);
  EXPECT_EQ(data->camera().height, 480);
  auto run = replayDrive(*data, options, std::nullopt);
  ASSERT_TRUE(run) << run.status().toString();
  ASSERT_EQ(run->T_w_c.size(), 6u);
  EXPECT_EQ(run->lost_frames, 0);
  metrics::EvaluationOptions eval;
  eval.plane = metrics::HorizontalPlane::kEastNorth;
  auto ev = metrics::evaluate(data->groundTruth(), run->T_w_c, eval);
  ASSERT_TRUE(ev) << ev.status().toString();
  std::printf("640x480 rig, 6 frames: final drift %.3f m, rot. ARMSE %.3g rad\n",
              ev->table1.final_drift_m, ev->table1.rot_armse_rad);
  // Measured: 0.111 m over 5 m (a 0.25 m baseline at 500 px gives a third of KITTI's depth
  // precision); a lost or refused frame costs metres.
  EXPECT_LT(ev->table1.final_drift_m, 0.25);
  EXPECT_LT(ev->table1.rot_armse_rad, 2e-3);
}

TEST(Replay, MissingDriveIsAClearError) {
  ReplayOptions options;
  options.dataset.path = "/nonexistent/drive_sync";
  auto data = openReplayDataset(options);
  ASSERT_FALSE(data);
  EXPECT_NE(data.status().message().find("/nonexistent/drive_sync"), std::string::npos);
  options.every_n_frames = 0;
  EXPECT_NE(options.validate().message().find("replay.every_n_frames"), std::string::npos);
}

TEST(Replay, ImageEstimatorCapIsValidated) {
  ReplayOptions options;
  options.dataset.path = "d";
  EXPECT_TRUE(options.validate().isOk());
  options.image_max_drift_deg_per_frame = 0.5 * options.fusion.min_drift_deg_per_frame;
  EXPECT_NE(options.validate().message().find("replay.image_max_drift_deg_per_frame"),
            std::string::npos);
  options.image_max_drift_deg_per_frame = 6.0;
  EXPECT_FALSE(options.validate().isOk());
}

// The image estimators' bias state: on by default (docs/fusion_bias.md), applied to their fusion
// only, its ranges the fusion's own.
TEST(Replay, ImageEstimatorBiasStateIsTheirsAndValidated) {
  ReplayOptions options;
  options.dataset.path = "d";
  EXPECT_EQ(options.fusion.sun_bias_sigma_deg, 0.0);
  EXPECT_EQ(options.imageFusion().sun_bias_sigma_deg, 30.0);
  EXPECT_EQ(options.imageFusion().sun_bias_length_frames, 2500.0);
  options.image_sun_bias_sigma_deg = 50.0;
  EXPECT_NE(options.validate().message().find("sun_bias_sigma_deg"), std::string::npos);
  options.image_sun_bias_sigma_deg = 0.0;
  options.image_sun_bias_length_frames = 0.5;
  EXPECT_NE(options.validate().message().find("sun_bias_length_frames"), std::string::npos);
}

// A KITTI odometry sequence's world is its first camera, whose tilt nobody measured: the replay
// measures the world's up from the cue's first answers (docs/vertical.md) instead of taking the
// first camera's -y, unless told otherwise. The 11 real frames give the cue two frames (5, 10),
// both within the 50 frames of the alignment: they measure the up and correct nothing.
TEST(Replay, AFirstCameraWorldAlignsItsUpFromTheCue) {
  ReplayOptions options;
  options.dataset.path = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";
  options.pipeline.vo.window.max_solver_time_in_seconds = 10.0;
  options.vertical.enabled = true;
  auto data = openReplayDataset(options);
  ASSERT_TRUE(data) << data.status().toString();
  ASSERT_EQ(data->world(), dataset::WorldFrame::kFirstCamera);
  auto aligned = replayDrive(*data, options, std::nullopt);
  ASSERT_TRUE(aligned) << aligned.status().toString();
  ASSERT_GE(aligned->vertical_stats.valid, 1u);
  EXPECT_EQ(aligned->world_up_answers, static_cast<int>(aligned->vertical_stats.valid));
  EXPECT_EQ(aligned->vertical_gate.accepted, 0u);
  EXPECT_EQ(aligned->world_up, -Eigen::Vector3d::UnitY());  // fewer than 3 answers: not done

  options.world_up_alignment_frames = 0;  // the first camera's -y is up
  auto told = replayDrive(*data, options, std::nullopt);
  ASSERT_TRUE(told) << told.status().toString();
  EXPECT_EQ(told->world_up_answers, 0);
  EXPECT_EQ(told->vertical_gate.accepted, told->vertical_stats.valid);
  // The fusion's walks per frame; the tilt's from the bank (the default likelihood rule), within
  // its range, with the cue's noise scale within its own.
  ASSERT_EQ(told->walk_log.size(), told->T_w_c.size());
  const auto& last = told->walk_log.back();
  EXPECT_GE(last.tilt_deg, options.fusion.min_drift_deg_per_frame);
  EXPECT_LE(last.tilt_deg, options.fusion.vertical_max_drift_deg_per_frame);
  EXPECT_GT(last.bank_tilt_deg, 0.0);
  EXPECT_GE(last.noise_scale, options.fusion.likelihood_noise_min);
  EXPECT_LE(last.noise_scale, options.fusion.likelihood_noise_max);

  // Levelling the start needs a world whose up is known.
  options.fusion.world_up_alignment_use = sunfusion::WorldUpAlignmentUse::kStartTilt;
  auto level = replayDrive(*data, options, std::nullopt);
  ASSERT_FALSE(level);
  EXPECT_NE(level.status().message().find("levelling the start needs a world whose up is known"),
            std::string::npos)
      << level.status().message();

  options.world_up_alignment_frames = -2;
  EXPECT_NE(options.validate().message().find("replay.world_up_alignment_frames"),
            std::string::npos);
  options.world_up_alignment_frames = 0;
  options.start_roll_error_deg = 31.0;
  EXPECT_NE(
      options.validate().message().find("replay.start_pitch_error_deg / start_roll_error_deg"),
      std::string::npos);
}

}  // namespace
}  // namespace sunvo::replay
