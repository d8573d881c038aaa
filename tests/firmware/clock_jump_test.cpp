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

#include "../support/drain_fd.hpp"
#include "../support/emulated_rig.hpp"
#include "../support/recording_link.hpp"
#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/supervisor.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {
namespace {

constexpr double kRateHz = testing::kRigRateHz;
constexpr int kStrobeLine = testing::kRigStrobeLine;
constexpr TimeNs kHour = 3'600'000'000'000;
// Under an emulator (the aarch64 job runs the tests in qemu) the front end is about five times
// slower: 17 poses in three 1 s phases, the first 4 of them in the phase that includes start-up.
// The phases are longer there, so that each still holds at least five poses.
constexpr bool kEmulated = sizeof(SUNVO_TOOL_EMULATOR) > 1;
constexpr TimeNs kPhaseNs = kEmulated ? 4'000'000'000 : 1'000'000'000;

TEST(ClockJump, WallClockStepsBothWaysAreCountedAndNeitherPosesNorFrameTimesJump) {
  emulated::EmulatedGpio gpio;
  emulated::EmulatedV4l2 cameras;
  ASSERT_TRUE(gpio.addChip("gpiochip0", 32).isOk());
  ASSERT_TRUE(testing::addRigCameras(cameras).isOk());
  const std::string out = std::string(SUNVO_BINARY_DIR) + "/test_out/clock_jump";
  std::filesystem::create_directories(out);
  auto overrides = testing::rigOverrides(out);
  overrides.insert(overrides.end(),
                   {{"health.fault_exit_s", "5.0"}, {"health.watchdog_pose_age_s", "1.0"}});
  auto config = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml", overrides);
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

  // Three phases of 1 s (4 s under an emulator), the supervisor ticking every 20 ms as
  // sunvo_rover's main thread does; the wall clock steps +1 h before the second, -1 h before the
  // third.
  bool fault = false;
  std::vector<std::uint64_t> poses_at;  // poses published when each phase ends
  std::vector<TimeNs> jump_mono;        // when each step was injected
  for (int phase = 0; phase < 3; ++phase) {
    if (phase > 0) {
      jump_mono.push_back(runtime::monotonicNs());
      runtime::injectUtcStep(phase == 1 ? kHour : -kHour);
    }
    const TimeNs until = runtime::monotonicNs() + kPhaseNs;
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
  const std::string events = testing::drainFd(log_pipe[0]);
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
