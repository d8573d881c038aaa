#include "requested_line.hpp"

#include <cstring>

namespace sunvo::gpio::detail {

std::string lineName(const GpioLineOptions& options) {
  return options.chip + " line " + std::to_string(options.line);
}

Status gpioError(const GpioLineOptions& options, const char* call, int err) {
  return {StatusCode::kDeviceError, lineName(options) + ": " + call + ": " + std::strerror(err) +
                                        " (errno " + std::to_string(err) + ")"};
}

Status requestLine(GpioApi& api, const GpioLineOptions& options, LineDirection direction,
                   int default_value, ChipHandle& chip, LineHandle& line) {
  int err = api.chipOpen(options.chip.c_str(), chip);
  if (err != 0) return gpioError(options, "open chip", err);
  err = api.chipGetLine(chip, static_cast<unsigned>(options.line), line);
  if (err != 0) {
    releaseLine(api, chip, line);
    return gpioError(options, "get line", err);
  }
  err = direction == LineDirection::kOutput
            ? api.lineRequestOutput(line, options.consumer.c_str(), default_value)
            : api.lineRequestBothEdgesEvents(line, options.consumer.c_str());
  if (err != 0) {
    // A line that was never requested must not be released; close the chip only.
    line = LineHandle{};
    releaseLine(api, chip, line);
    return gpioError(
        options,
        direction == LineDirection::kOutput ? "request output" : "request both-edge events", err);
  }
  return Status::ok();
}

void releaseLine(GpioApi& api, ChipHandle& chip, LineHandle& line) {
  if (line) api.lineRelease(line);
  if (chip) api.chipClose(chip);
  line = LineHandle{};
  chip = ChipHandle{};
}

}  // namespace sunvo::gpio::detail
