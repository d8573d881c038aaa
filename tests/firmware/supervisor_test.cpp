// Supervisor on RoverApp with emulated hardware (the rig of rover_devices_test: two EmulatedV4l2
// cameras, the strobe line of an EmulatedGpio chip), NOTIFY_SOCKET on a real datagram socket and
// the event log on a pipe. While the rig runs: READY=1, then WATCHDOG=1 pings. The left camera is
// then unplugged for longer than health.fault_exit_s (2.5 s): the pings stop, a warning names the
// device, and tick() returns the non-zero exit code with an error line naming the device.

#include "sunvo/rover/supervisor.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <vector>

#include "../support/drain_fd.hpp"
#include "../support/emulated_rig.hpp"
#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {
namespace {

constexpr double kRateHz = testing::kRigRateHz;
constexpr int kStrobeLine = testing::kRigStrobeLine;

// Appends every datagram waiting on a bound socket (read as systemd does, all along: the kernel
// queues only net.unix.max_dgram_qlen datagrams, 10 by default).
void receiveAll(int fd, std::vector<std::string>* out_datagrams) {
  std::vector<std::string>& out = *out_datagrams;
  char buf[512];
  ssize_t n;
  while ((n = recv(fd, buf, sizeof(buf), MSG_DONTWAIT)) > 0) {
    out.emplace_back(buf, static_cast<std::size_t>(n));
  }
}

TEST(Supervisor, UnpluggedCameraStopsTheWatchdogAndEndsWithAnErrorNamingIt) {
  emulated::EmulatedGpio gpio;
  emulated::EmulatedV4l2 cameras;
  ASSERT_TRUE(gpio.addChip("gpiochip0", 32).isOk());
  ASSERT_TRUE(testing::addRigCameras(cameras).isOk());
  const std::string out = std::string(SUNVO_BINARY_DIR) + "/test_out/supervisor";
  std::filesystem::create_directories(out);
  auto overrides = testing::rigOverrides(out);
  overrides.insert(overrides.end(),
                   {{"health.fault_exit_s", "2.5"}, {"health.watchdog_pose_age_s", "1.0"}});
  auto config = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml", overrides);
  ASSERT_TRUE(config.hasValue()) << config.status().toString();

  // systemd's side: the notify socket and a 200 ms watchdog (pings every 100 ms).
  const std::string sock = out + "/notify.sock";
  std::filesystem::remove(sock);
  const int listener = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, sock.c_str(), sizeof(addr.sun_path) - 1);
  ASSERT_EQ(bind(listener, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0) << sock;
  setenv("NOTIFY_SOCKET", sock.c_str(), 1);
  setenv("WATCHDOG_USEC", "200000", 1);
  unsetenv("WATCHDOG_PID");
  runtime::SdNotifier notifier = runtime::SdNotifier::fromEnvironment();
  unsetenv("NOTIFY_SOCKET");
  unsetenv("WATCHDOG_USEC");
  ASSERT_TRUE(notifier.enabled());
  int log_pipe[2];
  ASSERT_EQ(pipe2(log_pipe, O_NONBLOCK), 0);
  runtime::EventLog log("sunvo_rover", log_pipe[1]);

  auto app = RoverApp::create(*config, nullptr, RoverDevices{&cameras, &gpio});
  ASSERT_TRUE(app.hasValue()) << app.status().toString();
  (*app)->start();
  Supervisor supervisor(**app, config->health, notifier, log, runtime::monotonicNs());
  supervisor.ready();
  std::vector<std::string> datagrams;

  // The rig: strobe + exposure at 20 Hz until told to stop.
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

  // 1.5 s healthy.
  const TimeNs healthy_until = runtime::monotonicNs() + 1'500'000'000;
  bool fault_while_healthy = false;
  while (runtime::monotonicNs() < healthy_until) {
    EXPECT_FALSE(supervisor.tick(runtime::monotonicNs()).has_value());
    fault_while_healthy |= !supervisor.watch().healthy();
    receiveAll(listener, &datagrams);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::uint64_t pings_healthy = supervisor.watchdogPings();
  EXPECT_FALSE(fault_while_healthy) << supervisor.watch().reason();
  EXPECT_GE(pings_healthy, 5u);  // ~15 at 100 ms

  // Unplug the left camera for longer than fault_exit_s.
  ASSERT_TRUE(cameras.unplug("/dev/sunvo-left", std::chrono::milliseconds(10'000)).isOk());
  const TimeNs unplugged = runtime::monotonicNs();
  std::optional<int> code;
  std::uint64_t pings_at_fault = 0;
  bool saw_fault = false;
  while (!code && runtime::monotonicNs() - unplugged < 8'000'000'000) {
    code = supervisor.tick(runtime::monotonicNs());
    if (!saw_fault && !supervisor.watch().healthy()) {
      saw_fault = true;
      pings_at_fault = supervisor.watchdogPings();
    }
    receiveAll(listener, &datagrams);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double exit_after_s = static_cast<double>(runtime::monotonicNs() - unplugged) * 1e-9;
  supervisor.stopping("fault exit");
  rig_stop = true;
  rig.join();
  (*app)->requestStop();
  (*app)->join();

  ASSERT_TRUE(code.has_value()) << "no fault exit within 8 s";
  EXPECT_EQ(*code, Supervisor::kFaultExitCode);
  EXPECT_NE(*code, 0);
  EXPECT_TRUE(saw_fault);
  EXPECT_EQ(supervisor.watchdogPings(), pings_at_fault);  // no ping once the fault was seen
  EXPECT_GT(exit_after_s, 2.4);  // from the last frame, just before the unplug
  std::printf("fault exit %.2f s after the unplug; %llu pings while healthy\n", exit_after_s,
              static_cast<unsigned long long>(pings_healthy));

  // systemd saw READY=1 first, then only WATCHDOG/STATUS, STOPPING=1 last.
  receiveAll(listener, &datagrams);
  close(listener);
  ASSERT_GE(datagrams.size(), 3u);
  EXPECT_EQ(datagrams.front(), "READY=1");
  EXPECT_EQ(datagrams.back(), "STOPPING=1");
  std::uint64_t watchdogs = 0;
  for (const std::string& d : datagrams) watchdogs += d == "WATCHDOG=1" ? 1 : 0;
  EXPECT_EQ(watchdogs, supervisor.watchdogPings());
  EXPECT_EQ(notifier.errors(), 0u);

  close(log_pipe[1]);
  const std::string lines = testing::drainFd(log_pipe[0]);
  close(log_pipe[0]);
  std::printf("%s", lines.c_str());
  EXPECT_NE(lines.find("<6>sunvo_rover: ready"), std::string::npos) << lines;
  EXPECT_NE(lines.find("<4>sunvo_rover: fault: camera /dev/sunvo-left"), std::string::npos)
      << lines;
  EXPECT_NE(lines.find("<3>sunvo_rover: fault exit (health.fault_exit_s exceeded): camera "
                       "/dev/sunvo-left"),
            std::string::npos)
      << lines;
}

}  // namespace
}  // namespace sunvo::rover
