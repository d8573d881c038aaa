#include "sunvo/runtime/rt_setup.hpp"

#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "sunvo/runtime/clock.hpp"

namespace sunvo::runtime {
namespace {

std::string errnoText(int e) {
  return std::string(strerrordesc_np(e) != nullptr ? strerrordesc_np(e) : "unknown") + " (" +
         (strerrorname_np(e) != nullptr ? strerrorname_np(e) : "?") + ")";
}

}  // namespace

Status ThreadPolicy::validate(const std::string& key) const {
  if (fifo_priority < 0 || fifo_priority > 99) {
    return invalidArgument(key + ".fifo_priority: " + std::to_string(fifo_priority) +
                           " is outside [0, 99]");
  }
  if (cpu < -1 || cpu > 1023) {
    return invalidArgument(key + ".cpu: " + std::to_string(cpu) + " is outside [-1, 1023]");
  }
  return Status::ok();
}

std::string lockProcessMemory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  const int e = errno;
  return "warning: rt.lock_memory: mlockall(MCL_CURRENT|MCL_FUTURE) failed: " + errnoText(e) +
         "; pages may be swapped out (needs CAP_IPC_LOCK or a larger RLIMIT_MEMLOCK)";
}

std::string configureRealTimeHeap() {
  // mallopt returns 1 on success.
  if (mallopt(M_ARENA_MAX, 1) != 1 || mallopt(M_MMAP_MAX, 0) != 1 ||
      mallopt(M_TRIM_THRESHOLD, -1) != 1) {
    return "warning: rt.heap_reserve_mb: mallopt (M_ARENA_MAX, M_MMAP_MAX, M_TRIM_THRESHOLD) "
           "failed; the heap may keep growing";
  }
  return {};
}

std::string reserveHeap(std::size_t bytes) {
  if (bytes == 0) return {};
  auto* p = static_cast<volatile char*>(std::malloc(bytes));
  if (p == nullptr) {
    return "warning: rt.heap_reserve_mb: could not reserve " + std::to_string(bytes >> 20) +
           " MiB; the heap may grow while running";
  }
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  for (std::size_t i = 0; i < bytes; i += page) p[i] = 0;
  std::free(const_cast<char*>(p));
  return {};
}

std::string applyThreadPolicy(const std::string& key, const std::string& thread_name,
                              const ThreadPolicy& policy) {
  std::string warnings;
  const pthread_t self = pthread_self();
  pthread_setname_np(self, thread_name.substr(0, 15).c_str());
  if (policy.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = policy.fifo_priority;
    const int e = pthread_setschedparam(self, SCHED_FIFO, &sp);
    if (e != 0) {
      warnings += "warning: " + key + ".fifo_priority: SCHED_FIFO " +
                  std::to_string(policy.fifo_priority) + " not set: " + errnoText(e) +
                  "; the thread runs SCHED_OTHER (needs CAP_SYS_NICE or an RLIMIT_RTPRIO)";
    }
  }
  if (policy.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(policy.cpu), &set);
    const int e = pthread_setaffinity_np(self, sizeof(set), &set);
    if (e != 0) {
      if (!warnings.empty()) warnings += '\n';
      warnings += "warning: " + key + ".cpu: affinity to CPU " + std::to_string(policy.cpu) +
                  " not set: " + errnoText(e) + "; the thread may run on any CPU";
    }
  }
  return warnings;
}

void sleepUntilMonotonicNs(TimeNs t_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(t_ns % kNsPerSecond);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace sunvo::runtime
