#include "sunvo/runtime/rt_setup.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <thread>

namespace sunvo::runtime {
namespace {

TEST(RtSetup, PolicyIsAppliedOrExplainedInOneLine) {
  std::string warning;
  int policy = -1;
  cpu_set_t set;
  CPU_ZERO(&set);
  std::thread t([&] {
    warning = applyThreadPolicy("rt.threads.test", "sunvo_test", ThreadPolicy{10, 0});
    sched_param sp{};
    pthread_getschedparam(pthread_self(), &policy, &sp);
    pthread_getaffinity_np(pthread_self(), sizeof(set), &set);
  });
  t.join();
  if (warning.empty()) {  // permitted (root / CAP_SYS_NICE): it took effect
    EXPECT_EQ(policy, SCHED_FIFO);
    EXPECT_EQ(CPU_COUNT(&set), 1);
    EXPECT_TRUE(CPU_ISSET(0, &set));
  } else {  // not permitted: the warning names the key and the errno
    EXPECT_NE(warning.find("rt.threads.test."), std::string::npos) << warning;
    EXPECT_NE(warning.find("(E"), std::string::npos) << warning;
  }
  const ThreadPolicy bad_priority{100, -1};
  EXPECT_NE(bad_priority.validate("rt.threads.x")
                .message()
                .find("rt.threads.x.fifo_priority: 100 is outside [0, 99]"),
            std::string::npos);
  const ThreadPolicy bad_cpu{0, -2};
  EXPECT_NE(bad_cpu.validate("rt.threads.x").message().find("rt.threads.x.cpu"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::runtime
