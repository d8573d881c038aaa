#pragma once
// Real-time set-up of the process and its threads: locked memory, SCHED_FIFO priority and CPU
// affinity. Each call returns an empty string when it took effect, else one warning line naming
// the setting and the errno (e.g. without CAP_SYS_NICE / CAP_IPC_LOCK); the program prints it
// and runs on with the default policy.

#include <string>

#include "sunvo/core/status.hpp"

namespace sunvo::runtime {

struct ThreadPolicy {
  int fifo_priority = 0;  // SCHED_FIFO priority, [0, 99]; 0 = keep SCHED_OTHER
  int cpu = -1;           // CPU to pin the thread to, [-1, 1023]; -1 = no affinity
  // key: the config prefix for messages, e.g. "threads.capture".
  Status validate(const std::string& key) const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("fifo_priority", s.fifo_priority);
    v("cpu", s.cpu);
  }
};

// mlockall(MCL_CURRENT | MCL_FUTURE).
std::string lockProcessMemory();

// A heap whose resident size stops growing (glibc): one arena for all threads, large blocks from
// the heap instead of mmap (a freed mmap block is unmapped and faulted in again next time), and
// the top of the heap never trimmed. Call before any thread is started.
std::string configureRealTimeHeap();
// Grows the heap by `bytes`, touches every page and frees it again: later allocations (the
// estimator's bounded per-frame ones) are served from resident pages instead of growing RSS.
std::string reserveHeap(std::size_t bytes);
// Applies the policy to the calling thread and names it (pthread_setname_np, <= 15 chars).
std::string applyThreadPolicy(const std::string& key, const std::string& thread_name,
                              const ThreadPolicy& policy);

}  // namespace sunvo::runtime
