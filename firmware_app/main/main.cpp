// sunvo_rover: the onboard program. Reads the YAML config, starts the capture, estimator, sun
// and telemetry threads, and runs until SIGINT/SIGTERM (or, for a replay with end: stop, until
// the last pose is sent). SIGUSR1 writes the latency profile without stopping.
//
//   sunvo_rover --config config/rover.yaml [--set key=value ...]
//
// Exit codes: 0 clean shutdown, 2 bad command line or config, 1 any other start-up failure or a
// fault that lasted past health.fault_exit_s (so that systemd's Restart=on-failure fires).
// --help and --version answer and exit 0.
//
// Under systemd (Type=notify, WatchdogSec=): READY=1 once the threads run, WATCHDOG=1 every half
// $WATCHDOG_USEC while the stages are healthy, STOPPING=1 at the end (rover::Supervisor). Events
// go to stderr as journal lines with a priority prefix ("<3>" error, "<4>" warning, "<6>" info).

#include <signal.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/mavlink_link.hpp"
#include "sunvo/rover/supervisor.hpp"
#include "sunvo/runtime/allocation_meter.hpp"
#include "sunvo/runtime/clock.hpp"
#include "sunvo/runtime/event_log.hpp"
#include "sunvo/runtime/rt_setup.hpp"
#include "sunvo/runtime/sd_notify.hpp"

#ifdef SUNVO_ALLOC_COUNTER
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace {

// Resident set size of this process, kB (VmRSS of /proc/self/status); -1 if unreadable.
long residentKb() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return -1;
  char line[256];
  long kb = -1;
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    if (std::strncmp(line, "VmRSS:", 6) == 0) kb = std::strtol(line + 6, nullptr, 10);
  }
  std::fclose(f);
  return kb;
}

}  // namespace

