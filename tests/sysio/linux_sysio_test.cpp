// linuxSysIo() against real kernel objects this machine has (files, pipes, anonymous memory), and
// ioctlRetry's EINTR loop.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "sunvo/sysio/sysio.hpp"

namespace sunvo::sysio {
namespace {

TEST(LinuxSysIo, OpenAndCloseReportErrnoValues) {
  SysIo& io = linuxSysIo();
  const SysResult missing = io.open("/nonexistent/sunvo/video0", O_RDWR);
  EXPECT_EQ(missing.value, -1);
  EXPECT_EQ(missing.err, ENOENT);
  const SysResult null = io.open("/dev/null", O_RDWR | O_NONBLOCK);
  ASSERT_TRUE(null.ok());
  EXPECT_GE(null.value, 0);
  const int fd = static_cast<int>(null.value);
  // A V4L2 request on a device that is no video device.
  v4l2_capability cap{};
  const SysResult q = ioctlRetry(io, fd, VIDIOC_QUERYCAP, &cap);
  // The kernel says ENOTTY; qemu-user (the aarch64 tests) answers ioctls it does not translate
  // with ENOSYS. Either way the errno value itself must come back.
  EXPECT_EQ(q.value, -1);
  EXPECT_TRUE(q.err == ENOTTY || q.err == ENOSYS) << "errno " << q.err;
  EXPECT_TRUE(io.close(fd).ok());
  EXPECT_EQ(io.close(fd).err, EBADF);
}

TEST(LinuxSysIo, MapsAndUnmapsMemory) {
  SysIo& io = linuxSysIo();
  const MapResult m =
      io.mmap(nullptr, 8192, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_TRUE(m.ok());
  std::memset(m.addr, 0x5a, 8192);
  EXPECT_EQ(static_cast<unsigned char*>(m.addr)[8191], 0x5a);
  EXPECT_TRUE(io.munmap(m.addr, 8192).ok());
  const MapResult bad = io.mmap(nullptr, 4096, PROT_READ, MAP_SHARED, -1, 0);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.addr, nullptr);
  EXPECT_EQ(bad.err, EBADF);
}

TEST(LinuxSysIo, PollsAPipeAndSleepsWithoutDescriptors) {
  SysIo& io = linuxSysIo();
  std::array<int, 2> p{};
  ASSERT_EQ(::pipe2(p.data(), O_NONBLOCK | O_CLOEXEC), 0);
  pollfd fd{p[0], POLLIN, 0};
  SysResult r = io.poll(&fd, 1, 0);
  EXPECT_EQ(r.value, 0);
  ASSERT_EQ(::write(p[1], "x", 1), 1);
  r = io.poll(&fd, 1, 100);
  EXPECT_EQ(r.value, 1);
  EXPECT_NE(fd.revents & POLLIN, 0);
  EXPECT_TRUE(io.close(p[0]).ok());
  EXPECT_TRUE(io.close(p[1]).ok());

  const auto start = std::chrono::steady_clock::now();
  r = io.poll(nullptr, 0, 20);
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_TRUE(r.ok());
  EXPECT_GE(took, std::chrono::milliseconds(20));
  EXPECT_LT(took, std::chrono::milliseconds(200));
}

// A SysIo whose ioctl is interrupted a given number of times before it succeeds.
class InterruptedIo final : public SysIo {
 public:
  explicit InterruptedIo(int interruptions) : left_(interruptions) {}
  int calls = 0;
  SysResult open(const char*, int) override { return {-1, ENOSYS}; }
  SysResult close(int) override { return {-1, ENOSYS}; }
  SysResult ioctl(int, unsigned long, void*) override {
    ++calls;
    if (left_ > 0) {
      --left_;
      return {-1, EINTR};
    }
    return {0, 0};
  }
  MapResult mmap(void*, std::size_t, int, int, int, off_t) override { return {nullptr, ENOSYS}; }
  SysResult munmap(void*, std::size_t) override { return {-1, ENOSYS}; }
  SysResult poll(pollfd*, nfds_t, int) override { return {-1, ENOSYS}; }

 private:
  int left_;
};

TEST(IoctlRetry, RepeatsOnlyWhileInterrupted) {
  InterruptedIo io(2);
  int arg = 0;
  const SysResult r = ioctlRetry(io, 3, VIDIOC_STREAMON, &arg);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(io.calls, 3);
}

}  // namespace
}  // namespace sunvo::sysio
