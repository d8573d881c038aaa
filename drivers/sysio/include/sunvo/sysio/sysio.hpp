#pragma once
// The one thin syscall seam between sunvo's device drivers and the kernel.
//
// Drivers (V4L2 today) reach the kernel only through a SysIo&: open, close, ioctl, mmap, munmap
// and poll. linuxSysIo() forwards each call to the real syscall; tests and hardware-in-the-loop
// runs put an emulated device behind the same interface (hil/sim/emulated_devices), so the driver
// code that runs on the rover is the code the tests run.
//
// Every call reports failure as an errno value in the result (0 = success) instead of through
// the thread-local errno, so that an emulator never has to touch errno and a caller can keep the
// code next to the value. Nothing here logs, allocates or throws.

#include <poll.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>

namespace sunvo::sysio {

// value: the syscall's return value (a file descriptor, an ioctl's result, poll's count of ready
// descriptors), -1 on failure; err: 0 on success, else the errno value (ENODEV, EAGAIN, ...).
struct SysResult {
  long value = 0;
  int err = 0;
  bool ok() const { return err == 0; }
};

// addr: the mapping, or nullptr on failure; err as in SysResult.
struct MapResult {
  void* addr = nullptr;
  int err = 0;
  bool ok() const { return err == 0; }
};

class SysIo {
 public:
  SysIo() = default;
  SysIo(const SysIo&) = delete;
  SysIo& operator=(const SysIo&) = delete;
  virtual ~SysIo() = default;

  virtual SysResult open(const char* path, int flags) = 0;
  virtual SysResult close(int fd) = 0;
  // One ioctl; EINTR is returned like any other error (see ioctlRetry).
  virtual SysResult ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual MapResult mmap(void* addr, std::size_t length, int prot, int flags, int fd,
                         off_t offset) = 0;
  virtual SysResult munmap(void* addr, std::size_t length) = 0;
  // poll(2): nfds == 0 sleeps for timeout_ms (the drivers' only way to wait, so that an emulator
  // sees every wait). timeout_ms < 0 waits without limit; drivers never pass that.
  virtual SysResult poll(pollfd* fds, nfds_t nfds, int timeout_ms) = 0;
};

// The process-wide forwarder to the real syscalls.
SysIo& linuxSysIo();

// CLOCK_MONOTONIC in ns: the clock of the drivers' deadlines, and the one the kernel stamps V4L2
// buffers (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) and GPIO line events (Linux >= 5.7) with.
std::int64_t monotonicNowNs();

// ioctl, repeated while it fails with EINTR (a signal arrived during the call).
SysResult ioctlRetry(SysIo& io, int fd, unsigned long request, void* arg);

}  // namespace sunvo::sysio
