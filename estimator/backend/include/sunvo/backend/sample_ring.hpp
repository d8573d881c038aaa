#pragma once
// The last N samples of a few values each, in fixed memory, with the median of each value and a
// one-step undo: the window's learnt quantities (RateSpread, TravelDirection) keep one sample per
// solve and must take it back when the caller rejects that solve (restoreInitialGuess()).
//
// No allocation (a ring of kMaxSamples per value and a scratch copy for the median), no threads.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace sunvo::backend {

template <int kDims, int kMaxSamples>
class SampleRing {
 public:
  // n: samples kept, clamped to [0, kMaxSamples]; 0 keeps nothing. Clears the ring.
  void setCapacity(int n) {
    capacity_ = std::clamp(n, 0, kMaxSamples);
    clear();
  }
  void clear() {
    head_ = 0;
    size_ = 0;
    can_undo_ = false;
    overwrote_ = false;
  }

  // Keeps the sample, replacing the oldest when full. A sample with a non-finite value is not
  // kept (returns false), nor is any with a capacity of 0.
  bool push(const std::array<double, kDims>& sample) {
    if (capacity_ == 0 ||
        !std::all_of(sample.begin(), sample.end(), [](double x) { return std::isfinite(x); })) {
      return false;
    }
    const auto h = static_cast<std::size_t>(head_);
    overwrote_ = size_ == capacity_;
    for (std::size_t a = 0; a < kDims; ++a) {
      overwritten_[a] = ring_[a][h];
      ring_[a][h] = sample[a];
    }
    head_ = (head_ + 1) % capacity_;
    if (!overwrote_) ++size_;
    can_undo_ = true;
    return true;
  }
  // Takes back the newest push() made since the last commit(); false when there is none.
  bool undoLastPush() {
    if (!can_undo_) return false;
    head_ = (head_ + capacity_ - 1) % capacity_;
    if (overwrote_) {
      const auto h = static_cast<std::size_t>(head_);
      for (std::size_t a = 0; a < kDims; ++a) ring_[a][h] = overwritten_[a];
    } else {
      --size_;
    }
    can_undo_ = false;
    return true;
  }
  // Makes the samples pushed so far final (undoLastPush() no longer takes them back).
  void commit() { can_undo_ = false; }

  // The median of value dim over the kept samples (the mean of the middle two for an even count);
  // 0 when there are none.
  double median(int dim) const {
    if (size_ == 0) return 0.0;
    // The samples are the first size_ slots (the ring fills from 0 and then stays full).
    const auto& values = ring_[static_cast<std::size_t>(dim)];
    const auto n = static_cast<std::ptrdiff_t>(size_);
    std::copy(values.begin(), values.begin() + n, scratch_.begin());
    const auto mid = scratch_.begin() + n / 2;
    std::nth_element(scratch_.begin(), mid, scratch_.begin() + n);
    double m = *mid;
    if (n % 2 == 0) m = 0.5 * (m + *std::max_element(scratch_.begin(), mid));
    return m;
  }
  int size() const { return size_; }
  int capacity() const { return capacity_; }

 private:
  std::array<std::array<double, kMaxSamples>, kDims> ring_{};
  std::array<double, kDims> overwritten_{};  // the samples the newest push() replaced
  bool overwrote_ = false;                   // whether it replaced samples (ring full)
  bool can_undo_ = false;
  int capacity_ = 0;
  int head_ = 0;  // next slot to write
  int size_ = 0;
  mutable std::array<double, kMaxSamples> scratch_{};
};

}  // namespace sunvo::backend
