#pragma once
// The seam between sunvo's GPIO trigger code and libgpiod (v1.6 C API, Debian's libgpiod-dev).
//
// GpioApi wraps exactly the libgpiod calls the trigger code uses; LibgpiodApi forwards them to
// libgpiod, and hil/sim/emulated_devices' EmulatedGpio stands behind the same interface in tests.
// Every call returns 0 or an errno value (libgpiod itself returns -1 and sets errno). Handles are
// opaque: each implementation decides what they point to.

#include "sunvo/core/time.hpp"

namespace sunvo::gpio {

struct ChipHandle {
  void* impl = nullptr;
  explicit operator bool() const { return impl != nullptr; }
};
struct LineHandle {
  void* impl = nullptr;
  explicit operator bool() const { return impl != nullptr; }
};

// One edge read from a line requested for events.
struct LineEvent {
  TimeNs time_ns = 0;  // kernel timestamp (CLOCK_MONOTONIC on Linux >= 5.7, else CLOCK_REALTIME)
  bool rising = true;  // false: falling edge
};

class GpioApi {
 public:
  GpioApi() = default;
  GpioApi(const GpioApi&) = delete;
  GpioApi& operator=(const GpioApi&) = delete;
  virtual ~GpioApi() = default;

  // gpiod_chip_open_lookup: a name ("gpiochip0"), a path ("/dev/gpiochip0"), a number or a label.
  virtual int chipOpen(const char* name_or_path, ChipHandle& chip) = 0;
  // gpiod_chip_close: releases the chip's lines too.
  virtual void chipClose(ChipHandle chip) = 0;
  // gpiod_chip_get_line
  virtual int chipGetLine(ChipHandle chip, unsigned offset, LineHandle& line) = 0;
  // gpiod_line_request_output: the line becomes an output driven to default_value (0 or 1).
  virtual int lineRequestOutput(LineHandle line, const char* consumer, int default_value) = 0;
  // gpiod_line_request_both_edges_events
  virtual int lineRequestBothEdgesEvents(LineHandle line, const char* consumer) = 0;
  // gpiod_line_set_value
  virtual int lineSetValue(LineHandle line, int value) = 0;
  // gpiod_line_event_wait: ready = true when an event can be read, false at the timeout.
  virtual int lineEventWait(LineHandle line, TimeNs timeout_ns, bool& ready) = 0;
  // gpiod_line_event_read: the oldest pending event.
  virtual int lineEventRead(LineHandle line, LineEvent& event) = 0;
  // gpiod_line_release
  virtual void lineRelease(LineHandle line) = 0;
};

// Forwards to libgpiod.
class LibgpiodApi final : public GpioApi {
 public:
  int chipOpen(const char* name_or_path, ChipHandle& chip) override;
  void chipClose(ChipHandle chip) override;
  int chipGetLine(ChipHandle chip, unsigned offset, LineHandle& line) override;
  int lineRequestOutput(LineHandle line, const char* consumer, int default_value) override;
  int lineRequestBothEdgesEvents(LineHandle line, const char* consumer) override;
  int lineSetValue(LineHandle line, int value) override;
  int lineEventWait(LineHandle line, TimeNs timeout_ns, bool& ready) override;
  int lineEventRead(LineHandle line, LineEvent& event) override;
  void lineRelease(LineHandle line) override;
};

// The process-wide LibgpiodApi.
GpioApi& libgpiodApi();

}  // namespace sunvo::gpio
