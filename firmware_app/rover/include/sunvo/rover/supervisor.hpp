#pragma once
// The supervising side of sunvo_rover (its main thread, every ~50 ms, never per frame): feeds the
// HealthWatch from the running RoverApp, tells systemd READY=1 / WATCHDOG=1 / STATUS= /
// STOPPING=1 (SdNotifier), logs the events (start, ready, fault, recovery, fault exit, a
// wall-clock jump: HealthWatch::clockJumps) as
// journal lines with priorities (EventLog), and says when a fault has lasted past
// health.fault_exit_s. WATCHDOG=1 goes out every half $WATCHDOG_USEC, only while healthy: a
// stalled stage stops the pings and systemd restarts the service.

#include <cstdint>
#include <optional>

#include "sunvo/rover/app.hpp"
#include "sunvo/rover/health_watch.hpp"
#include "sunvo/runtime/event_log.hpp"
#include "sunvo/runtime/sd_notify.hpp"

namespace sunvo::rover {

class Supervisor {
 public:
  // Exit code when a fault lasted past health.fault_exit_s (a runtime failure).
  static constexpr int kFaultExitCode = 1;

  // All three must outlive the supervisor; app has been started.
  Supervisor(const RoverApp& app, const HealthConfig& config, runtime::SdNotifier& notifier,
             runtime::EventLog& log, TimeNs start_ns);
  // READY=1 and the "ready" line (the threads run).
  void ready();
  // One look at the counters at `now` (monotonic). Logs a fault when it appears (warning) and
  // when it clears (info), and the start's levelling once (info); pings the watchdog when due and
  // healthy. Returns kFaultExitCode after logging the reason (error) when the present fault lasted
  // past health.fault_exit_s.
  std::optional<int> tick(TimeNs now);
  // STOPPING=1 and the "stopping" line.
  void stopping(const char* why);

  const HealthWatch& watch() const { return watch_; }
  std::uint64_t watchdogPings() const { return pings_; }

 private:
  const RoverApp& app_;
  runtime::SdNotifier& notifier_;
  runtime::EventLog& log_;
  HealthWatch watch_;
  TimeNs ping_period_ns_;  // half of $WATCHDOG_USEC; 0: no watchdog
  TimeNs next_ping_ns_;
  HealthFault logged_ = HealthFault::kNone;
  bool start_tilt_logged_ = false;  // the start's levelling was logged (info)
  std::uint64_t pings_ = 0;
};

}  // namespace sunvo::rover
