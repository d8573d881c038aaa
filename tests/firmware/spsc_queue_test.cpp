#include "sunvo/runtime/spsc_queue.hpp"

#include <gtest/gtest.h>

#include <thread>

#include "sunvo/runtime/event_count.hpp"

namespace sunvo::runtime {
namespace {

TEST(SpscQueue, FifoAndCounters) {
  SpscQueue<std::uint32_t> q(4, QueuePolicy::kDropOldest);
  EXPECT_EQ(q.capacity(), 4u);
  std::uint32_t v = 0;
  EXPECT_FALSE(q.pop(&v));
  for (std::uint32_t i = 0; i < 3; ++i) EXPECT_TRUE(q.push(i));
  EXPECT_EQ(q.size(), 3u);
  for (std::uint32_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(q.pop(&v));
    EXPECT_EQ(v, i);
  }
  const QueueCounters c = q.counters();
  EXPECT_EQ(c.pushed, 3u);
  EXPECT_EQ(c.popped, 3u);
  EXPECT_EQ(c.dropped, 0u);
  EXPECT_EQ(c.high_water, 3u);
}

TEST(SpscQueue, DropOldestHandsBackTheDroppedItem) {
  SpscQueue<std::uint64_t> q(2, QueuePolicy::kDropOldest);
  std::uint64_t dropped = 99;
  bool did = true;
  EXPECT_TRUE(q.push(10, &dropped, &did));
  EXPECT_FALSE(did);
  EXPECT_TRUE(q.push(11, &dropped, &did));
  EXPECT_FALSE(did);
  EXPECT_TRUE(q.push(12, &dropped, &did));  // full: 10 leaves
  EXPECT_TRUE(did);
  EXPECT_EQ(dropped, 10u);
  std::uint64_t v = 0;
  ASSERT_TRUE(q.pop(&v));
  EXPECT_EQ(v, 11u);
  ASSERT_TRUE(q.pop(&v));
  EXPECT_EQ(v, 12u);
  EXPECT_EQ(q.counters().dropped, 1u);
  EXPECT_EQ(q.counters().high_water, 2u);
}

TEST(SpscQueue, RejectPolicyKeepsTheQueueAndCounts) {
  SpscQueue<std::uint32_t> q(2, QueuePolicy::kReject);
  EXPECT_TRUE(q.push(1));
  EXPECT_TRUE(q.push(2));
  EXPECT_FALSE(q.push(3));
  EXPECT_EQ(q.counters().rejected, 1u);
  std::uint32_t v = 0;
  ASSERT_TRUE(q.pop(&v));
  EXPECT_EQ(v, 1u);
}

TEST(SpscQueue, CapacityRoundsUpToAPowerOfTwo) {
  SpscQueue<std::uint32_t> q(5, QueuePolicy::kReject);
  EXPECT_EQ(q.capacity(), 8u);
  EXPECT_TRUE(isPowerOfTwo(1));
  EXPECT_TRUE(isPowerOfTwo(64));
  EXPECT_FALSE(isPowerOfTwo(0));
  EXPECT_FALSE(isPowerOfTwo(12));
}

// A multi-word item must never arrive torn, even when the producer overwrites the slot the
// consumer is copying (drop-oldest under contention).
struct Wide {
  std::uint64_t seq;
  std::uint64_t a, b, c;  // all equal to seq
};

TEST(SpscQueue, ConcurrentDropOldestDeliversWholeItemsInOrder) {
  constexpr std::uint64_t kItems = 400000;
  SpscQueue<Wide> q(8, QueuePolicy::kDropOldest);
  EventCount ev;
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t i = 1; i <= kItems; ++i) {
      q.push({i, i, i, i});
      if (i % 64 == 0) ev.notify();
    }
    done.store(true);
    ev.notify();
  });
  std::uint64_t last = 0, received = 0, torn = 0, disorder = 0;
  for (;;) {
    const std::uint32_t key = ev.prepare();
    Wide w{};
    if (q.pop(&w)) {
      ++received;
      if (w.a != w.seq || w.b != w.seq || w.c != w.seq) ++torn;
      if (w.seq <= last) ++disorder;
      last = w.seq;
      continue;
    }
    if (done.load() && q.size() == 0) break;
    ev.wait(key, 1'000'000);
  }
  producer.join();
  const QueueCounters c = q.counters();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(disorder, 0u);
  EXPECT_EQ(c.pushed, kItems);
  EXPECT_EQ(c.popped, received);
  EXPECT_EQ(c.popped + c.dropped, kItems);  // every item left exactly once
  EXPECT_EQ(last, kItems);                  // the newest item always arrives
  EXPECT_LE(c.high_water, 8u);
}

TEST(EventCount, WaitReturnsOnNotifyOrTimeout) {
  EventCount ev;
  const auto t0 = std::chrono::steady_clock::now();
  ev.wait(ev.prepare(), 20'000'000);  // nobody notifies: ~20 ms
  const double waited_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited_ms, 15.0);
  const std::uint32_t key = ev.prepare();
  ev.notify();
  const auto t1 = std::chrono::steady_clock::now();
  ev.wait(key, 5'000'000'000);  // the epoch moved: returns at once
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 1.0);
}

}  // namespace
}  // namespace sunvo::runtime
