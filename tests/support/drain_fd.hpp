#pragma once
// Reads a pipe or socket the program under test writes to (its event log, say).

#include <unistd.h>

#include <string>

namespace sunvo::testing {

// Everything readable now from a non-blocking descriptor.
inline std::string drainFd(int fd) {
  std::string out;
  char buf[4096];
  ssize_t n;
  while ((n = read(fd, buf, sizeof(buf))) > 0) out.append(buf, static_cast<std::size_t>(n));
  return out;
}

}  // namespace sunvo::testing
