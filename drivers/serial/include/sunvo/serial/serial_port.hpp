#pragma once
// A write-only serial port for a telemetry stream that must never hold up its caller.
//
// Frames go into a fixed ring (allocated at open) whole or not at all; the ring is drained with
// non-blocking write(2) calls. A full ring drops the new frame (counted). A write error other than
// EAGAIN/EINTR (EIO or ENXIO when a USB adapter is unplugged, the other end of a pseudo-terminal
// closed, ...) closes the port, drops what was queued (stale poses are of no use later) and
// reopens the same path with exponential backoff, driven by the caller's clock through flush().
// While the port is closed, send() drops frames (counted). No call blocks and, after open(), no
// call allocates except to build the message of a non-ok Status on an error transition.
//
// Written here means accepted by the kernel's tty layer; on a real UART the bytes leave the wire
// later (up to the driver's buffer at the baud rate). On a pseudo-terminal the baud rate is stored
// by termios but has no effect on the transfer rate.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::serial {

struct SerialOptions {
  std::string device;                   // path of the tty, e.g. /dev/ttyAMA0, /dev/serial/by-id/...
  int baud = 921600;                    // bit/s, one of the termios speeds 1200 .. 4000000
  std::size_t tx_buffer_bytes = 16384;  // bytes, 64 .. 16 MiB: the ring of queued frames
  std::size_t max_queued_frames = 256;  // frames, 1 .. 65536: frame ends tracked in the ring
  int reopen_initial_ms = 100;          // ms, 1 .. 60000: first wait after an error
  int reopen_max_ms = 5000;             // ms, reopen_initial_ms .. 600000: backoff ceiling
  Status validate() const;              // names the bad key, e.g. "serial.baud: ..."
};

struct SerialCounters {
  std::uint64_t frames_queued = 0;      // frames accepted by send()
  std::uint64_t frames_written = 0;     // frames whose last byte was written
  std::uint64_t frames_dropped = 0;     // refused by send() (ring full, port closed) or queued
                                        // and lost when a write error closed the port
  std::uint64_t bytes_written = 0;      // bytes accepted by write(2)
  std::uint64_t bytes_dropped = 0;      // bytes of dropped frames, queued bytes lost on close
  std::uint64_t write_would_block = 0;  // write(2) calls that returned EAGAIN
  std::uint64_t write_errors = 0;       // write(2) failures that closed the port
  std::uint64_t reopens = 0;            // successful reopens after an error
  std::uint64_t reopen_failures = 0;    // reopen attempts that failed (next wait doubled)
};

// A termios speed constant for a baud rate in bit/s; false when termios has none.
bool baudToSpeed(int baud, unsigned* speed);

class SerialPort {
 public:
  // Opens options.device O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC, sets raw mode
  // (cfmakeraw, 8N1, CLOCAL, no flow control) and the speed, and allocates the ring.
  static Expected<std::unique_ptr<SerialPort>> open(const SerialOptions& options);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Queues the whole frame or drops it whole (counted), then writes what the port takes without
  // blocking. now_ns: the caller's monotonic clock. Returns ok when the frame was queued or
  // dropped (see counters()); invalid_argument when n is 0 or larger than the ring; the error
  // of flush() when a write error closed the port during this call.
  Status send(const std::uint8_t* data, std::size_t n, TimeNs now_ns);
  // Writes pending bytes without blocking; when the port is closed and the backoff has passed,
  // tries to reopen it. Returns a non-ok Status only on a transition: the write error that
  // closed the port, or a failed reopen attempt.
  Status flush(TimeNs now_ns);

  // Monotonic time (the now_ns given to the send()/flush() that wrote it) when the last byte of
  // the last complete frame was written; 0 before the first.
  TimeNs lastByteWrittenNs() const { return last_frame_written_ns_; }
  const SerialCounters& counters() const { return counters_; }
  bool isOpen() const { return fd_ >= 0; }
  std::size_t queuedBytes() const { return size_; }
  const SerialOptions& options() const { return options_; }

 private:
  explicit SerialPort(const SerialOptions& options);
  Status openDevice();
  void closeAfterError(TimeNs now_ns);

  SerialOptions options_;
  int fd_ = -1;
  // Byte ring: size_ bytes starting at head_.
  std::vector<std::uint8_t> ring_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  // Absolute stream offsets (bytes ever queued) where the queued frames end, oldest first.
  std::vector<std::uint64_t> frame_ends_;
  std::size_t frames_head_ = 0;
  std::size_t frames_size_ = 0;
  std::uint64_t queued_total_ = 0;   // bytes ever queued
  std::uint64_t written_total_ = 0;  // bytes ever written or discarded from the ring
  TimeNs last_frame_written_ns_ = 0;
  // Reopen state.
  TimeNs next_reopen_ns_ = 0;
  int backoff_ms_ = 0;
  SerialCounters counters_;
};

}  // namespace sunvo::serial
