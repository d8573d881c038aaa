#pragma once
// A real pseudo-terminal pair for the serial and MAVLink tests: the slave path plays the serial
// device the code under test opens; the test reads (or does not read) the master side.

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace sunvo::testing {

class PseudoTerminal {
 public:
  // Opens a master (non-blocking, close-on-exec) and unlocks its slave; ok() tells whether it
  // worked, error() why not.
  PseudoTerminal() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0) {
      error_ = "posix_openpt failed";
      return;
    }
    char name[128] = {};
    if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0 ||
        ::ptsname_r(master_, name, sizeof(name)) != 0) {
      error_ = "grantpt/unlockpt/ptsname_r failed";
      closeMaster();
      return;
    }
    slave_path_ = name;
    ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  }
  ~PseudoTerminal() { closeMaster(); }
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  bool ok() const { return master_ >= 0; }
  const std::string& error() const { return error_; }
  int master() const { return master_; }
  const std::string& slavePath() const { return slave_path_; }

  // Closes the master: the slave side sees a hang-up, its writes fail with EIO.
  void closeMaster() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }

  // Appends to out whatever the master has now, waiting up to timeout_ms for the first byte and
  // then reading until nothing more is pending. Returns the number of bytes read.
  std::size_t read(std::vector<std::uint8_t>* out, int timeout_ms) {
    std::size_t total = 0;
    pollfd pfd{master_, POLLIN, 0};
    int wait_ms = timeout_ms;
    while (::poll(&pfd, 1, wait_ms) > 0 && (pfd.revents & POLLIN) != 0) {
      std::uint8_t buf[4096];
      const ssize_t n = ::read(master_, buf, sizeof(buf));
      if (n <= 0) break;
      out->insert(out->end(), buf, buf + n);
      total += static_cast<std::size_t>(n);
      wait_ms = 0;
    }
    return total;
  }

  // Reads until at least n bytes arrived in total or timeout_ms passed.
  void readAtLeast(std::vector<std::uint8_t>* out, std::size_t n, int timeout_ms) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (out->size() < n && std::chrono::steady_clock::now() < deadline) read(out, 10);
  }

 private:
  int master_ = -1;
  std::string slave_path_;
  std::string error_;
};

}  // namespace sunvo::testing
