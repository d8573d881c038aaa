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
    "    max_iterations: 12\n";

TEST(RoverConfig, TheShippedConfigsLoad) {
  auto replay = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover_replay.yaml");
  ASSERT_TRUE(replay) << replay.status().toString();
  EXPECT_EQ(replay->source.type, SourceType::kKitti);
  EXPECT_EQ(replay->trigger.type, TriggerType::kSimulated);
  EXPECT_EQ(replay->sun.provider, SunProviderType::kCsv);
  EXPECT_EQ(replay->source.kitti.end, EndAction::kHold);
  EXPECT_EQ(replay->frames.width, 1242);
  EXPECT_EQ(replay->rt.capture.fifo_priority, 80);
  // The deployment file: V4L2 pair with the GPIO strobe; Sun-CNN is refused there (the V4L2
  // source delivers gray and the CNN needs colour), naming the key; Lalonde takes gray.
  auto rover = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml");
  ASSERT_TRUE(rover) << rover.status().toString();
  EXPECT_EQ(rover->source.type, SourceType::kV4l2);
  EXPECT_EQ(rover->trigger.type, TriggerType::kGpio);
  EXPECT_EQ(rover->sun.model, "/etc/sunvo/sun_cnn.onnx");
  auto gray = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                              {{"sun.provider", "sun_cnn"}});
  ASSERT_FALSE(gray);
  EXPECT_NE(gray.status().message().find("sun.provider: sun_cnn"), std::string::npos)
      << gray.status().message();
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
  auto c = loadRoverConfig(path, {{"estimator.deadline_ms", "80"},
                                  {"serial.device", "/dev/pts/9"},
                                  {"sun.provider", "csv"},
                                  {"sun.csv", "/data/sun.csv"}});
  ASSERT_TRUE(c) << c.status().toString();
  EXPECT_EQ(c->estimator.max_iterations, 12);
  EXPECT_EQ(c->estimator.deadline_ms, 80.0);
  EXPECT_EQ(c->estimator.window_size, 2);  // default
  EXPECT_EQ(c->serial.device, "/dev/pts/9");
  EXPECT_EQ(c->sun.csv, "/data/sun.csv");
  EXPECT_EQ(c->queues.frames, 4);
  EXPECT_FALSE(c->describe().empty());
}

TEST(RoverConfig, ErrorsNameTheFileTheKeyAndTheLine) {
  const std::string path = writeConfig("minimal.yaml", kMinimal);
  auto range = loadRoverConfig(path, {{"estimator.window.max_iterations", "0"}});
  ASSERT_FALSE(range);
  EXPECT_EQ(range.status().message(),
            path + ": estimator.window.max_iterations: 0 is outside [1, 100]");

  const std::string unknown = writeConfig("unknown.yaml", std::string(kMinimal) + "  bogus: 3\n");
  auto u = loadRoverConfig(unknown);
  ASSERT_FALSE(u);
  EXPECT_EQ(u.status().message(), unknown + ":7: estimator.bogus: unknown key");

  auto top = loadRoverConfig(path, {{"telemetri.heartbeat_hz", "1"}});
  ASSERT_FALSE(top);
  EXPECT_NE(top.status().message().find("telemetri: unknown key"), std::string::npos);

  const std::string typed =
      writeConfig("typed.yaml", std::string(kMinimal) + "  deadline_ms: fast\n");
  auto t = loadRoverConfig(typed);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message(), typed + ":7: estimator.deadline_ms: expected a number");

  auto e = loadRoverConfig(path, {{"source.kitti.end", "rewind"}});
  ASSERT_FALSE(e);
  EXPECT_NE(e.status().message().find("source.kitti.end: 'rewind' is not one of stop, hold, loop, "
                                      "pingpong"),
            std::string::npos);

  auto drift = loadRoverConfig(path, {{"sun.max_drift_deg_per_frame", "0"}});
  ASSERT_FALSE(drift);
  EXPECT_EQ(drift.status().message(),
            path + ": sun.max_drift_deg_per_frame: 0 is outside [0.002, 5]");

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
