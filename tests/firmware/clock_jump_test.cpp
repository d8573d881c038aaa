// A wall-clock jump while sunvo_rover runs on emulated hardware (the rig of rover_devices_test:
// two EmulatedV4l2 cameras, the strobe line of an EmulatedGpio chip, 20 Hz). Mid-run the UTC
// clock of the whole process is stepped one hour forward, later one hour back, through the
// program's UTC seam (runtime::injectUtcStep; every runtime::utcNowNs() sees it). Expected: the
// estimator keeps publishing finite poses through both jumps with no fault; each pose's UTC time
// (the time the sun ephemeris and the window get: capture hands the same ev.utc_ns to the frame
// and to the sun request) stays its strobe edge plus the offset taken at start, so no dt and no
// sun time jumps; the supervisor counts two jumps (+3600 s, -3600 s) and logs each as a warning.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <vector>

#include "../support/recording_link.hpp"
#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/supervisor.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {
namespace {

constexpr int kWidth = 1242;  // the size of the calibration used (kitti_raw_sample)
constexpr int kHeight = 375;
constexpr double kRateHz = 20.0;
constexpr int kStrobeLine = 17;
constexpr TimeNs kHour = 3'600'000'000'000;

emulated::FrameContent planeContent(const cv::Mat& texture, int disparity) {
  return [texture, disparity](std::uint64_t frame, cv::Mat& gray) {
    const int shift = static_cast<int>(frame % 100) * 2 + disparity;
    texture(cv::Rect(shift, 0, gray.cols, gray.rows)).copyTo(gray);
  };
}

std::string drain(int fd) {
  std::string out;
  char buf[4096];
  ssize_t n;
  while ((n = read(fd, buf, sizeof(buf))) > 0) out.append(buf, static_cast<std::size_t>(n));
  return out;
}

TEST(ClockJump, WallClockStepsBothWaysAreCountedAndNeitherPosesNorFrameTimesJump) {
  emulated::EmulatedGpio gpio;
  emulated::EmulatedV4l2 cameras;
  ASSERT_TRUE(gpio.addChip("gpiochip0", 32).isOk());
  cv::Mat texture(kHeight, kWidth + 260, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  ASSERT_TRUE(cameras
                  .addCamera({"/dev/sunvo-left", kWidth, kHeight, true, true, 0, 0,
                              planeContent(texture, 12)})
                  .isOk());
  ASSERT_TRUE(cameras
                  .addCamera({"/dev/sunvo-right", kWidth, kHeight, true, true, 0, 0,
                              planeContent(texture, 0)})
                  .isOk());
  const std::string out = std::string(SUNVO_BINARY_DIR) + "/test_out/clock_jump";
  std::filesystem::create_directories(out);
  auto config = loadRoverConfig(
      std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
      {{"source.v4l2.calibration",
        std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26/calib_cam_to_cam.txt"},
       {"trigger.rate_hz", std::to_string(kRateHz)},
       {"trigger.gpio_line", std::to_string(kStrobeLine)},
       {"trigger.frame_delay_ms", "3.0"},
       {"trigger.match_window_ms", "4.0"},
       {"serial.device", "\"\""},
       {"rt.lock_memory", "false"},
       {"rt.heap_reserve_mb", "0"},
       {"rt.threads",
        "{capture: {fifo_priority: 0, cpu: -1}, estimator: {fifo_priority: 0, "
        "cpu: -1}, sun: {fifo_priority: 0, cpu: -1}, telemetry: {fifo_priority: "
        "0, cpu: -1}}"},
       {"realtime.warmup_frames", "0"},
       {"sun.provider", "none"},
       {"telemetry.pose_log", "\"\""},
       {"health.fault_exit_s", "5.0"},
       {"health.watchdog_pose_age_s", "1.0"},
       {"profiling.output_dir", out}});
  ASSERT_TRUE(config.hasValue()) << config.status().toString();
  int log_pipe[2];
  ASSERT_EQ(pipe2(log_pipe, O_NONBLOCK), 0);
  runtime::EventLog log("sunvo_rover", log_pipe[1]);
  runtime::SdNotifier notifier;  // disabled: the watchdog is supervisor_test's subject

  auto link = std::make_unique<testing::RecordingLink>();
  testing::RecordingLink* recorder = link.get();
  auto app = RoverApp::create(*config, std::move(link), RoverDevices{&cameras, &gpio});
  ASSERT_TRUE(app.hasValue()) << app.status().toString();
  (*app)->start();
  Supervisor supervisor(**app, config->health, notifier, log, runtime::monotonicNs());
  supervisor.ready();

  std::atomic<bool> rig_stop{false};
  std::thread rig([&] {
    const auto period_ns = static_cast<TimeNs>(1e9 / kRateHz);
    const TimeNs t0 = runtime::monotonicNs() + 20'000'000;
    for (int k = 0; !rig_stop.load(); ++k) {
      const TimeNs edge = t0 + k * period_ns;
      runtime::sleepUntilMonotonicNs(edge);
      cameras.trigger(edge + 3'000'000);
      (void)gpio.strobe("gpiochip0", kStrobeLine, edge, 1'000'000);
    }
  });

  // Three phases of 1 s, the supervisor ticking every 20 ms as sunvo_rover's main thread does;
  // the wall clock steps +1 h before the second, -1 h before the third.
  bool fault = false;
  std::vector<std::uint64_t> poses_at;  // poses published when each phase ends
  std::vector<TimeNs> jump_mono;        // when each step was injected
  for (int phase = 0; phase < 3; ++phase) {
    if (phase > 0) {
      jump_mono.push_back(runtime::monotonicNs());
      runtime::injectUtcStep(phase == 1 ? kHour : -kHour);
    }
    const TimeNs until = runtime::monotonicNs() + 1'000'000'000;
    while (runtime::monotonicNs() < until) {
      EXPECT_FALSE(supervisor.tick(runtime::monotonicNs()).has_value());
      fault |= !supervisor.watch().healthy();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    poses_at.push_back((*app)->healthSample(runtime::monotonicNs()).poses_published);
  }
  rig_stop = true;
  rig.join();
  (*app)->requestStop();
  (*app)->join();
  EXPECT_EQ(runtime::injectedUtcStepNs(), 0);  // both steps undone
  const std::string events = drain(log_pipe[0]);
  close(log_pipe[0]);
  close(log_pipe[1]);
  std::printf("%s%s", events.c_str(), (*app)->summary().c_str());

  EXPECT_FALSE(fault) << supervisor.watch().reason();
  EXPECT_EQ(supervisor.watch().clockJumps(), 2u);
  EXPECT_LT(std::llabs(supervisor.watch().lastClockJumpNs() + kHour), 50'000'000);
  EXPECT_NE(events.find("clock: the wall clock jumped +3600.0"), std::string::npos) << events;
  EXPECT_NE(events.find("clock: the wall clock jumped -3600.0"), std::string::npos) << events;
  // Poses kept coming in every phase (20 Hz: ~20 a phase; a loaded machine may drop some).
  ASSERT_EQ(poses_at.size(), 3u);
  EXPECT_GE(poses_at[0], 5u);
  EXPECT_GE(poses_at[1] - poses_at[0], 5u);
  EXPECT_GE(poses_at[2] - poses_at[1], 5u);

  // Every pose: finite, and its UTC time its strobe edge plus the one offset taken at start.
  const std::vector<PoseRecord> poses = recorder->poses();
  ASSERT_GE(poses.size(), 15u);
  const TimeNs offset = poses[0].utc_ns - poses[0].trigger_mono_ns;
  std::size_t after_first = 0, after_second = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const PoseRecord& p = poses[i];
    EXPECT_EQ(p.utc_ns - p.trigger_mono_ns, offset) << i;
    EXPECT_TRUE(std::isfinite(p.p_w[0]) && std::isfinite(p.p_w[1]) && std::isfinite(p.p_w[2])) << i;
    EXPECT_TRUE(std::isfinite(p.q_w_c[0]) && std::isfinite(p.q_w_c[3])) << i;
    if (i > 0) {
      const TimeNs dt = p.utc_ns - poses[i - 1].utc_ns;
      EXPECT_GT(dt, 0) << i;
      EXPECT_LT(dt, 1'000'000'000) << i;  // no hour in any frame-to-frame dt
    }
    after_first += p.trigger_mono_ns > jump_mono[0] ? 1 : 0;
    after_second += p.trigger_mono_ns > jump_mono[1] ? 1 : 0;
  }
  EXPECT_GE(after_first - after_second, 5u);  // tracked between the jumps
  EXPECT_GE(after_second, 5u);                // and after the second
}

}  // namespace
}  // namespace sunvo::rover
