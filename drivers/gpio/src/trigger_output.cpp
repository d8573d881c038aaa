#include <chrono>
#include <cmath>
#include <thread>

#include "requested_line.hpp"
#include "sunvo/gpio/trigger.hpp"

namespace sunvo::gpio {

Status GpioLineOptions::validate(const char* prefix) const {
  const std::string p(prefix);
  if (chip.empty()) return invalidArgument(p + ".chip: empty");
  if (line < 0 || line > 1023) {
    return invalidArgument(p + ".line: " + std::to_string(line) + " is outside [0, 1023]");
  }
  if (consumer.empty()) return invalidArgument(p + ".consumer: empty");
  return Status::ok();
}

Status TriggerOutputOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(gpio.validate("trigger_output"));
  if (!(rate_hz > 0.0 && rate_hz <= 1000.0)) {
    return invalidArgument("trigger_output.rate_hz: " + std::to_string(rate_hz) +
                           " is outside (0, 1000]");
  }
  const double half_period_us = 0.5e6 / rate_hz;
  if (pulse_width_us < 1 || pulse_width_us > 100000 || pulse_width_us >= half_period_us) {
    return invalidArgument("trigger_output.pulse_width_us: " + std::to_string(pulse_width_us) +
                           " is outside [1, 100000] or not below half the period (" +
                           std::to_string(half_period_us) + " us)");
  }
  return Status::ok();
}

TriggerOutput::TriggerOutput(const TriggerOutputOptions& options, GpioApi& api)
    : options_(options),
      api_(api),
      period_ns_(static_cast<TimeNs>(std::llround(1e9 / options.rate_hz))) {}

Expected<std::unique_ptr<TriggerOutput>> TriggerOutput::open(const TriggerOutputOptions& options,
                                                             GpioApi& api) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<TriggerOutput> out(new TriggerOutput(options, api));
  SUNVO_RETURN_IF_ERROR(detail::requestLine(api, options.gpio, detail::LineDirection::kOutput,
                                            options.active_low ? 1 : 0, out->chip_, out->line_));
  return out;
}

TriggerOutput::~TriggerOutput() {
  if (line_) (void)api_.lineSetValue(line_, options_.active_low ? 1 : 0);
  detail::releaseLine(api_, chip_, line_);
}

TimeNs TriggerOutput::nextPulseTime(TimeNs now_ns) const {
  if (!hasPulsed()) return now_ns;
  std::uint64_t slot = last_slot_ + 1;
  if (now_ns > first_ns_) {
    // The first slot at or after now_ns.
    const auto at_now =
        static_cast<std::uint64_t>((now_ns - first_ns_ + period_ns_ - 1) / period_ns_);
    if (at_now > slot) slot = at_now;
  }
  return first_ns_ + static_cast<TimeNs>(slot) * period_ns_;
}

Status TriggerOutput::pulse(TimeNs now_ns) {
  const int active = options_.active_low ? 0 : 1;
  int err = api_.lineSetValue(line_, active);
  if (err != 0) {
    ++counters_.errors;
    return detail::gpioError(options_.gpio, "set value (pulse start)", err);
  }
  std::this_thread::sleep_for(std::chrono::microseconds(options_.pulse_width_us));
  err = api_.lineSetValue(line_, 1 - active);

  std::uint64_t slot = 0;
  if (hasPulsed()) {
    // The slot nearest to now, at least the one after the last pulse's.
    const TimeNs since = now_ns - first_ns_;
    const std::uint64_t nearest =
        since > 0 ? static_cast<std::uint64_t>((since + period_ns_ / 2) / period_ns_) : 0;
    slot = nearest > last_slot_ ? nearest : last_slot_ + 1;
    counters_.missed_slots += slot - last_slot_ - 1;
    last_.sequence += 1;
  } else {
    first_ns_ = now_ns;
    last_.sequence = 0;
  }
  last_slot_ = slot;
  last_.time_ns = now_ns;
  ++counters_.pulses;
  if (err != 0) {
    ++counters_.errors;
    return detail::gpioError(options_.gpio, "set value (pulse end)", err);
  }
  return Status::ok();
}

}  // namespace sunvo::gpio
