#include <gpiod.h>

#include <cerrno>
#include <ctime>

#include "sunvo/gpio/gpio_api.hpp"

namespace sunvo::gpio {
namespace {

gpiod_chip* chipOf(ChipHandle h) {
  return static_cast<gpiod_chip*>(h.impl);
}
gpiod_line* lineOf(LineHandle h) {
  return static_cast<gpiod_line*>(h.impl);
}
// libgpiod reports failure as -1 with errno; errno 0 there would still be a failure.
int lastError() {
  return errno != 0 ? errno : EIO;
}

}  // namespace

int LibgpiodApi::chipOpen(const char* name_or_path, ChipHandle& chip) {
  errno = 0;
  gpiod_chip* c = gpiod_chip_open_lookup(name_or_path);
  if (c == nullptr) return errno != 0 ? errno : ENOENT;
  chip.impl = c;
  return 0;
}

void LibgpiodApi::chipClose(ChipHandle chip) {
  if (chip) gpiod_chip_close(chipOf(chip));
}

int LibgpiodApi::chipGetLine(ChipHandle chip, unsigned offset, LineHandle& line) {
  errno = 0;
  gpiod_line* l = gpiod_chip_get_line(chipOf(chip), offset);
  if (l == nullptr) return lastError();
  line.impl = l;
  return 0;
}

int LibgpiodApi::lineRequestOutput(LineHandle line, const char* consumer, int default_value) {
  return gpiod_line_request_output(lineOf(line), consumer, default_value) == 0 ? 0 : lastError();
}

int LibgpiodApi::lineRequestBothEdgesEvents(LineHandle line, const char* consumer) {
  return gpiod_line_request_both_edges_events(lineOf(line), consumer) == 0 ? 0 : lastError();
}

int LibgpiodApi::lineSetValue(LineHandle line, int value) {
  return gpiod_line_set_value(lineOf(line), value) == 0 ? 0 : lastError();
}

int LibgpiodApi::lineEventWait(LineHandle line, TimeNs timeout_ns, bool& ready) {
  const timespec timeout{static_cast<time_t>(timeout_ns / kNsPerSecond),
                         static_cast<long>(timeout_ns % kNsPerSecond)};
  const int rc = gpiod_line_event_wait(lineOf(line), &timeout);
  if (rc < 0) return lastError();
  ready = rc == 1;
  return 0;
}

int LibgpiodApi::lineEventRead(LineHandle line, LineEvent& event) {
  gpiod_line_event e{};
  if (gpiod_line_event_read(lineOf(line), &e) != 0) return lastError();
  event.time_ns = static_cast<TimeNs>(e.ts.tv_sec) * kNsPerSecond + e.ts.tv_nsec;
  event.rising = e.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
  return 0;
}

void LibgpiodApi::lineRelease(LineHandle line) {
  if (line) gpiod_line_release(lineOf(line));
}

GpioApi& libgpiodApi() {
  static LibgpiodApi api;
  return api;
}

}  // namespace sunvo::gpio
