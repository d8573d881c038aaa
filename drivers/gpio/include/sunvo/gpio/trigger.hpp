#pragma once
// Camera trigger over GPIO: TriggerOutput drives a pulse train to the cameras' trigger inputs;
// StrobeInput reads the cameras' strobe (exposure) edges with kernel timestamps. Both reach
// libgpiod only through a GpioApi& (tests: hil/sim/emulated_devices' EmulatedGpio).
// Neither owns a thread: the program's trigger thread calls them.

#include <cstdint>
#include <memory>
#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/gpio/gpio_api.hpp"

namespace sunvo::gpio {

// One trigger: a pulse sent or a strobe edge read.
struct TriggerEvent {
  std::uint64_t sequence = 0;  // 0, 1, 2, ... per TriggerOutput / StrobeInput
  TimeNs time_ns = 0;          // pulse: the caller's time at the rising edge; strobe: kernel time
};

// The chip and line shared by both directions.
struct GpioLineOptions {
  std::string chip = "gpiochip0";  // name, /dev path, number or label (gpiod_chip_open_lookup)
  int line = 0;                    // line offset on the chip, [0, 1023]
  std::string consumer = "sunvo";  // label shown by gpioinfo, non-empty

  // prefix names the section in messages, e.g. "trigger_output".
  Status validate(const char* prefix) const;
};

struct TriggerOutputOptions {
  GpioLineOptions gpio{"gpiochip0", 0, "sunvo-trigger"};
  double rate_hz = 10.0;     // pulses per second, (0, 1000]
  int pulse_width_us = 500;  // active time of a pulse, [1, 100000] µs, less than half the period
  bool active_low = false;   // true: the pulse drives the line low, idle high

  Status validate() const;  // names the bad key, e.g. "trigger_output.rate_hz"
};

struct TriggerOutputCounters {
  std::uint64_t pulses = 0;        // pulses driven
  std::uint64_t missed_slots = 0;  // grid slots with no pulse because pulse() came late
  std::uint64_t errors = 0;        // failed set-value calls
};

class TriggerOutput {
 public:
  // Requests the line as an output at its idle level.
  static Expected<std::unique_ptr<TriggerOutput>> open(const TriggerOutputOptions& options,
                                                       GpioApi& api);
  TriggerOutput(const TriggerOutput&) = delete;
  TriggerOutput& operator=(const TriggerOutput&) = delete;
  ~TriggerOutput();  // line back to idle, released, chip closed

  // One pulse: the line goes active, stays so for pulse_width_us (a bounded sleep, the only one)
  // and goes back to idle. now_ns (the caller's clock) and the next sequence number become
  // lastPulse(). Pulses are spaced by the period: slots skipped since the last pulse count as
  // missed_slots.
  Status pulse(TimeNs now_ns);

  // Schedule helper: when to call pulse() next. The slots are t0 + k * period, t0 = the first
  // pulse's time; returns the first slot after the last pulse's one that is not before now_ns
  // (slots already past are skipped and later counted as missed). now_ns before any pulse.
  TimeNs nextPulseTime(TimeNs now_ns) const;

  TimeNs periodNs() const { return period_ns_; }
  const TriggerEvent& lastPulse() const { return last_; }
  bool hasPulsed() const { return counters_.pulses > 0; }
  const TriggerOutputCounters& counters() const { return counters_; }

 private:
  TriggerOutput(const TriggerOutputOptions& options, GpioApi& api);

  TriggerOutputOptions options_;
  GpioApi& api_;
  ChipHandle chip_;
  LineHandle line_;
  TimeNs period_ns_ = 0;
  TimeNs first_ns_ = 0;
  std::uint64_t last_slot_ = 0;
  TriggerEvent last_;
  TriggerOutputCounters counters_;
};

struct StrobeInputOptions {
  GpioLineOptions gpio{"gpiochip0", 1, "sunvo-strobe"};
  int wait_timeout_ms = 200;  // longest wait in one next(), [1, 60000]

  Status validate() const;  // names the bad key, e.g. "strobe_input.wait_timeout_ms"
};

struct StrobeInputCounters {
  std::uint64_t rising = 0;    // rising edges returned
  std::uint64_t falling = 0;   // falling edges read and skipped
  std::uint64_t timeouts = 0;  // next() calls that saw no rising edge in time
  std::uint64_t errors = 0;    // failed wait or read calls
};

class StrobeInput {
 public:
  // Requests both-edge events on the line.
  static Expected<std::unique_ptr<StrobeInput>> open(const StrobeInputOptions& options,
                                                     GpioApi& api);
  StrobeInput(const StrobeInput&) = delete;
  StrobeInput& operator=(const StrobeInput&) = delete;
  ~StrobeInput();

  // The next rising edge, {sequence, kernel timestamp}; waits at most wait_timeout_ms in all.
  // kTimeout when none came, kDeviceError (naming chip and line) when libgpiod fails.
  Expected<TriggerEvent> next();

  const StrobeInputCounters& counters() const { return counters_; }

 private:
  StrobeInput(const StrobeInputOptions& options, GpioApi& api);

  StrobeInputOptions options_;
  GpioApi& api_;
  ChipHandle chip_;
  LineHandle line_;
  std::uint64_t sequence_ = 0;
  StrobeInputCounters counters_;
};

}  // namespace sunvo::gpio
