#include "sunvo/runtime/sd_notify.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace sunvo::runtime {

SdNotifier SdNotifier::fromEnvironment() {
  SdNotifier n;
  const char* usec = std::getenv("WATCHDOG_USEC");
  const char* pid = std::getenv("WATCHDOG_PID");
  if (usec != nullptr && (pid == nullptr || std::strtol(pid, nullptr, 10) == getpid())) {
    const long long us = std::strtoll(usec, nullptr, 10);
    if (us > 0) n.watchdog_ns_ = static_cast<TimeNs>(us) * 1000;
  }
  const char* name = std::getenv("NOTIFY_SOCKET");
  if (name == nullptr || name[0] == '\0') return n;
  const std::size_t len = std::strlen(name);
  // '@' or '/' first (sd_notify's rule), and room for the name in sun_path.
  if ((name[0] != '@' && name[0] != '/') || len >= sizeof(n.addr_.sun_path)) {
    n.errors_.fetch_add(1, std::memory_order_relaxed);
    return n;
  }
  n.addr_.sun_family = AF_UNIX;
  std::memcpy(n.addr_.sun_path, name, len);
  if (name[0] == '@') n.addr_.sun_path[0] = '\0';  // abstract: no terminating NUL counted
  n.addr_len_ =
      static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + len + (name[0] == '@' ? 0 : 1));
  n.fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (n.fd_ < 0) n.errors_.fetch_add(1, std::memory_order_relaxed);
  return n;
}

SdNotifier::~SdNotifier() {
  if (fd_ >= 0) close(fd_);
}

SdNotifier::SdNotifier(SdNotifier&& o) noexcept
    : fd_(o.fd_),
      addr_(o.addr_),
      addr_len_(o.addr_len_),
      watchdog_ns_(o.watchdog_ns_),
      sent_(o.sent()),
      errors_(o.errors()) {
  o.fd_ = -1;
}

SdNotifier& SdNotifier::operator=(SdNotifier&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) close(fd_);
    fd_ = o.fd_;
    addr_ = o.addr_;
    addr_len_ = o.addr_len_;
    watchdog_ns_ = o.watchdog_ns_;
    sent_.store(o.sent());
    errors_.store(o.errors());
    o.fd_ = -1;
  }
  return *this;
}

bool SdNotifier::sendBytes(const char* data, std::size_t len) {
  if (fd_ < 0) return true;
  const ssize_t n = sendto(fd_, data, len, MSG_NOSIGNAL | MSG_DONTWAIT,
                           reinterpret_cast<const sockaddr*>(&addr_), addr_len_);
  if (n != static_cast<ssize_t>(len)) {
    errors_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  sent_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool SdNotifier::send(const char* state) {
  const std::size_t len = std::strlen(state);
  if (len > kMaxMessage) {
    errors_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return sendBytes(state, len);
}

bool SdNotifier::status(const char* text) {
  if (fd_ < 0) return true;
  char buf[kMaxMessage];
  constexpr std::size_t kPrefix = 7;  // "STATUS="
  std::memcpy(buf, "STATUS=", kPrefix);
  std::size_t len = std::strlen(text);
  if (len > kMaxMessage - kPrefix) len = kMaxMessage - kPrefix;
  std::memcpy(buf + kPrefix, text, len);
  return sendBytes(buf, kPrefix + len);
}

}  // namespace sunvo::runtime
