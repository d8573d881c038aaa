#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sunvo/rover/config.hpp"

namespace sunvo::rover {
namespace {

std::string writeConfig(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::path(SUNVO_BINARY_DIR) / "test_out" / "rover_config";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

const char* kMinimal =
    "source:\n"
    "  kitti:\n"
    "    drive_dir: /data/drive_sync\n"
    "estimator:\n"
    "  window:\n"
    "    max_num_iterations: 12\n";

TEST(RoverConfig, TheShippedConfigsLoad) {
  auto replay = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover_replay.yaml");
  ASSERT_TRUE(replay) << replay.status().toString();
  EXPECT_EQ(replay->source.type, SourceType::kKitti);
  EXPECT_EQ(replay->trigger.type, TriggerType::kSimulated);
  EXPECT_EQ(replay->sun.provider, SunProviderType::kCsv);
  EXPECT_EQ(replay->source.kitti.end, EndAction::kHold);
  EXPECT_EQ(replay->frames.width, 1242);
  EXPECT_EQ(replay->rt.threads.capture.fifo_priority, 80);
  // The deployment file: V4L2 pair with the GPIO strobe; every image provider takes its grey
  // frames (Sun-CNN through the grey model the file names).
  auto rover = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml");
  ASSERT_TRUE(rover) << rover.status().toString();
  EXPECT_EQ(rover->source.type, SourceType::kV4l2);
  EXPECT_EQ(rover->trigger.type, TriggerType::kGpio);
  EXPECT_EQ(rover->sun.model, "/usr/share/sunvo/sun_cnn.onnx");  // installed by the .deb
  // The image estimator's azimuth error is a state of the fusion (docs/fusion_bias.md); the
  // replay file's true sun has none.
  EXPECT_EQ(rover->estimator.fusion.sun_bias_sigma_deg, 30.0);
  EXPECT_EQ(rover->estimator.fusion.sun_bias_length_frames, 2500.0);
  EXPECT_EQ(replay->estimator.fusion.sun_bias_sigma_deg, 0.0);
  // The vertical cue, in the sun thread, with time to answer (docs/vertical.md).
  EXPECT_TRUE(rover->estimator.vertical.enabled);
  EXPECT_GE(rover->realtime.sun_wait_ms, 20.0);
  // Its first three answers level the start (docs/start_levelling.md); the
  // replay file starts from the drive's OXTS pose and does not.
  EXPECT_EQ(rover->estimator.fusion.world_up_alignment_use,
            sunfusion::WorldUpAlignmentUse::kStartTilt);
  EXPECT_EQ(rover->estimator.fusion.world_up_alignment_frames, sunfusion::kStartTiltFrames);
  EXPECT_EQ(replay->estimator.fusion.world_up_alignment_frames, 0);
  auto bad_use = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                                 {{"estimator.fusion.world_up_alignment_use", "level"}});
  ASSERT_FALSE(bad_use);
  EXPECT_NE(bad_use.status().message().find("world_up_alignment_use"), std::string::npos)
      << bad_use.status().message();
  auto gray = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                              {{"sun.provider", "sun_cnn"}});
  EXPECT_TRUE(gray) << gray.status().toString();
  auto lalonde = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                                 {{"sun.provider", "lalonde_vo"}});
  EXPECT_TRUE(lalonde) << lalonde.status().toString();
  auto no_gpio = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                                 {{"trigger.type", "simulated"}});
  ASSERT_FALSE(no_gpio);
  EXPECT_NE(no_gpio.status().message().find("trigger.type"), std::string::npos);
}

