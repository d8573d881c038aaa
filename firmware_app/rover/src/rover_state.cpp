#include "rover_state.hpp"

#include <cmath>

namespace sunvo::rover {

void AttitudeMailbox::publish(const Eigen::Quaterniond& q) {
  const std::uint64_t s0 = seq_.load(std::memory_order_relaxed);
  seq_.store(s0 + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  q_[0].store(q.w(), std::memory_order_relaxed);
  q_[1].store(q.x(), std::memory_order_relaxed);
  q_[2].store(q.y(), std::memory_order_relaxed);
  q_[3].store(q.z(), std::memory_order_relaxed);
  seq_.store(s0 + 2, std::memory_order_release);
}

bool AttitudeMailbox::latest(Eigen::Quaterniond* q) const {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t s0 = seq_.load(std::memory_order_acquire);
    if (s0 == 0) return false;  // no pose yet
    if (s0 & 1U) continue;      // being written
    const double w = q_[0].load(std::memory_order_relaxed);
    const double x = q_[1].load(std::memory_order_relaxed);
    const double y = q_[2].load(std::memory_order_relaxed);
    const double z = q_[3].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != s0) continue;
    *q = Eigen::Quaterniond(w, x, y, z);
    return std::isfinite(q->norm()) && q->norm() > 0.5;
  }
  return false;
}

}  // namespace sunvo::rover
