#include <algorithm>

#include "stages.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {

void TelemetryStage::run() {
  Channels& ch = ctx_.channels;
  Health& health = ctx_.health;
  const auto hb_period_ns = static_cast<TimeNs>(1e9 / ctx_.config.telemetry.heartbeat_hz);
  const auto deadline_ns = static_cast<TimeNs>(ctx_.config.realtime.deadline_ms * 1e6);
  const auto pose_timeout_ns = static_cast<TimeNs>(ctx_.config.telemetry.pose_timeout_s * 1e9);
  TimeNs next_hb = runtime::monotonicNs();
  TimeNs last_pose_ns = next_hb;  // the start counts as a pose: the camera gets the timeout
  bool pending = false;           // a pose whose last byte has not left yet
  std::uint64_t pending_seq = 0;
  TimeNs pending_trigger = 0;
  TimeNs drain_until = 0;  // after the estimator finished: flush for at most this long
  constexpr TimeNs kLogFlushPeriodNs = 1'000'000'000;
  TimeNs next_log_flush = runtime::monotonicNs() + kLogFlushPeriodNs;
  auto log_error = [&](const Status& s) {
    if (!s.isOk()) health.pose_log_errors.fetch_add(1, std::memory_order_relaxed);
  };
  auto complete = [&](TimeNs last_byte) {
    ctx_.profiler.stamp(pending_seq, runtime::Stamp::kLastByte, last_byte);
    if (last_byte - pending_trigger > deadline_ns) {
      health.deadline_misses.fetch_add(1, std::memory_order_relaxed);
    }
    health.poses_published.fetch_add(1, std::memory_order_relaxed);
    pending = false;
    meter_.frameDone();
  };
  for (;;) {
    const std::uint32_t key = ch.poses_ev.prepare();
    PoseRecord pose;
    while (ch.poses.pop(&pose)) {
      const TimeNs now = runtime::monotonicNs();
      last_pose_ns = now;
      ctx_.profiler.stamp(pose.sequence, runtime::Stamp::kPublishStart, now);
      if (pending) complete(link_ ? link_->lastByteWrittenNs() : now);  // superseded while pending
      pending = true;
      pending_seq = pose.sequence;
      pending_trigger = pose.trigger_mono_ns;
      if (link_ && !link_->sendPose(pose, now).isOk()) {
        health.link_errors.fetch_add(1, std::memory_order_relaxed);
      }
      if (!link_) complete(runtime::monotonicNs());
      if (pose_log_) log_error(pose_log_->append(pose));  // after the link: off its latency
    }
    const TimeNs now = runtime::monotonicNs();
    if (pose_log_ && now >= next_log_flush) {
      log_error(pose_log_->flush());
      next_log_flush = now + kLogFlushPeriodNs;
    }
    if (link_) {
      // Stale: no pose for pose_timeout_s while the estimator still runs (HEARTBEAT CRITICAL).
      const bool estimating = !ch.estimator_done.load(std::memory_order_acquire);
      link_->setPoseStale(estimating && now - last_pose_ns > pose_timeout_ns, now);
      if (!link_->service(now).isOk()) health.link_errors.fetch_add(1, std::memory_order_relaxed);
      if (pending && link_->drained()) complete(link_->lastByteWrittenNs());
      if (now >= next_hb) {
        if (!link_->sendHeartbeat(now).isOk()) {
          health.link_errors.fetch_add(1, std::memory_order_relaxed);
        }
        health.heartbeats.fetch_add(1, std::memory_order_relaxed);
        next_hb += hb_period_ns;
        if (next_hb < now) next_hb = now + hb_period_ns;
      }
    }
    const bool upstream_done = ch.estimator_done.load(std::memory_order_acquire);
    if (upstream_done && ch.poses.size() == 0) {
      if (drain_until == 0) drain_until = now + 200'000'000;  // 200 ms to flush the port
      if (!pending || now >= drain_until) break;
    }
    TimeNs sleep_ns = std::max<TimeNs>(next_hb - now, 0);
    if (pending) sleep_ns = std::min<TimeNs>(sleep_ns, 1'000'000);  // poll the port each ms
    sleep_ns = std::clamp<TimeNs>(sleep_ns, 100'000, 100'000'000);
    ch.poses_ev.wait(key, sleep_ns);
  }
  if (pose_log_) log_error(pose_log_->flush());
  ch.telemetry_done.store(true, std::memory_order_release);
}

}  // namespace sunvo::rover
