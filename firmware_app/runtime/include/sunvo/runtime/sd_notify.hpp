#pragma once
// The systemd notification protocol (sd_notify(3)) without libsystemd: one datagram of
// "KEY=VALUE" lines to the unix datagram socket named by $NOTIFY_SOCKET (a file-system path, or
// the abstract namespace when the name starts with '@'). With Type=notify the unit is "started"
// at READY=1; with WatchdogSec= systemd sets $WATCHDOG_USEC and kills the service (SIGABRT, then
// Restart=) when no WATCHDOG=1 arrives within that time.
//
// The socket and its address are set up once in fromEnvironment(); a send is one sendto() from a
// fixed buffer (no allocation). Without $NOTIFY_SOCKET every call is a no-op. A failed send is
// counted (errors()), never fatal: the program must not stop because the supervisor went away.

#include <sys/socket.h>
#include <sys/un.h>

#include <atomic>
#include <cstdint>

#include "sunvo/core/time.hpp"

namespace sunvo::runtime {

class SdNotifier {
 public:
  // Disabled (every call a no-op).
  SdNotifier() = default;
  // Reads $NOTIFY_SOCKET and $WATCHDOG_USEC (honoured only when $WATCHDOG_PID is unset or this
  // process's pid, as sd_watchdog_enabled(3) does). An unusable socket name counts one error and
  // leaves the notifier disabled.
  static SdNotifier fromEnvironment();
  ~SdNotifier();
  SdNotifier(SdNotifier&& other) noexcept;
  SdNotifier& operator=(SdNotifier&& other) noexcept;
  SdNotifier(const SdNotifier&) = delete;
  SdNotifier& operator=(const SdNotifier&) = delete;

  bool enabled() const { return fd_ >= 0; }
  // The watchdog period systemd asked for ($WATCHDOG_USEC), ns; 0 when there is none.
  TimeNs watchdogNs() const { return watchdog_ns_; }

  // Each sends one datagram; false (and one more error) when it could not be sent or `state` does
  // not fit the buffer. A disabled notifier returns true and sends nothing.
  bool ready() { return send("READY=1"); }
  bool watchdog() { return send("WATCHDOG=1"); }
  bool stopping() { return send("STOPPING=1"); }
  // "STATUS=<text>" (one line shown by systemctl status); text is cut at kMaxMessage bytes.
  bool status(const char* text);
  // A raw notification ("KEY=VALUE\n...").
  bool send(const char* state);

  std::uint64_t sent() const { return sent_.load(std::memory_order_relaxed); }
  std::uint64_t errors() const { return errors_.load(std::memory_order_relaxed); }

  static constexpr std::size_t kMaxMessage = 256;  // bytes of one datagram

 private:
  bool sendBytes(const char* data, std::size_t len);

  int fd_ = -1;
  sockaddr_un addr_{};
  socklen_t addr_len_ = 0;
  TimeNs watchdog_ns_ = 0;
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> errors_{0};
};

}  // namespace sunvo::runtime
