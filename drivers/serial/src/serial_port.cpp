#include "sunvo/serial/serial_port.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace sunvo::serial {
namespace {

struct BaudEntry {
  int baud;
  speed_t speed;
};

constexpr BaudEntry kBauds[] = {
    {1200, B1200},       {2400, B2400},       {4800, B4800},       {9600, B9600},
    {19200, B19200},     {38400, B38400},     {57600, B57600},     {115200, B115200},
    {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},
    {921600, B921600},   {1000000, B1000000}, {1152000, B1152000}, {1500000, B1500000},
    {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000}, {3500000, B3500000},
    {4000000, B4000000},
};

std::string errnoText(int err) {
  return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")";
}

constexpr TimeNs kNsPerMs = 1'000'000;

}  // namespace

bool baudToSpeed(int baud, unsigned* speed) {
  for (const BaudEntry& e : kBauds) {
    if (e.baud == baud) {
      *speed = static_cast<unsigned>(e.speed);
      return true;
    }
  }
  return false;
}

Status SerialOptions::validate() const {
  if (device.empty()) return invalidArgument("serial.device: empty path");
  unsigned speed = 0;
  if (!baudToSpeed(baud, &speed)) {
    return invalidArgument("serial.baud: " + std::to_string(baud) +
                           " is not a termios speed (1200 .. 4000000, e.g. 115200, 921600)");
  }
  if (tx_buffer_bytes < 64 || tx_buffer_bytes > (16u << 20)) {
    return invalidArgument("serial.tx_buffer_bytes: " + std::to_string(tx_buffer_bytes) +
                           " outside 64 .. 16777216");
  }
  if (max_queued_frames < 1 || max_queued_frames > 65536) {
    return invalidArgument("serial.max_queued_frames: " + std::to_string(max_queued_frames) +
                           " outside 1 .. 65536");
  }
  if (reopen_initial_ms < 1 || reopen_initial_ms > 60000) {
    return invalidArgument("serial.reopen_initial_ms: " + std::to_string(reopen_initial_ms) +
                           " outside 1 .. 60000");
  }
  if (reopen_max_ms < reopen_initial_ms || reopen_max_ms > 600000) {
    return invalidArgument("serial.reopen_max_ms: " + std::to_string(reopen_max_ms) +
                           " outside reopen_initial_ms .. 600000");
  }
  return Status::ok();
}

SerialPort::SerialPort(const SerialOptions& options)
    : options_(options),
      ring_(options.tx_buffer_bytes),
      frame_ends_(options.max_queued_frames),
      backoff_ms_(options.reopen_initial_ms) {}

SerialPort::~SerialPort() {
  if (fd_ >= 0) ::close(fd_);
}

Expected<std::unique_ptr<SerialPort>> SerialPort::open(const SerialOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<SerialPort> port(new SerialPort(options));
  SUNVO_RETURN_IF_ERROR(port->openDevice());
  return port;
}

Status SerialPort::openDevice() {
  const int fd = ::open(options_.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    return Status(err == ENOENT ? StatusCode::kNotFound : StatusCode::kDeviceError,
                  options_.device + ": open: " + errnoText(err));
  }
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    const int err = errno;
    ::close(fd);
    return Status(StatusCode::kDeviceError,
                  options_.device + ": not a terminal (tcgetattr: " + errnoText(err) + ")");
  }
  // Raw 8N1: no line editing, no echo, no signals, no CR/NL translation, no software or
  // hardware flow control; CLOCAL so a missing carrier never blocks or hangs up the port.
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  unsigned speed = 0;
  baudToSpeed(options_.baud, &speed);  // validated in open()
  if (::cfsetispeed(&tio, static_cast<speed_t>(speed)) != 0 ||
      ::cfsetospeed(&tio, static_cast<speed_t>(speed)) != 0 ||
      ::tcsetattr(fd, TCSANOW, &tio) != 0) {
    const int err = errno;
    ::close(fd);
    return Status(StatusCode::kDeviceError, options_.device + ": cannot set raw mode at " +
                                                std::to_string(options_.baud) +
                                                " baud: " + errnoText(err));
  }
  fd_ = fd;
  return Status::ok();
}