int main(int argc, char** argv) {
  std::string config_path;
  std::vector<std::string> sets;
  CLI::App cli{
      "The onboard sun-aided stereo VO program. Signals: SIGINT/SIGTERM stop cleanly, "
      "SIGUSR1 writes the latency profile.",
      "sunvo_rover"};
  cli.add_option("--config", config_path,
                 "YAML config (config/rover.yaml, config/rover_replay.yaml)")
      ->required();
  cli.add_option("--set", sets, "override one config key, e.g. --set serial.device=/dev/pts/3")
      ->check([](const std::string& kv) {
        const auto eq = kv.find('=');
        return eq == std::string::npos || eq == 0 ? std::string("expected key=value")
                                                  : std::string();
      });
  if (auto code = sunvo::cli::parse(cli, argc, argv)) return *code;
  std::vector<std::pair<std::string, std::string>> overrides;
  for (const std::string& kv : sets) {
    const auto eq = kv.find('=');
    overrides.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
  }
  using sunvo::runtime::LogPriority;
  sunvo::runtime::EventLog events("sunvo_rover");
  auto config = sunvo::rover::loadRoverConfig(config_path, overrides);
  if (!config) {
    events.log(LogPriority::kErr, "%s", config.status().message().c_str());
    return 2;
  }
  std::printf("%s", config->describe().c_str());
  std::fflush(stdout);
  events.log(LogPriority::kInfo, "starting (config %s)", config_path.c_str());
  {
    std::string warning;
    const sunvo::Status clock =
        sunvo::rover::checkClock(config->health, sunvo::rover::readClockState(), &warning);
    if (!clock.isOk()) {
      events.log(LogPriority::kErr, "%s", clock.message().c_str());
      return 1;
    }
    if (!warning.empty()) {
      events.log(LogPriority::kWarning, "%s (health.clock_unsynced: warn)", warning.c_str());
    }
  }

  // Before any thread exists: one malloc arena, no mmap blocks, no trimming.
  if (config->rt.heap_reserve_mb > 0) {
    const std::string w = sunvo::runtime::configureRealTimeHeap();
    if (!w.empty()) events.log(LogPriority::kWarning, "%s", w.c_str());
  }
#ifdef SUNVO_ALLOC_COUNTER
  sunvo::runtime::setThreadAllocationProbe(&sunvo::runtime::threadAllocationCount);
#endif

  // Signals are blocked in every thread (the threads inherit the mask) and taken here.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::unique_ptr<sunvo::rover::PoseLink> link;
  if (!config->serial.device.empty()) {
    auto l = sunvo::rover::MavlinkSerialLink::open(config->serial, config->telemetry);
    if (!l) {
      events.log(LogPriority::kErr, "serial.device: %s", l.status().message().c_str());
      return 1;
    }
    link = std::move(*l);
  }
  auto app =
      sunvo::rover::RoverApp::create(*config, std::move(link), sunvo::rover::productionDevices());
  if (!app) {
    events.log(LogPriority::kErr, "%s", app.status().message().c_str());
    return app.status().code() == sunvo::StatusCode::kInvalidArgument ? 2 : 1;
  }
  {
    const std::string w =
        sunvo::runtime::reserveHeap(static_cast<std::size_t>(config->rt.heap_reserve_mb) << 20);
    if (!w.empty()) events.log(LogPriority::kWarning, "%s", w.c_str());
  }
  const long rss_start_kb = residentKb();  // every buffer allocated, threads not started
  for (const std::string& w : (*app)->start()) events.log(LogPriority::kWarning, "%s", w.c_str());
  std::printf("sunvo_rover: running (pid %d)\n", static_cast<int>(getpid()));
  std::fflush(stdout);
  sunvo::runtime::SdNotifier notifier = sunvo::runtime::SdNotifier::fromEnvironment();
  sunvo::rover::Supervisor supervisor(**app, config->health, notifier, events,
                                      sunvo::runtime::monotonicNs());
  supervisor.ready();
  int exit_code = 0;

  // RSS once the warm-up frames are through, and at the end: growth = a leak or a buffer that
  // grows.
  const auto warmup = static_cast<std::uint64_t>(config->realtime.warmup_frames);
  long rss_warm_kb = -1;
  std::uint64_t rss_warm_frame = 0;
  int dumps = 0;
  const char* reason = "end of the replay";
  for (;;) {
    timespec tick{0, 50'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &tick);
    if (sig == SIGUSR1) {
      auto text = (*app)->writeProfile("sigusr1_" + std::to_string(++dumps));
      events.log(text ? LogPriority::kInfo : LogPriority::kWarning, "SIGUSR1: profile %s",
                 text ? "written" : text.status().message().c_str());
      continue;
    }
    if (sig == SIGINT || sig == SIGTERM) {
      reason = sig == SIGINT ? "SIGINT" : "SIGTERM";
      break;
    }
    if (rss_warm_kb < 0 && (*app)->framesProcessed() >= warmup) {
      rss_warm_frame = (*app)->framesProcessed();
      rss_warm_kb = residentKb();
    }
    if ((*app)->finished()) {
      if ((*app)->sourceFailed()) {
        exit_code = 1;
        reason = "the frame source failed persistently";
      }
      break;
    }
    if (auto code = supervisor.tick(sunvo::runtime::monotonicNs())) {
      exit_code = *code;
      reason = "fault exit";
      break;
    }
  }
  supervisor.stopping(reason);
  (*app)->requestStop();
  (*app)->join();
  const long rss_end_kb = residentKb();
  auto profile = (*app)->writeProfile("final");
  std::printf("sunvo_rover: stopped (%s)\n%s", reason, (*app)->summary().c_str());
  std::printf("  clock: %llu wall-clock jumps (last %+.3f s); frame times kept the start offset\n",
              static_cast<unsigned long long>(supervisor.watch().clockJumps()),
              static_cast<double>(supervisor.watch().lastClockJumpNs()) * 1e-9);
  if (rss_warm_kb >= 0) {
    std::printf(
        "  rss: %ld kB at start, %ld kB after warm-up (frame %llu), %ld kB at the end: "
        "growth after warm-up %ld kB\n",
        rss_start_kb, rss_warm_kb, static_cast<unsigned long long>(rss_warm_frame), rss_end_kb,
        rss_end_kb - rss_warm_kb);
  } else {
    std::printf("  rss: %ld kB at start, %ld kB at the end (warm-up not reached)\n", rss_start_kb,
                rss_end_kb);
  }
  if (!profile) {
    events.log(LogPriority::kWarning, "profile: %s", profile.status().message().c_str());
  } else {
    std::printf("  profile: %s/final_latency.csv, final_trace.json, final_latency_summary.txt\n",
                config->profiling.output_dir.c_str());
  }
  std::fflush(stdout);
  events.log(exit_code == 0 ? LogPriority::kInfo : LogPriority::kErr, "exit %d (%s)", exit_code,
             reason);
  return exit_code;
}