TEST(RoverConfig, DefaultsAndOverrides) {
  const std::string path = writeConfig("minimal.yaml", kMinimal);
  auto c = loadRoverConfig(path, {{"realtime.deadline_ms", "80"},
                                  {"serial.device", "/dev/pts/9"},
                                  {"sun.provider", "csv"},
                                  {"sun.csv", "/data/sun.csv"},
                                  {"estimator.fusion.gate.plane", "xz"},
                                  {"estimator.frontend.max_features", "1500"},
                                  {"telemetry.frame", "ardupilot"},
                                  {"telemetry.position_sigma_per_m", "0.05"}});
  ASSERT_TRUE(c) << c.status().toString();
  EXPECT_EQ(c->telemetry.frame, mavlink::FrameProfile::kArduPilot);
  EXPECT_DOUBLE_EQ(c->telemetry.position_sigma_per_m, 0.05);
  EXPECT_DOUBLE_EQ(c->telemetry.origin_period_s, 10.0);  // default
  // The estimator section is the estimator's own options struct: its field names are the keys.
  EXPECT_EQ(c->estimator.pipeline.vo.window.max_num_iterations, 12);
  EXPECT_EQ(c->estimator.pipeline.vo.window.window_size, 2);  // default
  EXPECT_EQ(c->estimator.pipeline.frontend.max_features, 1500);
  EXPECT_EQ(c->estimator.fusion.gate.plane, sunfusion::GatePlane::kXZ);
  // The rover's defaults of the estimator: a 40 ms solver budget, the image estimators' cap.
  EXPECT_DOUBLE_EQ(c->estimator.pipeline.vo.window.max_solver_time_in_seconds, 0.040);
  EXPECT_DOUBLE_EQ(c->estimator.fusion.max_drift_deg_per_frame, 0.01);
  EXPECT_DOUBLE_EQ(c->estimator.fusion.vertical_max_drift_deg_per_frame, 0.2);  // the cue's
  EXPECT_EQ(c->realtime.deadline_ms, 80.0);
  EXPECT_EQ(c->serial.device, "/dev/pts/9");
  EXPECT_EQ(c->sun.csv, "/data/sun.csv");
  EXPECT_EQ(c->queues.frames, 4);
  // Every key is printed once, by the same list that reads it.
  const std::string text = c->describe();
  EXPECT_NE(text.find("  estimator.window.max_num_iterations: 12\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  estimator.fusion.gate.plane: xz\n"), std::string::npos);
  EXPECT_NE(text.find("  rt.threads.capture.fifo_priority: 80\n"), std::string::npos);
  EXPECT_NE(text.find("  source.kitti.end: stop\n"), std::string::npos);
  EXPECT_NE(text.find("  telemetry.frame: ardupilot\n"), std::string::npos);
  auto px4 = loadRoverConfig(path);
  ASSERT_TRUE(px4) << px4.status().toString();
  EXPECT_EQ(px4->telemetry.frame, mavlink::FrameProfile::kPx4);                // the default
  EXPECT_EQ(px4->estimator.pipeline.self_calibration.disparity_bias_px, 0.0);  // none entered
  // A rig's measured disparity bias (docs/disparity_bias.md), and one outside its range.
  auto biased = loadRoverConfig(path, {{"estimator.self_calibration.disparity_bias_px", "-0.37"}});
  ASSERT_TRUE(biased) << biased.status().toString();
  EXPECT_DOUBLE_EQ(biased->estimator.pipeline.self_calibration.disparity_bias_px, -0.37);
  auto too_big = loadRoverConfig(path, {{"estimator.self_calibration.disparity_bias_px", "7"}});
  ASSERT_FALSE(too_big);
  EXPECT_NE(too_big.status().message().find("self_calibration.disparity_bias_px"),
            std::string::npos)
      << too_big.status().message();
}

