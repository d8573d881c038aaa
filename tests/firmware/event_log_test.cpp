// EventLog: each line carries the sd-daemon priority prefix journald parses, one write per line,
// embedded newlines flattened, long lines cut with the newline kept.

#include "sunvo/runtime/event_log.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "../support/drain_fd.hpp"

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::runtime {
namespace {

TEST(EventLog, PriorityPrefixesAndOneLinePerEvent) {
  int p[2];
  ASSERT_EQ(pipe(p), 0);
  EventLog log("sunvo_rover", p[1]);
  log.log(LogPriority::kInfo, "ready (%d threads)", 4);
  log.log(LogPriority::kWarning, "fault: camera %s\nsilent", "/dev/sunvo-left");
  log.log(LogPriority::kErr, "exit %d", 3);
  close(p[1]);
  EXPECT_EQ(testing::drainFd(p[0]),
            "<6>sunvo_rover: ready (4 threads)\n"
            "<4>sunvo_rover: fault: camera /dev/sunvo-left silent\n"
            "<3>sunvo_rover: exit 3\n");
  close(p[0]);
  EXPECT_EQ(log.errors(), 0u);
}

TEST(EventLog, LongLineIsCutAndEndsWithNewline) {
  int p[2];
  ASSERT_EQ(pipe(p), 0);
  EventLog log("t", p[1]);
  const std::string text(2000, 'y');
  log.log(LogPriority::kInfo, "%s", text.c_str());
  close(p[1]);
  const std::string line = testing::drainFd(p[0]);
  close(p[0]);
  EXPECT_EQ(line.size(), EventLog::kMaxLine);
  EXPECT_EQ(line.substr(0, 5), "<6>t:");
  EXPECT_EQ(line.back(), '\n');
}

TEST(EventLog, FailedWriteIsCounted) {
  EventLog log("t", -1);
  log.log(LogPriority::kErr, "lost");
  EXPECT_EQ(log.errors(), 1u);
}

TEST(EventLog, LoggingAllocatesNothing) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(allocCounterActive());
  int p[2];
  ASSERT_EQ(pipe(p), 0);
  EventLog log("sunvo_rover", p[1]);
  const std::uint64_t before = threadAllocationCount();
  for (int i = 0; i < 5; ++i) {
    log.log(LogPriority::kWarning, "fault: camera %s delivered no frame for %.1f s",
            "/dev/sunvo-left", 1.0 + i);
  }
  EXPECT_EQ(threadAllocationCount() - before, 0u);
  close(p[1]);
  EXPECT_NE(testing::drainFd(p[0]).find("<4>sunvo_rover: fault: camera /dev/sunvo-left"),
            std::string::npos);
  close(p[0]);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::runtime
