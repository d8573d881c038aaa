#include "sunvo/rover/fault_injection.hpp"

#include <string>

namespace sunvo::rover {
namespace {

Status checkRate(const char* prefix, const char* key, double rate) {
  if (!(rate >= 0.0 && rate <= 0.5)) {
    return invalidArgument(std::string(prefix) + "." + key + ": " + std::to_string(rate) +
                           " is outside [0, 0.5]");
  }
  return Status::ok();
}

}  // namespace

Status FaultInjectionConfig::validate(const char* prefix) const {
  if (seed < 0) return invalidArgument(std::string(prefix) + ".seed: must be >= 0");
  SUNVO_RETURN_IF_ERROR(checkRate(prefix, "missed_trigger_rate", missed_trigger_rate));
  SUNVO_RETURN_IF_ERROR(checkRate(prefix, "bad_frame_rate", bad_frame_rate));
  return checkRate(prefix, "dark_frame_rate", dark_frame_rate);
}

FaultyTrigger::FaultyTrigger(std::unique_ptr<TriggerSource> inner,
                             const FaultInjectionConfig& config, InjectedFaults& counts)
    : inner_(std::move(inner)),
      rate_(config.missed_trigger_rate),
      counts_(counts),
      rng_(static_cast<std::uint64_t>(config.seed) * 2 + 1) {}

Status FaultyTrigger::wait(TimeNs timeout_ns, TriggerEvent* out) {
  for (;;) {
    const Status st = inner_->wait(timeout_ns, out);
    if (!st.isOk() || !(unit_(rng_) < rate_)) return st;
    counts_.missed_triggers.fetch_add(1, std::memory_order_relaxed);
  }
}

FaultyFrameSource::FaultyFrameSource(std::unique_ptr<FrameSource> inner,
                                     const FaultInjectionConfig& config, InjectedFaults& counts)
    : inner_(std::move(inner)),
      bad_rate_(config.bad_frame_rate),
      dark_rate_(config.dark_frame_rate),
      counts_(counts),
      rng_(static_cast<std::uint64_t>(config.seed) * 2) {}

Status FaultyFrameSource::grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) {
  // Both draws every frame, so that one fault kind's rate does not shift the other's sequence.
  const bool bad = unit_(rng_) < bad_rate_;
  const bool dark = unit_(rng_) < dark_rate_;
  if (bad) {
    counts_.bad_frames.fetch_add(1, std::memory_order_relaxed);
    return ioError("injected fault");  // short enough to need no heap (small-string buffer)
  }
  SUNVO_RETURN_IF_ERROR(inner_->grab(trigger, slot));
  if (dark) {
    StereoFrame& f = slot.frame;
    for (cv::Mat* m : {&f.left, &f.right, &f.left_color, &f.right_color}) {
      if (!m->empty()) m->setTo(0);
    }
    counts_.dark_frames.fetch_add(1, std::memory_order_relaxed);
  }
  return Status::ok();
}

}  // namespace sunvo::rover
