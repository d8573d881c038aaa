#include "sunvo/runtime/event_count.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace sunvo::runtime {

// std::atomic<uint32_t> is a plain 32-bit word on Linux (the futex's requirement).
static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));

void EventCount::wait(std::uint32_t key, TimeNs timeout_ns) {
  if (epoch_.load(std::memory_order_acquire) != key) return;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(timeout_ns / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(timeout_ns % kNsPerSecond);
  // Returns at once (EAGAIN) when the epoch moved; EINTR and ETIMEDOUT are normal returns.
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&epoch_), FUTEX_WAIT_PRIVATE, key, &ts,
          nullptr, 0);
}

void EventCount::notify() {
  epoch_.fetch_add(1, std::memory_order_release);
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&epoch_), FUTEX_WAKE_PRIVATE, 1, nullptr,
          nullptr, 0);
}

}  // namespace sunvo::runtime