void SerialPort::closeAfterError(TimeNs now_ns) {
  ::close(fd_);
  fd_ = -1;
  // What was queued is stale by the time the port is back: drop it, including a partly written
  // frame (the receiver resynchronises on the next start byte).
  counters_.bytes_dropped += size_;
  counters_.frames_dropped += frames_size_;
  written_total_ += size_;
  head_ = 0;
  size_ = 0;
  frames_head_ = 0;
  frames_size_ = 0;
  backoff_ms_ = options_.reopen_initial_ms;
  next_reopen_ns_ = now_ns + static_cast<TimeNs>(backoff_ms_) * kNsPerMs;
}

Status SerialPort::send(const std::uint8_t* data, std::size_t n, TimeNs now_ns) {
  if (n == 0 || n > ring_.size()) {
    return invalidArgument(
        "serial send: frame of " + std::to_string(n) +
        " bytes does not fit serial.tx_buffer_bytes = " + std::to_string(ring_.size()));
  }
  // Make room first: a frame that fits after this write is not dropped needlessly.
  Status before = (fd_ >= 0 && size_ > 0) ? flush(now_ns) : Status::ok();
  if (fd_ < 0 || ring_.size() - size_ < n || frames_size_ == frame_ends_.size()) {
    ++counters_.frames_dropped;
    counters_.bytes_dropped += n;
    if (!before.isOk()) return before;
    // A closed port may be due for its reopen attempt.
    return fd_ < 0 ? flush(now_ns) : Status::ok();
  }
  // Copy into the ring in at most two pieces.
  const std::size_t tail = (head_ + size_) % ring_.size();
  const std::size_t first = std::min(n, ring_.size() - tail);
  std::memcpy(ring_.data() + tail, data, first);
  std::memcpy(ring_.data(), data + first, n - first);
  size_ += n;
  queued_total_ += n;
  frame_ends_[(frames_head_ + frames_size_) % frame_ends_.size()] = queued_total_;
  ++frames_size_;
  ++counters_.frames_queued;
  return flush(now_ns);  // `before` was ok: a failed flush leaves the port closed
}

Status SerialPort::flush(TimeNs now_ns) {
  if (fd_ < 0) {
    if (now_ns < next_reopen_ns_) return Status::ok();
    Status opened = openDevice();
    if (!opened.isOk()) {
      ++counters_.reopen_failures;
      backoff_ms_ = std::min(options_.reopen_max_ms, backoff_ms_ * 2);
      next_reopen_ns_ = now_ns + static_cast<TimeNs>(backoff_ms_) * kNsPerMs;
      return opened;
    }
    ++counters_.reopens;
    backoff_ms_ = options_.reopen_initial_ms;
    return Status::ok();
  }
  while (size_ > 0) {
    // The contiguous piece starting at head_.
    const std::size_t piece = std::min(size_, ring_.size() - head_);
    const ssize_t w = ::write(fd_, ring_.data() + head_, piece);
    if (w < 0) {
      const int err = errno;
      if (err == EINTR) continue;
      if (err == EAGAIN || err == EWOULDBLOCK) {
        ++counters_.write_would_block;
        break;
      }
      ++counters_.write_errors;
      closeAfterError(now_ns);
      return Status(StatusCode::kDeviceError,
                    options_.device + ": write: " + errnoText(err) + "; reopening in " +
                        std::to_string(options_.reopen_initial_ms) + " ms");
    }
    if (w == 0) break;
    const auto written = static_cast<std::size_t>(w);
    head_ = (head_ + written) % ring_.size();
    size_ -= written;
    written_total_ += written;
    counters_.bytes_written += written;
    while (frames_size_ > 0 && frame_ends_[frames_head_] <= written_total_) {
      frames_head_ = (frames_head_ + 1) % frame_ends_.size();
      --frames_size_;
      ++counters_.frames_written;
      last_frame_written_ns_ = now_ns;
    }
    if (written < piece) break;  // the port took less than offered: it is full for now
  }
  if (size_ == 0) head_ = 0;
  return Status::ok();
}

}  // namespace sunvo::serial
