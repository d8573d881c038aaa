#pragma once
// Opening and requesting one GPIO line, shared by TriggerOutput and StrobeInput.

#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/gpio/gpio_api.hpp"
#include "sunvo/gpio/trigger.hpp"

namespace sunvo::gpio::detail {

enum class LineDirection { kOutput, kBothEdges };

// "<chip> line <n>", for messages.
std::string lineName(const GpioLineOptions& options);

// Opens the chip, gets the line and requests it; on failure releases what it took and names the
// chip, the line and the failed call.
Status requestLine(GpioApi& api, const GpioLineOptions& options, LineDirection direction,
                   int default_value, ChipHandle& chip, LineHandle& line);

// Releases the line and closes the chip (each if held) and clears the handles.
void releaseLine(GpioApi& api, ChipHandle& chip, LineHandle& line);

Status gpioError(const GpioLineOptions& options, const char* call, int err);

}  // namespace sunvo::gpio::detail
