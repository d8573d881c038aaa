#include "sunvo/rover/sources.hpp"

#include <cmath>

#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {

void TriggerMonitor::observe(TimeNs t_ns) {
  if (have_last_) {
    const TimeNs dt = t_ns - last_ns_;
    if (2 * dt < period_ns_) {
      ++duplicates_;
      return;  // a duplicate does not move the reference edge
    }
    const auto periods = static_cast<std::int64_t>(
        std::llround(static_cast<double>(dt) / static_cast<double>(period_ns_)));
    if (periods >= 2) missed_ += static_cast<std::uint64_t>(periods - 1);
  }
  last_ns_ = t_ns;
  have_last_ = true;
}

ReplaySchedule::ReplaySchedule(std::vector<TimeNs> times_ns, std::int64_t first_index,
                               EndAction end, std::int64_t total_frames, TimeNs period_ns,
                               bool follow_recording)
    : times_ns_(std::move(times_ns)),
      first_(first_index),
      end_(end),
      total_(total_frames),
      period_ns_(period_ns),
      follow_(follow_recording) {}

bool ReplaySchedule::has(std::uint64_t k) const {
  if (times_ns_.empty()) return false;
  if (total_ > 0 && k >= static_cast<std::uint64_t>(total_)) return false;
  if (end_ == EndAction::kStop || end_ == EndAction::kHold) return k < times_ns_.size();
  return true;
}

std::int64_t ReplaySchedule::recordingIndex(std::uint64_t k) const {
  const auto n = static_cast<std::uint64_t>(times_ns_.size());
  std::uint64_t j = k;
  if (end_ == EndAction::kLoop) {
    j = k % n;
  } else if (end_ == EndAction::kPingPong && n > 1) {
    const std::uint64_t cycle = 2 * n - 2;  // 0 .. n-1 .. 1
    j = k % cycle;
    if (j >= n) j = cycle - j;
  } else if (end_ == EndAction::kPingPong) {
    j = 0;
  }
  return first_ + static_cast<std::int64_t>(std::min(j, n - 1));
}

TimeNs ReplaySchedule::offsetNs(std::uint64_t k) const {
  const std::uint64_t n = times_ns_.size();
  if (!follow_) return static_cast<TimeNs>(k) * period_ns_;
  if (k < n) return times_ns_[k] - times_ns_.front();
  return (times_ns_.back() - times_ns_.front()) + static_cast<TimeNs>(k - (n - 1)) * period_ns_;
}

Status SimulatedTrigger::wait(TimeNs timeout_ns, TriggerEvent* out) {
  if (!schedule_->has(next_)) {
    runtime::sleepUntilMonotonicNs(runtime::monotonicNs() + timeout_ns);
    return notFound("simulated trigger: end of the recording");
  }
  const TimeNs now = runtime::monotonicNs();
  if (next_ == 0) start_mono_ns_ = now;
  const TimeNs edge = start_mono_ns_ + schedule_->offsetNs(next_);
  if (edge - now > timeout_ns) {
    runtime::sleepUntilMonotonicNs(now + timeout_ns);
    return {StatusCode::kTimeout, "simulated trigger: no edge yet"};
  }
  runtime::sleepUntilMonotonicNs(edge);
  out->sequence = next_;
  out->mono_ns = edge;
  out->utc_ns = schedule_->utcNs(next_);
  ++next_;
  return Status::ok();
}

Expected<std::unique_ptr<KittiReplaySource>> KittiReplaySource::open(
    const KittiSourceConfig& config, bool color) {
  if (!config.preload && (config.end == EndAction::kLoop || config.end == EndAction::kPingPong)) {
    return invalidArgument("source.kitti.end: loop and pingpong need source.kitti.preload: true");
  }
  dataset::DatasetOptions d;
  d.path = config.drive_dir;
  d.utc_offset_s = config.utc_offset_s;
  d.first_frame = config.first_frame;
  d.last_frame = config.last_frame;
  d.drop_bad_frames = true;  // a bad image drops its frame (grab() fails on it), never the run
  auto ds = dataset::Dataset::open(d);
  if (!ds) return ds.status();
  if (!ds->hasImages()) return invalidArgument(config.drive_dir + ": no images");
  kitti::KittiSourceOptions o = ds->imageSourceOptions();
  o.use_color = color;
  o.drop_bad_frames = true;
  std::unique_ptr<KittiReplaySource> src(new KittiReplaySource());
  src->config_ = config;
  src->camera_ = ds->camera();
  src->dataset_.emplace(std::move(*ds));
  auto live = kitti::KittiStereoSource::open(o);
  if (!live) return live.status();
  if (config.preload) {
    auto all = kitti::loadAllFrames(o);
    if (!all) return all.status();
    src->preloaded_ = std::move(all->frames);
  } else {
    src->live_.emplace(std::move(*live));
  }
  return src;
}

Status KittiReplaySource::grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) {
  if (!schedule_) return failedPrecondition("KittiReplaySource: no schedule");
  const std::int64_t index = schedule_->recordingIndex(trigger.sequence);
  StereoFrame& dst = slot.frame;
  if (!preloaded_.empty()) {
    const StereoFrame& src = preloaded_[static_cast<std::size_t>(index - config_.first_frame)];
    if (src.left.empty()) {
      return parseError("source.kitti: frame " + std::to_string(index) +
                        ": bad image (dropped at preload)");
    }
    if (src.left.size() != dst.left.size() || src.right.size() != dst.right.size()) {
      return invalidArgument("frames.width/height: " + std::to_string(dst.left.cols) + "x" +
                             std::to_string(dst.left.rows) + " differ from the drive's " +
                             std::to_string(src.left.cols) + "x" + std::to_string(src.left.rows));
    }
    src.left.copyTo(dst.left);  // same size and type: no allocation
    src.right.copyTo(dst.right);
    if (!src.left_color.empty() && src.left_color.size() == dst.left_color.size()) {
      src.left_color.copyTo(dst.left_color);  // colour slots (image sun providers)
    }
  } else {
    // A bad frame's error comes with the source moved past it (drop_bad_frames).
    SUNVO_RETURN_IF_ERROR(live_->next(dst));
  }
  dst.sequence = trigger.sequence;
  dst.trigger_time_ns = trigger.utc_ns;
  slot.meta.source_index = index;
  return Status::ok();
}

}  // namespace sunvo::rover
