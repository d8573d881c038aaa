// SdNotifier against a real unix datagram socket (what systemd listens on): a path socket and an
// abstract one; the datagrams read back must be the protocol's exact lines.

#include "sunvo/runtime/sd_notify.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::runtime {
namespace {

// A bound datagram socket; name starting with '@' = abstract namespace.
class Listener {
 public:
  explicit Listener(const std::string& name) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, name.data(), name.size());
    if (name[0] == '@') addr.sun_path[0] = '\0';
    const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size() +
                                            (name[0] == '@' ? 0 : 1));
    bound_ = bind(fd_, reinterpret_cast<sockaddr*>(&addr), len) == 0;
    timeval tv{1, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  }
  ~Listener() { close(fd_); }
  bool bound() const { return bound_; }
  // The next datagram, "" after a 1 s timeout.
  std::string next() {
    char buf[1024];
    const ssize_t n = recv(fd_, buf, sizeof(buf), 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  }
  // True when no datagram is waiting.
  bool empty() {
    char buf[16];
    return recv(fd_, buf, sizeof(buf), MSG_DONTWAIT) < 0;
  }

 private:
  int fd_ = -1;
  bool bound_ = false;
};

TEST(SdNotify, DisabledWithoutSocketIsANoOp) {
  unsetenv("NOTIFY_SOCKET");
  unsetenv("WATCHDOG_USEC");
  SdNotifier n = SdNotifier::fromEnvironment();
  EXPECT_FALSE(n.enabled());
  EXPECT_EQ(n.watchdogNs(), 0);
  EXPECT_TRUE(n.ready());
  EXPECT_EQ(n.sent(), 0u);
  EXPECT_EQ(n.errors(), 0u);
}

TEST(SdNotify, SendsTheProtocolLinesToAPathSocket) {
  const std::string path = std::string(SUNVO_BINARY_DIR) + "/test_out/sd_notify_test.sock";
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::filesystem::remove(path);
  Listener listener(path);
  ASSERT_TRUE(listener.bound()) << path;
  setenv("NOTIFY_SOCKET", path.c_str(), 1);
  setenv("WATCHDOG_USEC", "5000000", 1);
  unsetenv("WATCHDOG_PID");
  SdNotifier n = SdNotifier::fromEnvironment();
  ASSERT_TRUE(n.enabled());
  EXPECT_EQ(n.watchdogNs(), 5'000'000'000);
  EXPECT_TRUE(n.ready());
  EXPECT_TRUE(n.watchdog());
  EXPECT_TRUE(n.status("tracking, 20 poses/s"));
  EXPECT_TRUE(n.stopping());
  EXPECT_EQ(listener.next(), "READY=1");
  EXPECT_EQ(listener.next(), "WATCHDOG=1");
  EXPECT_EQ(listener.next(), "STATUS=tracking, 20 poses/s");
  EXPECT_EQ(listener.next(), "STOPPING=1");
  EXPECT_EQ(n.sent(), 4u);
  EXPECT_EQ(n.errors(), 0u);
  // The listener gone: sends fail, are counted, and nothing throws or ends.
  std::filesystem::remove(path);
  EXPECT_FALSE(n.watchdog());
  EXPECT_EQ(n.errors(), 1u);
  unsetenv("NOTIFY_SOCKET");
  unsetenv("WATCHDOG_USEC");
}

TEST(SdNotify, AbstractNamespaceAndForeignWatchdogPid) {
  const std::string name = "@sunvo_sd_notify_test_" + std::to_string(getpid());
  Listener listener(name);
  ASSERT_TRUE(listener.bound());
  setenv("NOTIFY_SOCKET", name.c_str(), 1);
  setenv("WATCHDOG_USEC", "2000000", 1);
  setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);  // meant for another process
  SdNotifier n = SdNotifier::fromEnvironment();
  EXPECT_EQ(n.watchdogNs(), 0);
  EXPECT_TRUE(n.ready());
  EXPECT_EQ(listener.next(), "READY=1");
  EXPECT_TRUE(listener.empty());
  // A status longer than a datagram is cut, not refused.
  const std::string long_text(1000, 'x');
  EXPECT_TRUE(n.status(long_text.c_str()));
  EXPECT_EQ(listener.next().size(), SdNotifier::kMaxMessage);
  unsetenv("NOTIFY_SOCKET");
  unsetenv("WATCHDOG_USEC");
  unsetenv("WATCHDOG_PID");
}

TEST(SdNotify, BadSocketNameIsCountedNotFatal) {
  setenv("NOTIFY_SOCKET", "relative/name", 1);
  SdNotifier n = SdNotifier::fromEnvironment();
  EXPECT_FALSE(n.enabled());
  EXPECT_EQ(n.errors(), 1u);
  unsetenv("NOTIFY_SOCKET");
}

TEST(SdNotify, SendsAllocateNothing) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(allocCounterActive());
  const std::string name = "@sunvo_sd_notify_alloc_" + std::to_string(getpid());
  Listener listener(name);
  ASSERT_TRUE(listener.bound());
  setenv("NOTIFY_SOCKET", name.c_str(), 1);
  SdNotifier n = SdNotifier::fromEnvironment();
  unsetenv("NOTIFY_SOCKET");
  const std::uint64_t before = threadAllocationCount();
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(n.watchdog());
    EXPECT_TRUE(n.status("camera /dev/sunvo-left delivered no frame for 1.0 s"));
  }
  EXPECT_EQ(threadAllocationCount() - before, 0u);
  EXPECT_EQ(n.sent(), 10u);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::runtime
