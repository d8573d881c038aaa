#pragma once
// Field health of sunvo_rover, judged from the stages' counters by the supervising (main) thread:
// which fault is present, whether the systemd watchdog may be fed, and whether a fault has lasted
// so long (health.fault_exit_s) that the program should end and let Restart=on-failure start it
// again. Also the start-up clock check (adjtimex). Pure logic on samples: tests feed it times.
//
// A fault is a silence longer than health.watchdog_pose_age_s:
//   camera: frames_grabbed has not advanced (while the source has not ended);
//   lost:   frames are processed but none tracked (frames_processed - lost_frames stands still);
//   pose:   poses_published has not advanced (while the estimator runs).
// The camera comes first (it explains the other two). Healthy = no fault = feed the watchdog.
//
// Clock jumps: each sample also carries the wall clock (UTC) read with it. When UTC - monotonic
// changes by more than kClockJumpNs between two samples, the wall clock was stepped (settimeofday,
// an NTP step; a slew changes it by at most 0.5 ms/s): the jump is counted, not a fault. Frame
// times do not follow it: they are monotonic stamps mapped to UTC with the offset taken when the
// source opened (RoverApp), so dt and the sun's ephemeris time stay continuous.

#include <cstdint>
#include <string>

#include "sunvo/core/time.hpp"
#include "sunvo/rover/config.hpp"

namespace sunvo::rover {

// The counters the watch reads (RoverApp::healthSample()).
struct HealthSample {
  TimeNs now_ns = 0;  // monotonic
  TimeNs utc_ns = 0;  // wall clock (UTC) read just after now_ns; 0: not read (no jump check)
  std::uint64_t frames_grabbed = 0;
  std::uint64_t grab_errors = 0;
  std::uint64_t trigger_timeouts = 0;
  std::uint64_t frames_processed = 0;
  std::uint64_t lost_frames = 0;
  std::uint64_t poses_published = 0;
  bool source_ended = false;    // the capture loop has finished (end of a replay, or stop)
  bool estimator_done = false;  // the estimator loop has finished
  // The start's tilt error the cue's first answers measured (fusion.world_up_alignment_use
  // start_tilt), millidegrees, from how many answers (0: not judged yet), and whether the
  // estimator removed it (false: within the answers' noise, left to the filter). An event, not a
  // fault: the supervisor logs it once.
  std::int64_t start_tilt_mdeg = 0;
  bool start_tilt_removed = false;
  std::uint64_t start_tilt_answers = 0;
};

enum class HealthFault { kNone, kCamera, kLost, kNoPose };
const char* healthFaultName(HealthFault f);

class HealthWatch {
 public:
  // camera: how the reason names the frame source ("/dev/sunvo-left + /dev/sunvo-right").
  HealthWatch(const HealthConfig& config, TimeNs start_ns, std::string camera);

  // Takes one sample; returns the present fault (kNone when healthy).
  HealthFault update(const HealthSample& s);
  HealthFault fault() const { return fault_; }
  bool healthy() const { return fault_ == HealthFault::kNone; }
  // How long the present fault's silence has lasted, ns (0 when healthy).
  TimeNs faultAgeNs() const { return fault_age_ns_; }
  // True when the present fault has lasted longer than health.fault_exit_s (never when 0).
  bool mustExit() const;
  // The present fault in words, naming the device and the counters (fixed buffer).
  const char* reason() const { return reason_; }

  // A change of UTC - monotonic above this between two samples is a wall-clock jump.
  static constexpr TimeNs kClockJumpNs = 1'000'000'000;
  // Wall-clock jumps seen so far, and the size of the last one (UTC - monotonic, after - before).
  std::uint64_t clockJumps() const { return clock_jumps_; }
  TimeNs lastClockJumpNs() const { return last_clock_jump_ns_; }

 private:
  HealthConfig config_;
  std::string camera_;
  std::uint64_t frames_ = 0, tracked_ = 0, processed_ = 0, poses_ = 0;
  TimeNs last_frame_ns_, last_tracked_ns_, last_processed_ns_, last_pose_ns_;
  HealthFault fault_ = HealthFault::kNone;
  TimeNs fault_age_ns_ = 0;
  char reason_[256] = "";
  bool have_utc_offset_ = false;
  TimeNs utc_offset_ns_ = 0;  // UTC - monotonic at the last sample
  std::uint64_t clock_jumps_ = 0;
  TimeNs last_clock_jump_ns_ = 0;
};

// The kernel's view of the system clock (adjtimex(2) with modes = 0).
struct ClockState {
  int adjtimex_rc = 0;    // the call's return: TIME_OK .. TIME_ERROR, or -1
  int status = 0;         // timex.status (STA_* bits)
  long max_error_us = 0;  // timex.maxerror, µs
};
ClockState readClockState();
// Unsynchronised: the call failed, returned TIME_ERROR, or STA_UNSYNC is set.
bool clockUnsynced(const ClockState& c);
// The start-up decision: ok when synchronised; when not, ok with *warning set (warn) or a
// failed-precondition naming health.clock_unsynced (refuse).
Status checkClock(const HealthConfig& config, const ClockState& c, std::string* warning);

}  // namespace sunvo::rover
