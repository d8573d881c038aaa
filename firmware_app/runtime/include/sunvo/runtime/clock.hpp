#pragma once
// The program's two clocks: monotonic ns for latency and deadlines, UTC ns for frame times.
// UTC is read through utcNowNs() only, the seam through which a test steps the wall clock
// (injectUtcStep), as settimeofday or an NTP step would, without touching the machine's clock.

#include <time.h>

#include "sunvo/core/time.hpp"

namespace sunvo::runtime {

inline TimeNs clockNs(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}
inline TimeNs monotonicNs() {
  return clockNs(CLOCK_MONOTONIC);
}
// Sum of the steps injectUtcStep() added (0 unless a test injected a clock jump).
TimeNs injectedUtcStepNs();
// Fault injection: every later utcNowNs() in this process reads CLOCK_REALTIME + step_ns more
// (steps add up; inject -step to undo). Thread-safe. Never called by the program itself.
void injectUtcStep(TimeNs step_ns);
inline TimeNs utcNowNs() {
  return clockNs(CLOCK_REALTIME) + injectedUtcStepNs();
}
// Sleeps until the monotonic time t_ns (returns at once when it has passed).
void sleepUntilMonotonicNs(TimeNs t_ns);

}  // namespace sunvo::runtime
