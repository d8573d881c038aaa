#include "sunvo/runtime/clock.hpp"

#include <atomic>

namespace sunvo::runtime {
namespace {
std::atomic<TimeNs> g_utc_step_ns{0};
}  // namespace

TimeNs injectedUtcStepNs() {
  return g_utc_step_ns.load(std::memory_order_relaxed);
}

void injectUtcStep(TimeNs step_ns) {
  g_utc_step_ns.fetch_add(step_ns, std::memory_order_relaxed);
}

}  // namespace sunvo::runtime
