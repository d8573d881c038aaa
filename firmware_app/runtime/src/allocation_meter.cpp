#include "sunvo/runtime/allocation_meter.hpp"

namespace sunvo::runtime {
namespace {
std::atomic<ThreadAllocationProbe> g_probe{nullptr};
}  // namespace

void setThreadAllocationProbe(ThreadAllocationProbe probe) {
  g_probe.store(probe, std::memory_order_release);
}

bool allocationProbeInstalled() {
  return g_probe.load(std::memory_order_acquire) != nullptr;
}

void AllocationMeter::frameDone() {
  const ThreadAllocationProbe probe = g_probe.load(std::memory_order_acquire);
  if (probe == nullptr) return;
  const std::uint64_t now = probe();
  ++seen_;
  if (seen_ > warmup_) {
    allocs_.fetch_add(now - last_, std::memory_order_relaxed);
    frames_.fetch_add(1, std::memory_order_relaxed);
  }
  last_ = now;
}

double AllocationMeter::perFrame() const {
  const std::uint64_t n = framesMeasured();
  return n == 0 ? 0.0 : static_cast<double>(allocationsAfterWarmup()) / static_cast<double>(n);
}

}  // namespace sunvo::runtime
