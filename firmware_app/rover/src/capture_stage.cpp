#include "stages.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {

void CaptureStage::run() {
  Channels& ch = ctx_.channels;
  Health& health = ctx_.health;
  TriggerMonitor monitor(ctx_.period_ns);
  const auto timeout_ns =
      static_cast<TimeNs>(ctx_.config.trigger.timeout_factor * static_cast<double>(ctx_.period_ns));
  const auto max_bad = static_cast<std::uint64_t>(ctx_.config.source.max_consecutive_bad_frames);
  std::uint64_t bad_in_a_row = 0;
  while (!ch.stop.load(std::memory_order_acquire)) {
    TriggerEvent ev;
    const Status st = trigger_.wait(timeout_ns, &ev);
    if (st.code() == StatusCode::kTimeout) {
      health.trigger_timeouts.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (st.code() == StatusCode::kNotFound) break;  // the replay's last frame has been triggered
    if (!st.isOk()) {
      health.trigger_timeouts.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    health.triggers.fetch_add(1, std::memory_order_relaxed);
    monitor.observe(ev.mono_ns);
    health.triggers_missed.store(monitor.missed(), std::memory_order_relaxed);
    health.triggers_duplicate.store(monitor.duplicates(), std::memory_order_relaxed);

    std::uint32_t index = 0;
    if (!ctx_.pool.acquire(&index)) {
      health.pool_exhausted.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    runtime::FrameSlot& slot = ctx_.pool.slot(index);
    ctx_.profiler.begin(ev.sequence, ev.utc_ns, ev.mono_ns);
    if (!source_.grab(ev, slot).isOk()) {
      // The frame is dropped; the estimator matches the next good frame against the last one.
      health.grab_errors.fetch_add(1, std::memory_order_relaxed);
      ctx_.pool.recycle(index);
      ++bad_in_a_row;
      if (bad_in_a_row > health.grab_errors_in_a_row_max.load(std::memory_order_relaxed)) {
        health.grab_errors_in_a_row_max.store(bad_in_a_row, std::memory_order_relaxed);
      }
      if (bad_in_a_row > max_bad) {
        health.source_fault_stop.store(true, std::memory_order_release);
        break;
      }
      continue;
    }
    bad_in_a_row = 0;
    const TimeNs grabbed = runtime::monotonicNs();
    slot.meta.sequence = ev.sequence;
    slot.meta.trigger_mono_ns = ev.mono_ns;
    slot.meta.trigger_utc_ns = ev.utc_ns;
    slot.meta.grab_mono_ns = grabbed;
    ctx_.profiler.stamp(ev.sequence, runtime::Stamp::kGrabEnd, grabbed);
    health.frames_grabbed.fetch_add(1, std::memory_order_relaxed);
    if (schedule_.isAidFrame(ev.sequence)) requestSun(slot, ev.sequence, ev.utc_ns);

    FrameTicket dropped;
    bool did_drop = false;
    ch.frames.push({index, ev.sequence}, &dropped, &did_drop);
    if (did_drop) ctx_.pool.recycle(dropped.slot);
    ch.frames_ev.notify();
    meter_.frameDone();
  }
  ch.capture_done.store(true, std::memory_order_release);
  ch.frames_ev.notify();
  ch.sun_requests_ev.notify();
}

void CaptureStage::requestSun(const runtime::FrameSlot& slot, std::uint64_t sequence,
                              TimeNs utc_ns) {
  Channels& ch = ctx_.channels;
  SunRequest req{sequence, slot.meta.source_index, utc_ns, kNoImage};
  if (ctx_.sun_pool != nullptr && ctx_.sun_pool->acquire(&req.image_slot)) {
    StereoFrame& dst = ctx_.sun_pool->slot(req.image_slot).frame;
    slot.frame.left.copyTo(dst.left);
    if (!slot.frame.left_color.empty()) slot.frame.left_color.copyTo(dst.left_color);
  }
  SunRequest dropped;
  bool did_drop = false;
  ch.sun_requests.push(req, &dropped, &did_drop);
  if (did_drop && dropped.image_slot != kNoImage) ctx_.sun_pool->recycle(dropped.image_slot);
  ctx_.health.sun_requests.fetch_add(1, std::memory_order_relaxed);
  ch.sun_requests_ev.notify();
}

}  // namespace sunvo::rover