// The raw-calibration, colour and camera-mount keys (docs/deployment.md, "Stereo calibration"):
// read from the deployment file's V4L2 source, defaults that keep today's behaviour, and
// errors naming the key.
TEST(RoverConfig, CalibrationColourAndMountKeys) {
  const std::string rover = std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml";
  auto d = loadRoverConfig(rover);
  ASSERT_TRUE(d) << d.status().toString();
  EXPECT_EQ(d->source.v4l2.calibration_format, calib::CalibrationFormat::kAuto);
  EXPECT_DOUBLE_EQ(d->source.v4l2.rectify.alpha, 0.0);
  EXPECT_FALSE(d->source.v4l2.left_color);
  EXPECT_DOUBLE_EQ(d->body.camera_x_m, 0.0);
  auto c = loadRoverConfig(rover, {{"source.v4l2.calibration_format", "kalibr"},
                                   {"source.v4l2.rectify.alpha", "0.25"},
                                   {"source.v4l2.pixel_format", "yuyv"},
                                   {"source.v4l2.left_color", "true"},
                                   {"body.camera_pitch_deg", "-15"},
                                   {"body.camera_x_m", "0.42"},
                                   {"body.camera_z_m", "-0.3"}});
  ASSERT_TRUE(c) << c.status().toString();
  EXPECT_EQ(c->source.v4l2.calibration_format, calib::CalibrationFormat::kKalibr);
  EXPECT_DOUBLE_EQ(c->source.v4l2.rectify.alpha, 0.25);
  EXPECT_TRUE(c->source.v4l2.left_color);
  EXPECT_DOUBLE_EQ(c->body.camera_pitch_deg, -15.0);
  EXPECT_DOUBLE_EQ(c->body.camera_x_m, 0.42);
  EXPECT_DOUBLE_EQ(c->body.camera_z_m, -0.3);
  const std::string text = c->describe();
  EXPECT_NE(text.find("  source.v4l2.calibration_format: kalibr\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  source.v4l2.rectify.alpha: 0.25\n"), std::string::npos);
  EXPECT_NE(text.find("  body.camera_x_m: 0.42\n"), std::string::npos);

  const auto error = [&](const std::string& key, const std::string& value) {
    auto bad = loadRoverConfig(rover, {{key, value}});
    EXPECT_FALSE(bad) << key;
    return bad ? std::string() : bad.status().message();
  };
  EXPECT_NE(error("source.v4l2.calibration_format", "ros")
                .find("'ros' is not one of auto, kitti, "
                      "opencv, kalibr"),
            std::string::npos);
  EXPECT_NE(error("source.v4l2.rectify.alpha", "1.5").find("source.v4l2.rectify.alpha"),
            std::string::npos);
  EXPECT_NE(error("source.v4l2.left_color", "true").find("source.v4l2.left_color: needs"),
            std::string::npos);
  EXPECT_NE(error("body.camera_pitch_deg", "95").find("body.camera_pitch_deg"), std::string::npos);
  EXPECT_NE(error("body.camera_y_m", "200").find("body.camera_y_m"), std::string::npos);
}

// Found by fuzzing (tests/fuzz/fuzz_rover_yaml): a complex key ("? ...") made yaml-cpp throw out
// of the reader, which ended the program; it is an error naming the file, line and section.
TEST(RoverConfig, AComplexKeyIsAnErrorNotAnException) {
  const std::string top =
      writeConfig("complex_key.yaml", std::string(kMinimal) + "?  heap_reserve=mb: 64\n");
  auto t = loadRoverConfig(top);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message(), top + ":7: top level: a key must be a plain name");
  const std::string nested =
      writeConfig("complex_nested_key.yaml", std::string(kMinimal) + "  ? [a, b]\n  : 3\n");
  auto n = loadRoverConfig(nested);
  ASSERT_FALSE(n);
  EXPECT_EQ(n.status().message(), nested + ":7: estimator: a key must be a plain name");
}

