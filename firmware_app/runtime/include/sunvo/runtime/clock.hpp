#pragma once
// The program's two clocks: monotonic ns for latency and deadlines, UTC ns for frame times.

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
inline TimeNs utcNowNs() {
  return clockNs(CLOCK_REALTIME);
}
// Sleeps until the monotonic time t_ns (returns at once when it has passed).
void sleepUntilMonotonicNs(TimeNs t_ns);

}  // namespace sunvo::runtime
