#include "rover_state.hpp"

#include <cmath>

namespace sunvo::rover {

// A sequence lock with atomic payload and no standalone fences (ThreadSanitizer models orderings
// on atomics, not fences). The payload stores are release: a reader whose acquire load sees a
// value of a newer publish() also sees that publish's odd sequence number afterwards, so its
// final sequence check fails and it retries.
void AttitudeMailbox::publish(const Eigen::Quaterniond& q) {
  const std::uint64_t s0 = seq_.load(std::memory_order_relaxed);
  seq_.store(s0 + 1, std::memory_order_relaxed);
  q_[0].store(q.w(), std::memory_order_release);
  q_[1].store(q.x(), std::memory_order_release);
  q_[2].store(q.y(), std::memory_order_release);
  q_[3].store(q.z(), std::memory_order_release);
  seq_.store(s0 + 2, std::memory_order_release);
}

bool AttitudeMailbox::latest(Eigen::Quaterniond* q) const {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t s0 = seq_.load(std::memory_order_acquire);
    if (s0 == 0) return false;  // no pose yet
    if (s0 & 1U) continue;      // being written
    const double w = q_[0].load(std::memory_order_acquire);
    const double x = q_[1].load(std::memory_order_acquire);
    const double y = q_[2].load(std::memory_order_acquire);
    const double z = q_[3].load(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != s0) continue;
    *q = Eigen::Quaterniond(w, x, y, z);
    return std::isfinite(q->norm()) && q->norm() > 0.5;
  }
  return false;
}

}  // namespace sunvo::rover
