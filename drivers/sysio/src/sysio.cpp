#include "sunvo/sysio/sysio.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>

namespace sunvo::sysio {
namespace {

SysResult fromReturn(long rc) {
  if (rc < 0) return {-1, errno};
  return {rc, 0};
}

class LinuxSysIo final : public SysIo {
 public:
  SysResult open(const char* path, int flags) override {
    return fromReturn(::open(path, flags | O_CLOEXEC));
  }
  SysResult close(int fd) override { return fromReturn(::close(fd)); }
  SysResult ioctl(int fd, unsigned long request, void* arg) override {
    return fromReturn(::ioctl(fd, request, arg));
  }
  MapResult mmap(void* addr, std::size_t length, int prot, int flags, int fd,
                 off_t offset) override {
    void* p = ::mmap(addr, length, prot, flags, fd, offset);
    if (p == MAP_FAILED) return {nullptr, errno};
    return {p, 0};
  }
  SysResult munmap(void* addr, std::size_t length) override {
    return fromReturn(::munmap(addr, length));
  }
  SysResult poll(pollfd* fds, nfds_t nfds, int timeout_ms) override {
    return fromReturn(::poll(fds, nfds, timeout_ms));
  }
};

}  // namespace

SysIo& linuxSysIo() {
  static LinuxSysIo io;
  return io;
}

std::int64_t monotonicNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

SysResult ioctlRetry(SysIo& io, int fd, unsigned long request, void* arg) {
  SysResult r;
  do {
    r = io.ioctl(fd, request, arg);
  } while (r.err == EINTR);
  return r;
}

}  // namespace sunvo::sysio
