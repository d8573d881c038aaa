#include "sunvo/backend/rate_spread.hpp"

#include <algorithm>
#include <cmath>

namespace sunvo::backend {

void RateSpread::setCapacity(int frames) {
  capacity_ = std::clamp(frames, 0, kMaxFrames);
  clear();
}

void RateSpread::clear() {
  head_ = 0;
  size_ = 0;
  can_undo_ = false;
  overwrote_ = false;
}

bool RateSpread::push(const Eigen::Vector3d& rate_rad_s) {
  if (capacity_ == 0 || !rate_rad_s.allFinite()) return false;
  const auto h = static_cast<std::size_t>(head_);
  overwrote_ = size_ == capacity_;
  for (std::size_t a = 0; a < 3; ++a) {
    overwritten_[a] = ring_[a][h];
    ring_[a][h] = std::abs(rate_rad_s[static_cast<Eigen::Index>(a)]);
  }
  head_ = (head_ + 1) % capacity_;
  if (!overwrote_) ++size_;
  can_undo_ = true;
  return true;
}

bool RateSpread::undoLastPush() {
  if (!can_undo_) return false;
  head_ = (head_ + capacity_ - 1) % capacity_;
  if (overwrote_) {
    const auto h = static_cast<std::size_t>(head_);
    for (std::size_t a = 0; a < 3; ++a) ring_[a][h] = overwritten_[a];
  } else {
    --size_;
  }
  can_undo_ = false;
  return true;
}

Eigen::Vector3d RateSpread::spread() const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  if (!ready()) return s;
  const auto n = static_cast<std::ptrdiff_t>(size_);
  for (std::size_t a = 0; a < 3; ++a) {
    // The samples are the first size_ slots (the ring fills from 0 and then stays full).
    std::copy(ring_[a].begin(), ring_[a].begin() + n, scratch_.begin());
    const auto mid = scratch_.begin() + n / 2;
    std::nth_element(scratch_.begin(), mid, scratch_.begin() + n);
    double median = *mid;
    if (n % 2 == 0) median = 0.5 * (median + *std::max_element(scratch_.begin(), mid));
    s[static_cast<Eigen::Index>(a)] = 1.4826 * median;
  }
  return s;
}

}  // namespace sunvo::backend
