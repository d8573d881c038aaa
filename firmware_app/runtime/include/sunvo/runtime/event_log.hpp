#pragma once
// Event lines for the journal without libsystemd: journald reads a service's stderr and takes a
// leading "<N>" as the line's syslog priority (sd-daemon(3): SD_ERR "<3>", SD_WARNING "<4>",
// SD_INFO "<6>"), so `journalctl -u sunvo -p warning` shows the faults. One line = one write(2)
// from a stack buffer (no allocation, lines of different threads do not interleave); a line is
// cut at kMaxLine bytes. Meant for events (start, ready, fault, recovery, exit), not per frame.

#include <cstddef>
#include <cstdint>

namespace sunvo::runtime {

enum class LogPriority : int { kErr = 3, kWarning = 4, kInfo = 6 };

class EventLog {
 public:
  // Lines go to `fd` (stderr by default; a test passes a pipe), prefixed "<N>tag: ".
  explicit EventLog(const char* tag, int fd = 2) : tag_(tag), fd_(fd) {}
  __attribute__((format(printf, 3, 4))) void log(LogPriority priority, const char* fmt, ...);
  // Lines that could not be written completely.
  std::uint64_t errors() const { return errors_; }

  static constexpr std::size_t kMaxLine = 512;

 private:
  const char* tag_;
  int fd_;
  std::uint64_t errors_ = 0;
};

}  // namespace sunvo::runtime
