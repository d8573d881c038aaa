#include "sunvo/rover/supervisor.hpp"

#include "sunvo/sunfusion/sun_window_term.hpp"

namespace sunvo::rover {

Supervisor::Supervisor(const RoverApp& app, const HealthConfig& config,
                       runtime::SdNotifier& notifier, runtime::EventLog& log, TimeNs start_ns)
    : app_(app),
      notifier_(notifier),
      log_(log),
      watch_(config, start_ns, app.cameraName()),
      ping_period_ns_(notifier.watchdogNs() / 2),
      next_ping_ns_(start_ns) {}

void Supervisor::ready() {
  notifier_.ready();
  notifier_.status("running");
  log_.log(runtime::LogPriority::kInfo, "ready: 4 stages running, watchdog %s",
           ping_period_ns_ > 0 ? "on" : "off");
}

std::optional<int> Supervisor::tick(TimeNs now) {
  const std::uint64_t jumps_before = watch_.clockJumps();
  const HealthSample sample = app_.healthSample(now);
  const HealthFault fault = watch_.update(sample);
  if (!start_tilt_logged_ && sample.start_tilt_answers > 0) {
    log_.log(runtime::LogPriority::kInfo,
             "start tilt: %.3f deg measured from %llu vertical-cue answers %s",
             static_cast<double>(sample.start_tilt_mdeg) * 1e-3,
             static_cast<unsigned long long>(sample.start_tilt_answers),
             sunfusion::startTiltOutcome(sample.start_tilt_removed));
    start_tilt_logged_ = true;
  }
  if (watch_.clockJumps() != jumps_before) {
    log_.log(runtime::LogPriority::kWarning,
             "clock: the wall clock jumped %+.3f s (UTC - monotonic; jump %llu); frame times keep "
             "the offset taken at start",
             static_cast<double>(watch_.lastClockJumpNs()) * 1e-9,
             static_cast<unsigned long long>(watch_.clockJumps()));
  }
  if (fault != logged_) {
    if (fault == HealthFault::kNone) {
      log_.log(runtime::LogPriority::kInfo, "recovered from fault (%s)", healthFaultName(logged_));
      notifier_.status("running");
    } else {
      log_.log(runtime::LogPriority::kWarning, "fault: %s", watch_.reason());
      notifier_.status(watch_.reason());
    }
    logged_ = fault;
  }
  if (watch_.mustExit()) {
    log_.log(runtime::LogPriority::kErr, "fault exit (health.fault_exit_s exceeded): %s",
             watch_.reason());
    notifier_.status(watch_.reason());
    return kFaultExitCode;
  }
  if (ping_period_ns_ > 0 && now >= next_ping_ns_ && watch_.healthy()) {
    if (notifier_.watchdog()) ++pings_;
    next_ping_ns_ = now + ping_period_ns_;
  }
  return std::nullopt;
}

void Supervisor::stopping(const char* why) {
  notifier_.stopping();
  log_.log(runtime::LogPriority::kInfo, "stopping (%s)", why);
}

}  // namespace sunvo::rover
