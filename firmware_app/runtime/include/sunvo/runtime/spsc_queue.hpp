#pragma once
// A bounded single-producer/single-consumer ring for small trivially copyable items (pool
// indices, pose records), lock-free, sized once at construction (capacity a power of two).
//
// Policy when full:
//  - kDropOldest: the producer discards the oldest queued item (returned to it, e.g. to recycle
//    a pool slot) and queues the new one: the consumer always gets the freshest data.
//  - kReject: push() fails and the item stays with the producer (e.g. a free-list return that
//    must never lose a slot; size the queue so that it cannot fill).
//
// Drop-oldest needs the producer to move the consumer's read index. Both sides advance `tail_`
// by compare-and-swap, so an item leaves the ring exactly once: popped or dropped. The consumer
// copies an item before it claims it; if the producer dropped and overwrote that slot meanwhile,
// the claim fails and the copy is thrown away. The payload is kept in relaxed atomic words
// (a seqlock-style copy), so that such an overlap is not a data race.
//
// Counters (any thread may read them): pushed, dropped (drop-oldest), rejected (kReject full),
// popped, and the high-water mark of the fill level.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>

namespace sunvo::runtime {

enum class QueuePolicy { kDropOldest, kReject };

struct QueueCounters {
  std::uint64_t pushed = 0;
  std::uint64_t dropped = 0;
  std::uint64_t rejected = 0;
  std::uint64_t popped = 0;
  std::uint64_t high_water = 0;  // most items queued at once
  std::uint64_t capacity = 0;
};

// True for 1, 2, 4, ... (capacities of the ring).
constexpr bool isPowerOfTwo(std::size_t n) {
  return n > 0 && (n & (n - 1)) == 0;
}

template <typename T>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>, "SpscQueue items are copied as raw words");
  static constexpr std::size_t kWords = (sizeof(T) + sizeof(std::uint64_t) - 1) / 8;

 public:
  // capacity: a power of two >= 1 (checked by the caller's options; a wrong value is rounded up
  // to the next power of two so the ring's index arithmetic stays valid).
  SpscQueue(std::size_t capacity, QueuePolicy policy)
      : capacity_(roundUp(capacity)),
        mask_(capacity_ - 1),
        policy_(policy),
        slots_(std::make_unique<Slot[]>(capacity_)) {}
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  // Producer only. Returns false when the item was not queued (kReject and full). With
  // kDropOldest it always queues; when an older item had to make room it is copied to *dropped
  // (if not null) and *did_drop is set.
  bool push(const T& item, T* dropped = nullptr, bool* did_drop = nullptr) {
    if (did_drop != nullptr) *did_drop = false;
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    std::uint64_t tail = tail_.load(std::memory_order_acquire);
    if (head - tail >= capacity_) {
      if (policy_ == QueuePolicy::kReject) {
        rejected_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
      T old{};
      readSlot(tail, &old);
      // Claim the oldest item; when the consumer took it first there is room anyway.
      if (tail_.compare_exchange_strong(tail, tail + 1, std::memory_order_acq_rel)) {
        dropped_.fetch_add(1, std::memory_order_relaxed);
        if (dropped != nullptr) *dropped = old;
        if (did_drop != nullptr) *did_drop = true;
      }
    }
    writeSlot(head, item);
    head_.store(head + 1, std::memory_order_release);
    pushed_.fetch_add(1, std::memory_order_relaxed);
    const std::uint64_t level = head + 1 - tail_.load(std::memory_order_relaxed);
    if (level > high_water_.load(std::memory_order_relaxed)) {
      high_water_.store(level, std::memory_order_relaxed);
    }
    return true;
  }

  // Consumer only. False when empty.
  bool pop(T* out) {
    std::uint64_t tail = tail_.load(std::memory_order_acquire);
    for (;;) {
      const std::uint64_t head = head_.load(std::memory_order_acquire);
      if (tail == head) return false;
      T copy{};
      readSlot(tail, &copy);
      // Fails only when the producer dropped this item meanwhile; `tail` is then reloaded.
      if (tail_.compare_exchange_strong(tail, tail + 1, std::memory_order_acq_rel)) {
        *out = copy;
        popped_.fetch_add(1, std::memory_order_relaxed);
        return true;
      }
    }
  }

  std::size_t size() const {
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    return static_cast<std::size_t>(head - tail);
  }
  std::size_t capacity() const { return capacity_; }

  QueueCounters counters() const {
    QueueCounters c;
    c.pushed = pushed_.load(std::memory_order_relaxed);
    c.dropped = dropped_.load(std::memory_order_relaxed);
    c.rejected = rejected_.load(std::memory_order_relaxed);
    c.popped = popped_.load(std::memory_order_relaxed);
    c.high_water = high_water_.load(std::memory_order_relaxed);
    c.capacity = capacity_;
    return c;
  }

 private:
  struct Slot {
    std::array<std::atomic<std::uint64_t>, kWords> words;
  };

  static std::size_t roundUp(std::size_t n) {
    std::size_t c = 1;
    while (c < n) c <<= 1;
    return c;
  }

  void writeSlot(std::uint64_t index, const T& item) {
    std::array<std::uint64_t, kWords> raw{};
    std::memcpy(raw.data(), &item, sizeof(T));
    Slot& s = slots_[index & mask_];
    for (std::size_t i = 0; i < kWords; ++i) s.words[i].store(raw[i], std::memory_order_relaxed);
  }

  void readSlot(std::uint64_t index, T* item) const {
    std::array<std::uint64_t, kWords> raw{};
    const Slot& s = slots_[index & mask_];
    for (std::size_t i = 0; i < kWords; ++i) raw[i] = s.words[i].load(std::memory_order_relaxed);
    std::memcpy(static_cast<void*>(item), raw.data(), sizeof(T));
  }

  const std::size_t capacity_;
  const std::uint64_t mask_;
  const QueuePolicy policy_;
  std::unique_ptr<Slot[]> slots_;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // written by the producer
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // advanced by the consumer (and drop-oldest)
  alignas(64) std::atomic<std::uint64_t> pushed_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<std::uint64_t> high_water_{0};
  alignas(64) std::atomic<std::uint64_t> popped_{0};
};

}  // namespace sunvo::runtime