TEST(RoverConfig, ErrorsNameTheFileTheKeyAndTheLine) {
  const std::string path = writeConfig("minimal.yaml", kMinimal);
  auto range = loadRoverConfig(path, {{"estimator.window.max_num_iterations", "0"}});
  ASSERT_FALSE(range);
  EXPECT_NE(range.status().message().find(path + ": estimator.window.max_num_iterations must be"),
            std::string::npos)
      << range.status().message();

  const std::string unknown = writeConfig("unknown.yaml", std::string(kMinimal) + "  bogus: 3\n");
  auto u = loadRoverConfig(unknown);
  ASSERT_FALSE(u);
  EXPECT_EQ(u.status().message(), unknown + ":7: estimator.bogus: unknown key");

  auto top = loadRoverConfig(path, {{"telemetri.heartbeat_hz", "1"}});
  ASSERT_FALSE(top);
  EXPECT_NE(top.status().message().find("telemetri: unknown key"), std::string::npos);

  const std::string typed =
      writeConfig("typed.yaml", std::string(kMinimal) + "  every_n_frames: often\n");
  auto t = loadRoverConfig(typed);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message(), typed + ":7: estimator.every_n_frames: expected an integer");

  auto frame = loadRoverConfig(path, {{"telemetry.frame", "mavros"}});
  ASSERT_FALSE(frame);
  EXPECT_NE(frame.status().message().find("telemetry.frame: 'mavros' is not one of px4, ardupilot"),
            std::string::npos)
      << frame.status().message();
  auto k = loadRoverConfig(path, {{"telemetry.position_sigma_per_m", "1.5"}});
  ASSERT_FALSE(k);
  EXPECT_NE(k.status().message().find("telemetry.position_sigma_per_m"), std::string::npos);

  auto e = loadRoverConfig(path, {{"source.kitti.end", "rewind"}});
  ASSERT_FALSE(e);
  EXPECT_NE(e.status().message().find("source.kitti.end: 'rewind' is not one of stop, hold, loop, "
                                      "pingpong"),
            std::string::npos);

  auto drift = loadRoverConfig(path, {{"estimator.fusion.max_drift_deg_per_frame", "0"}});
  ASSERT_FALSE(drift);
  EXPECT_NE(drift.status().message().find(
                path + ": estimator.fusion.min_drift_deg_per_frame / max_drift_deg_per_frame"),
            std::string::npos)
      << drift.status().message();
  EXPECT_NE(drift.status().message().find("max_drift_deg_per_frame"), std::string::npos);

  auto plane = loadRoverConfig(path, {{"estimator.fusion.gate.plane", "diagonal"}});
  ASSERT_FALSE(plane);
  EXPECT_NE(plane.status().message().find(
                "estimator.fusion.gate.plane: 'diagonal' is not one of full_3d, xz"),
            std::string::npos)
      << plane.status().message();

  auto budget = loadRoverConfig(path, {{"realtime.min_solver_time_ms", "50"}});
  ASSERT_FALSE(budget);
  EXPECT_NE(budget.status().message().find("realtime.min_solver_time_ms: 50 is outside [0.1, 40]"),
            std::string::npos)
      << budget.status().message();

  auto bad_frames = loadRoverConfig(path, {{"source.max_consecutive_bad_frames", "0"}});
  ASSERT_FALSE(bad_frames);
  EXPECT_NE(bad_frames.status().message().find("source.max_consecutive_bad_frames: 0 is outside"),
            std::string::npos)
      << bad_frames.status().message();

  auto q = loadRoverConfig(path, {{"queues.frames", "3"}});
  ASSERT_FALSE(q);
  EXPECT_NE(q.status().message().find("queues.frames: 3 is not a power of two"), std::string::npos);

  auto depth = loadRoverConfig(path, {{"queues.frames", "8"}});
  ASSERT_FALSE(depth);
  EXPECT_NE(depth.status().message().find("frames.pool_depth: 8 must be >= queues.frames + 2"),
            std::string::npos);

  auto missing = loadRoverConfig("/nonexistent/rover.yaml");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.status().message().find("/nonexistent/rover.yaml"), std::string::npos);

  const std::string broken = writeConfig("broken.yaml", "source: [1, 2\n");
  auto b = loadRoverConfig(broken);
  ASSERT_FALSE(b);
  EXPECT_NE(b.status().message().find(broken + ":"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::rover
