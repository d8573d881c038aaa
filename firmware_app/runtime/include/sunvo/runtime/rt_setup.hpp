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
};

// mlockall(MCL_CURRENT | MCL_FUTURE).
std::string lockProcessMemory();
// Applies the policy to the calling thread and names it (pthread_setname_np, <= 15 chars).
std::string applyThreadPolicy(const std::string& key, const std::string& thread_name,
                              const ThreadPolicy& policy);

}  // namespace sunvo::runtime
