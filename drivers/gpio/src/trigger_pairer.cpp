#include "sunvo/gpio/trigger_pairer.hpp"

#include <cstdlib>
#include <string>

namespace sunvo::gpio {
namespace {

Status outside(const char* key, long long value, const std::string& range) {
  return invalidArgument(std::string("trigger_pairer.") + key + ": " + std::to_string(value) +
                         " is outside " + range);
}

}  // namespace

Status TriggerPairerOptions::validate() const {
  if (capacity < 2 || capacity > 65536) return outside("capacity", capacity, "[2, 65536]");
  if (frame_period_ns <= 0 || frame_period_ns > 10 * kNsPerSecond) {
    return outside("frame_period_ns", frame_period_ns, "(0, 1e10]");
  }
  if (expected_delay_ns < -kNsPerSecond || expected_delay_ns > kNsPerSecond) {
    return outside("expected_delay_ns", expected_delay_ns, "[-1e9, 1e9]");
  }
  if (match_window_ns < 0 || match_window_ns > frame_period_ns / 2) {
    return outside("match_window_ns", match_window_ns,
                   "[0, frame_period_ns / 2 = " + std::to_string(frame_period_ns / 2) + "]");
  }
  if (!(duplicate_fraction > 0.0 && duplicate_fraction <= 1.0)) {
    return invalidArgument("trigger_pairer.duplicate_fraction: " +
                           std::to_string(duplicate_fraction) + " is outside (0, 1]");
  }
  return Status::ok();
}

Expected<TriggerPairer> TriggerPairer::create(const TriggerPairerOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  return TriggerPairer(options);
}

TriggerPairer::TriggerPairer(const TriggerPairerOptions& options)
    : options_(options), ring_(static_cast<std::size_t>(options.capacity)) {}

const TriggerEvent& TriggerPairer::at(int i) const {
  return ring_[static_cast<std::size_t>((head_ + i) % options_.capacity)];
}

void TriggerPairer::popOldest() {
  head_ = (head_ + 1) % options_.capacity;
  --size_;
}

void TriggerPairer::addTrigger(const TriggerEvent& trigger) {
  if (have_newest_) {
    const TimeNs gap = trigger.time_ns - newest_ns_;
    if (gap < 0) {
      ++counters_.out_of_order_triggers;
      return;
    }
    // A second edge within duplicate_fraction of a period of the first: bounce or double pulse.
    if (static_cast<double>(gap) <
        options_.duplicate_fraction * static_cast<double>(options_.frame_period_ns)) {
      ++counters_.duplicate_triggers;
      return;
    }
  }
  have_newest_ = true;
  newest_ns_ = trigger.time_ns;
  ++counters_.triggers;
  if (size_ == options_.capacity) {
    popOldest();  // its frame never came while capacity triggers followed
    ++counters_.triggers_without_frame;
  }
  ring_[static_cast<std::size_t>((head_ + size_) % options_.capacity)] = trigger;
  ++size_;
}

std::optional<TriggerEvent> TriggerPairer::matchFrame(TimeNs frame_time_ns) {
  ++counters_.frames;
  // Where this frame's trigger must be: frame = trigger + delay, within the window.
  const TimeNs target = frame_time_ns - options_.expected_delay_ns;
  // Triggers before the window can match no frame from now on (frames come in time order).
  while (size_ > 0 && at(0).time_ns < target - options_.match_window_ns) {
    popOldest();
    ++counters_.triggers_without_frame;
  }
  // The triggers are in time order: among the leading ones inside the window take the closest;
  // those before it had no frame.
  int best = -1;
  for (int i = 0; i < size_ && at(i).time_ns <= target + options_.match_window_ns; ++i) {
    if (best < 0 || std::llabs(at(i).time_ns - target) < std::llabs(at(best).time_ns - target)) {
      best = i;
    }
  }
  if (best < 0) {
    ++counters_.frames_without_trigger;
    return std::nullopt;
  }
  for (int i = 0; i < best; ++i) {
    popOldest();
    ++counters_.triggers_without_frame;
  }
  const TriggerEvent matched = at(0);
  popOldest();
  ++counters_.paired;
  return matched;
}

}  // namespace sunvo::gpio
