#include "requested_line.hpp"
#include "sunvo/gpio/trigger.hpp"
#include "sunvo/sysio/sysio.hpp"

namespace sunvo::gpio {

Status StrobeInputOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(gpio.validate("strobe_input"));
  if (wait_timeout_ms < 1 || wait_timeout_ms > 60000) {
    return invalidArgument("strobe_input.wait_timeout_ms: " + std::to_string(wait_timeout_ms) +
                           " is outside [1, 60000]");
  }
  return Status::ok();
}

StrobeInput::StrobeInput(const StrobeInputOptions& options, GpioApi& api)
    : options_(options), api_(api) {}

Expected<std::unique_ptr<StrobeInput>> StrobeInput::open(const StrobeInputOptions& options,
                                                         GpioApi& api) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<StrobeInput> in(new StrobeInput(options, api));
  SUNVO_RETURN_IF_ERROR(detail::requestLine(api, options.gpio, detail::LineDirection::kBothEdges, 0,
                                            in->chip_, in->line_));
  return in;
}

StrobeInput::~StrobeInput() {
  detail::releaseLine(api_, chip_, line_);
}

Expected<TriggerEvent> StrobeInput::next() {
  const TimeNs deadline =
      sysio::monotonicNowNs() + static_cast<TimeNs>(options_.wait_timeout_ms) * 1'000'000;
  for (;;) {
    const TimeNs left = deadline - sysio::monotonicNowNs();
    bool ready = false;
    if (left > 0) {
      const int err = api_.lineEventWait(line_, left, ready);
      if (err != 0) {
        ++counters_.errors;
        return detail::gpioError(options_.gpio, "event wait", err);
      }
    }
    if (!ready) {
      ++counters_.timeouts;
      return Status(StatusCode::kTimeout, detail::lineName(options_.gpio) +
                                              ": no rising edge within " +
                                              std::to_string(options_.wait_timeout_ms) + " ms");
    }
    LineEvent event;
    const int err = api_.lineEventRead(line_, event);
    if (err != 0) {
      ++counters_.errors;
      return detail::gpioError(options_.gpio, "event read", err);
    }
    if (!event.rising) {
      ++counters_.falling;
      continue;
    }
    ++counters_.rising;
    return TriggerEvent{sequence_++, event.time_ns};
  }
}

}  // namespace sunvo::gpio
