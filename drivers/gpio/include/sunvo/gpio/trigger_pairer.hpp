#pragma once
// TriggerPairer: matches camera frames to trigger events by time, and counts what does not match.
//
// Triggers (pulses sent or strobe edges read, gpio::TriggerEvent) go in with addTrigger(); each
// frame's driver timestamp goes to matchFrame(), which returns the trigger that caused it: the one
// closest to frame_time - expected_delay_ns within match_window_ns. Both clocks must be the same
// (V4L2 buffer timestamps and GPIO event timestamps are both CLOCK_MONOTONIC on current kernels).
//
// Counted: frames with no trigger; triggers with no frame (older than every frame that could still
// match them, or pushed out of the full ring); duplicate triggers (a trigger closer to the previous
// one than duplicate_fraction of a frame period: a bouncing or doubled edge; the first is kept).
// Pure logic: a fixed ring allocated in create(), nothing allocated per call, no clock, no I/O.

#include <cstdint>
#include <optional>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/gpio/trigger.hpp"

namespace sunvo::gpio {

struct TriggerPairerOptions {
  int capacity = 64;                     // triggers held while waiting for frames, [2, 65536]
  TimeNs frame_period_ns = 100'000'000;  // nominal trigger period, (0, 10 s]
  TimeNs expected_delay_ns = 0;          // frame timestamp minus its trigger time, [-1 s, 1 s]
  TimeNs match_window_ns = 10'000'000;   // largest |frame - delay - trigger|, [0, period / 2]
  double duplicate_fraction = 0.5;       // closer triggers are duplicates, (0, 1] of a period

  Status validate() const;  // names the bad key, e.g. "trigger_pairer.match_window_ns"
};

struct TriggerPairerCounters {
  std::uint64_t triggers = 0;                // triggers accepted into the ring
  std::uint64_t duplicate_triggers = 0;      // dropped as duplicates
  std::uint64_t out_of_order_triggers = 0;   // older than the newest one held: dropped
  std::uint64_t frames = 0;                  // matchFrame() calls
  std::uint64_t paired = 0;                  // frames matched to a trigger
  std::uint64_t frames_without_trigger = 0;  // missed trigger seen from the frame side
  std::uint64_t triggers_without_frame = 0;  // missed frame seen from the trigger side
};

class TriggerPairer {
 public:
  static Expected<TriggerPairer> create(const TriggerPairerOptions& options);

  void addTrigger(const TriggerEvent& trigger);
  // The trigger of the frame stamped frame_time_ns, removed from the ring; nullopt if none.
  // Triggers older than the window of this frame are discarded as triggers_without_frame, so
  // frames must come in time order.
  std::optional<TriggerEvent> matchFrame(TimeNs frame_time_ns);

  int pending() const { return size_; }
  const TriggerPairerCounters& counters() const { return counters_; }
  const TriggerPairerOptions& options() const { return options_; }

 private:
  explicit TriggerPairer(const TriggerPairerOptions& options);
  const TriggerEvent& at(int i) const;  // i-th oldest
  void popOldest();

  TriggerPairerOptions options_;
  std::vector<TriggerEvent> ring_;
  int head_ = 0;  // index of the oldest
  int size_ = 0;
  bool have_newest_ = false;
  TimeNs newest_ns_ = 0;  // the last accepted trigger's time, kept after it is matched
  TriggerPairerCounters counters_;
};

}  // namespace sunvo::gpio
