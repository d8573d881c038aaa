#include "sunvo/runtime/event_log.hpp"

#include <unistd.h>

#include <cstdarg>
#include <cstdio>

namespace sunvo::runtime {

void EventLog::log(LogPriority priority, const char* fmt, ...) {
  char line[kMaxLine];
  int n = std::snprintf(line, sizeof(line), "<%d>%s: ", static_cast<int>(priority), tag_);
  if (n < 0) n = 0;
  std::size_t len = static_cast<std::size_t>(n) < sizeof(line) ? static_cast<std::size_t>(n) : 0;
  va_list args;
  va_start(args, fmt);
  const int m = std::vsnprintf(line + len, sizeof(line) - len, fmt, args);
  va_end(args);
  if (m > 0) len += static_cast<std::size_t>(m);
  if (len > sizeof(line) - 1) len = sizeof(line) - 1;  // cut: keep room for the newline
  // Newlines inside the text would start lines without a priority: flatten them.
  for (std::size_t i = 0; i < len; ++i) {
    if (line[i] == '\n') line[i] = ' ';
  }
  line[len++] = '\n';
  if (write(fd_, line, len) != static_cast<ssize_t>(len)) ++errors_;
}

}  // namespace sunvo::runtime
