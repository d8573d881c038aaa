#pragma once
// Heap allocations per frame of one thread after warm-up, for the real-time claims (0 per frame
// in capture and telemetry). The count comes from a probe the executable installs (sunvo_rover
// links firmware_app/alloc_counter's counting malloc, whose per-thread counter it passes here); without a probe
// the meter reports "not measured".

#include <atomic>
#include <cstdint>

namespace sunvo::runtime {

// Allocation calls made by the calling thread so far.
using ThreadAllocationProbe = std::uint64_t (*)();
void setThreadAllocationProbe(ThreadAllocationProbe probe);
bool allocationProbeInstalled();

class AllocationMeter {
 public:
  // warmup_frames: frames whose allocations are not counted (buffers growing to size).
  explicit AllocationMeter(std::uint64_t warmup_frames = 0) : warmup_(warmup_frames) {}
  void setWarmup(std::uint64_t frames) { warmup_ = frames; }
  // Called by the owning thread at the end of each frame's work.
  void frameDone();

  std::uint64_t framesMeasured() const { return frames_.load(std::memory_order_relaxed); }
  std::uint64_t allocationsAfterWarmup() const { return allocs_.load(std::memory_order_relaxed); }
  double perFrame() const;

 private:
  std::uint64_t warmup_;
  std::uint64_t seen_ = 0;  // frames so far (owning thread)
  std::uint64_t last_ = 0;  // probe value at the last frame end (owning thread)
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> allocs_{0};
};

}  // namespace sunvo::runtime
