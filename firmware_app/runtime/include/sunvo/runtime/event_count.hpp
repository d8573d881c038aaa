#pragma once
// Sleeping on a lock-free queue without a lock: an event count on a Linux futex.
//
//   consumer:  for (;;) { const auto key = ev.prepare(); if (q.pop(&x)) break; ev.wait(key, t); }
//   producer:  q.push(x); ev.notify();
//
// prepare() reads the epoch before the consumer looks at the queue; notify() bumps it after the
// producer queued, so a push between the check and the sleep makes wait() return at once (the
// futex compares the epoch). No allocation, no mutex; a spurious wake-up is harmless.

#include <atomic>
#include <cstdint>

#include "sunvo/core/time.hpp"

namespace sunvo::runtime {

class EventCount {
 public:
  std::uint32_t prepare() const { return epoch_.load(std::memory_order_acquire); }
  // Sleeps until notify() after prepare() returned `key`, or timeout_ns (> 0) passed.
  void wait(std::uint32_t key, TimeNs timeout_ns);
  void notify();

 private:
  std::atomic<std::uint32_t> epoch_{0};
};

}  // namespace sunvo::runtime
