#include "sunvo/rover/health_watch.hpp"

#include <sys/timex.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <utility>

namespace sunvo::rover {

const char* healthFaultName(HealthFault f) {
  switch (f) {
    case HealthFault::kNone:
      return "none";
    case HealthFault::kCamera:
      return "camera";
    case HealthFault::kLost:
      return "lost";
    case HealthFault::kNoPose:
      return "no pose";
  }
  return "?";
}

HealthWatch::HealthWatch(const HealthConfig& config, TimeNs start_ns, std::string camera)
    : config_(config),
      camera_(std::move(camera)),
      last_frame_ns_(start_ns),
      last_tracked_ns_(start_ns),
      last_processed_ns_(start_ns),
      last_pose_ns_(start_ns) {}

HealthFault HealthWatch::update(const HealthSample& s) {
  const TimeNs now = s.now_ns;
  if (s.utc_ns != 0) {
    const TimeNs offset = s.utc_ns - now;
    if (have_utc_offset_ &&
        std::max(offset - utc_offset_ns_, utc_offset_ns_ - offset) > kClockJumpNs) {
      ++clock_jumps_;
      last_clock_jump_ns_ = offset - utc_offset_ns_;
    }
    utc_offset_ns_ = offset;  // a slew is followed sample by sample, never counted
    have_utc_offset_ = true;
  }
  // The counters are read one by one (relaxed): lost may briefly exceed processed.
  const std::uint64_t tracked =
      s.frames_processed > s.lost_frames ? s.frames_processed - s.lost_frames : 0;
  if (s.frames_grabbed != frames_) last_frame_ns_ = now;
  if (tracked > tracked_) last_tracked_ns_ = now;
  if (s.frames_processed != processed_) last_processed_ns_ = now;
  if (s.poses_published != poses_) last_pose_ns_ = now;
  frames_ = s.frames_grabbed;
  tracked_ = std::max(tracked_, tracked);
  processed_ = s.frames_processed;
  poses_ = s.poses_published;

  const auto limit = static_cast<TimeNs>(config_.watchdog_pose_age_s * 1e9);
  const TimeNs frame_age = now - last_frame_ns_;
  const TimeNs tracked_age = now - last_tracked_ns_;
  const TimeNs pose_age = now - last_pose_ns_;
  fault_ = HealthFault::kNone;
  fault_age_ns_ = 0;
  reason_[0] = '\0';
  if (s.source_ended) return fault_;  // a replay that ended (end: hold) is idle, not broken
  if (frame_age > limit) {
    fault_ = HealthFault::kCamera;
    fault_age_ns_ = frame_age;
    std::snprintf(reason_, sizeof(reason_),
                  "camera %s delivered no frame for %.1f s (frames %" PRIu64
                  ", grab errors %" PRIu64 ", trigger timeouts %" PRIu64 ")",
                  camera_.c_str(), static_cast<double>(frame_age) * 1e-9, s.frames_grabbed,
                  s.grab_errors, s.trigger_timeouts);
  } else if (tracked_age > limit && last_processed_ns_ > last_tracked_ns_) {
    fault_ = HealthFault::kLost;
    fault_age_ns_ = tracked_age;
    std::snprintf(reason_, sizeof(reason_),
                  "estimator lost on every frame for %.1f s (frames processed %" PRIu64
                  ", lost %" PRIu64 ")",
                  static_cast<double>(tracked_age) * 1e-9, s.frames_processed, s.lost_frames);
  } else if (!s.estimator_done && pose_age > limit) {
    fault_ = HealthFault::kNoPose;
    fault_age_ns_ = pose_age;
    std::snprintf(reason_, sizeof(reason_),
                  "no pose published for %.1f s (frames grabbed %" PRIu64 ", processed %" PRIu64
                  ", poses %" PRIu64 ")",
                  static_cast<double>(pose_age) * 1e-9, s.frames_grabbed, s.frames_processed,
                  s.poses_published);
  }
  return fault_;
}

bool HealthWatch::mustExit() const {
  return fault_ != HealthFault::kNone && config_.fault_exit_s > 0.0 &&
         static_cast<double>(fault_age_ns_) > config_.fault_exit_s * 1e9;
}

ClockState readClockState() {
  timex tx{};
  tx.modes = 0;  // read only
  ClockState c;
  c.adjtimex_rc = adjtimex(&tx);
  c.status = tx.status;
  c.max_error_us = tx.maxerror;
  return c;
}

bool clockUnsynced(const ClockState& c) {
  return c.adjtimex_rc < 0 || c.adjtimex_rc == TIME_ERROR || (c.status & STA_UNSYNC) != 0;
}

Status checkClock(const HealthConfig& config, const ClockState& c, std::string* warning) {
  if (!clockUnsynced(c)) return Status::ok();
  char text[200];
  std::snprintf(text, sizeof(text),
                "system clock not synchronised (adjtimex %d, status 0x%x, max error %ld us): "
                "the sun's UTC is unchecked",
                c.adjtimex_rc, static_cast<unsigned>(c.status), c.max_error_us);
  if (config.clock_unsynced == ClockUnsyncedAction::kRefuse) {
    return failedPrecondition(std::string("health.clock_unsynced: refuse: ") + text);
  }
  *warning = text;
  return Status::ok();
}

}  // namespace sunvo::rover
