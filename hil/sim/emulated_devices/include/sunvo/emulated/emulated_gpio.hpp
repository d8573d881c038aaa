#pragma once
// EmulatedGpio: GPIO chips in user space behind the gpio::GpioApi seam, with libgpiod v1.6's
// semantics for the calls sunvo makes: a chip opens by name or /dev path (ENOENT otherwise); a
// line offset past the chip's lines is EINVAL; requesting a line already requested is EBUSY;
// set-value on a line that is not an output, or waiting/reading events on a line not requested
// for events, is EPERM; closing a chip releases its lines.
//
// Output lines record every value written with the monotonic time of the write. Input lines
// receive edges from strobe()/pushEdge() with the kernel timestamp the test chooses; faults:
// strobes that never arrive (missed triggers), strobes that arrive twice (duplicate triggers) and
// a one-shot errno on the next call. Thread-safe: a test thread may strobe while a reader waits.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/gpio/gpio_api.hpp"

namespace sunvo::emulated {

struct GpioWrite {
  int value = 0;
  TimeNs time_ns = 0;  // sysio::monotonicNowNs() at the write
};

class EmulatedGpio final : public gpio::GpioApi {
 public:
  EmulatedGpio();
  ~EmulatedGpio() override;

  // A chip opened as "name" or "/dev/name", with lines 0 .. num_lines - 1.
  Status addChip(const std::string& name, int num_lines);

  // A strobe pulse on an input line: a rising edge stamped time_ns and a falling one width_ns
  // later, unless a fault says otherwise. Lines not requested for events ignore it (as a kernel
  // does with edges nobody listens to).
  Status strobe(const std::string& chip, int line, TimeNs time_ns, TimeNs width_ns);
  // One raw edge.
  Status pushEdge(const std::string& chip, int line, TimeNs time_ns, bool rising);

  // Faults on a line: the next `count` strobes never arrive; the next `count` strobes arrive
  // twice, the copy gap_ns after the original; the next API call on the line fails with err.
  Status dropStrobes(const std::string& chip, int line, int count);
  Status duplicateStrobes(const std::string& chip, int line, int count, TimeNs gap_ns);
  Status failNextCall(const std::string& chip, int line, int err);

  // Called after every value written to an output line (value, monotonic time of the write),
  // outside the lock: wires a trigger output to emulated cameras, e.g.
  // [&](int v, TimeNs t) { if (v == 1) cameras.trigger(t + exposure_delay); }.
  using OutputListener = std::function<void(int value, TimeNs time_ns)>;
  Status onOutput(const std::string& chip, int line, OutputListener listener);

  // Introspection (an unknown chip or line reads as empty, 0 or false).
  std::vector<GpioWrite> writes(const std::string& chip, int line) const;
  int value(const std::string& chip, int line) const;
  bool requested(const std::string& chip, int line) const;
  int openChips() const;

  // gpio::GpioApi
  int chipOpen(const char* name_or_path, gpio::ChipHandle& chip) override;
  void chipClose(gpio::ChipHandle chip) override;
  int chipGetLine(gpio::ChipHandle chip, unsigned offset, gpio::LineHandle& line) override;
  int lineRequestOutput(gpio::LineHandle line, const char* consumer, int default_value) override;
  int lineRequestBothEdgesEvents(gpio::LineHandle line, const char* consumer) override;
  int lineSetValue(gpio::LineHandle line, int value) override;
  int lineEventWait(gpio::LineHandle line, TimeNs timeout_ns, bool& ready) override;
  int lineEventRead(gpio::LineHandle line, gpio::LineEvent& event) override;
  void lineRelease(gpio::LineHandle line) override;

 private:
  struct Line;
  struct Chip;

  Line* findLine(const std::string& chip, int line) const;
  // Runs change on the named line under the lock, then wakes waiters.
  Status withLine(const std::string& chip, int line, const std::function<void(Line&)>& change);
  int takeFault(Line& l);
  // lineRequestOutput (output = true) and lineRequestBothEdgesEvents.
  int request(gpio::LineHandle line, const char* consumer, bool output, int default_value);

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::unique_ptr<Chip>> chips_;
};

}  // namespace sunvo::emulated
