// SerialPort over a real pseudo-terminal pair: raw mode, whole frames through, a reader that does
// not read never blocks send(), a vanished device is counted and reopened with backoff, and the
// throughput of the MAVLink stream at 921600 and 115200 baud (termios stores the speed of a
// pseudo-terminal but does not pace it).

#include "sunvo/serial/serial_port.hpp"

#include <gtest/gtest.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <new>
#include <thread>
#include <vector>

#include "../support/pty.hpp"
#include "../support/telemetry.hpp"
#include "sunvo/mavlink/mavlink.hpp"

namespace sunvo::serial {
namespace {

using sunvo::testing::PseudoTerminal;

using sunvo::testing::decodeAll;
using sunvo::testing::monotonicNs;

// Options for a port on the slave side of pty.
SerialOptions optionsFor(const PseudoTerminal& pty, std::size_t tx_buffer_bytes = 16384) {
  SerialOptions o;
  o.device = pty.slavePath();
  o.tx_buffer_bytes = tx_buffer_bytes;
  return o;
}

std::vector<std::uint8_t> odometryFrame(std::uint8_t seq, float x) {
  mavlink::Odometry m;
  m.time_usec = 1'000'000ULL * seq;
  m.x = x;
  m.quality = 50;
  std::vector<std::uint8_t> frame(mavlink::kMaxFrameBytes);
  frame.resize(mavlink::encodeOdometry(m, mavlink::Endpoint{}, seq, frame.data()));
  return frame;
}

TEST(SerialOptions, ValidateNamesTheBadKey) {
  SerialOptions o;
  o.device = "/dev/ttyS0";
  EXPECT_TRUE(o.validate().isOk());
  o.baud = 12345;
  EXPECT_NE(o.validate().message().find("serial.baud"), std::string::npos);
  o.baud = 115200;
  o.tx_buffer_bytes = 10;
  EXPECT_NE(o.validate().message().find("serial.tx_buffer_bytes"), std::string::npos);
  o.tx_buffer_bytes = 4096;
  o.reopen_max_ms = 10;
  EXPECT_NE(o.validate().message().find("serial.reopen_max_ms"), std::string::npos);
  o.reopen_max_ms = 5000;
  o.device.clear();
  EXPECT_NE(o.validate().message().find("serial.device"), std::string::npos);
}

TEST(SerialPort, OpenFailsClearlyOnMissingDeviceOrNonTerminal) {
  SerialOptions o;
  o.device = "/nonexistent/ttyUSB9";
  auto missing = SerialPort::open(o);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("/nonexistent/ttyUSB9"), std::string::npos);
  o.device = "/dev/null";
  auto not_tty = SerialPort::open(o);
  ASSERT_FALSE(not_tty);
  EXPECT_NE(not_tty.status().message().find("not a terminal"), std::string::npos);
}

TEST(SerialPort, SetsRawModeAndSpeedAndPassesEveryByteUnchanged) {
  PseudoTerminal pty;
  ASSERT_TRUE(pty.ok()) << pty.error();
  SerialOptions o = optionsFor(pty);
  o.baud = 115200;
  auto port = SerialPort::open(o);
  ASSERT_TRUE(port) << port.status().toString();

  // The slave's settings as the port left them (a pty shares one termios between its ends).
  termios tio{};
  ASSERT_EQ(::tcgetattr(pty.master(), &tio), 0);
  EXPECT_EQ(tio.c_lflag & (ICANON | ECHO | ISIG | IEXTEN), 0u);
  EXPECT_EQ(tio.c_oflag & OPOST, 0u);
  EXPECT_EQ(tio.c_iflag & (ICRNL | IXON | IXOFF | ISTRIP), 0u);
  EXPECT_EQ(tio.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_EQ(tio.c_cflag & (PARENB | CSTOPB | CRTSCTS), 0u);
  EXPECT_NE(tio.c_cflag & CLOCAL, 0u);
  EXPECT_EQ(::cfgetospeed(&tio), static_cast<speed_t>(B115200));

  // Bytes a cooked tty would change or act on: NL (-> CR NL), CR, ^C, XON/XOFF, ^D, 0xFF.
  std::vector<std::uint8_t> data = {0x0A, 0x0D, 0x03, 0x11, 0x13, 0x04, 0xFF, 0x00, 0xFD};
  for (int i = 0; i < 256; ++i) data.push_back(static_cast<std::uint8_t>(i));
  ASSERT_TRUE((*port)->send(data.data(), data.size(), monotonicNs()).isOk());
  std::vector<std::uint8_t> got;
  pty.readAtLeast(&got, data.size(), 2000);
  EXPECT_EQ(got, data);
  EXPECT_EQ((*port)->counters().bytes_written, data.size());
  EXPECT_EQ((*port)->counters().frames_written, 1u);
  EXPECT_GT((*port)->lastByteWrittenNs(), 0);
}

TEST(SerialPort, SlowReaderNeverBlocksAndFramesAreDroppedWhole) {
  PseudoTerminal pty;
  ASSERT_TRUE(pty.ok()) << pty.error();
  auto port = SerialPort::open(optionsFor(pty, 4096));
  ASSERT_TRUE(port) << port.status().toString();
  // Nobody reads the master: the kernel's pty buffer fills, then the ring, then frames drop.
  constexpr int kFrames = 3000;
  std::size_t queued_bytes = 0;
  double max_send_ms = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kFrames; ++i) {
    const auto frame = odometryFrame(static_cast<std::uint8_t>(i), static_cast<float>(i));
    const std::uint64_t dropped_before = (*port)->counters().frames_dropped;
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE((*port)->send(frame.data(), frame.size(), monotonicNs()).isOk());
    const auto t1 = std::chrono::steady_clock::now();
    max_send_ms = std::max(max_send_ms, std::chrono::duration<double, std::milli>(t1 - t0).count());
    if ((*port)->counters().frames_dropped == dropped_before) queued_bytes += frame.size();
  }
  const double total_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const SerialCounters& c = (*port)->counters();
  std::cout << "slow reader: " << kFrames << " sends in " << total_ms << " ms, max " << max_send_ms
            << " ms; queued " << c.frames_queued << ", dropped " << c.frames_dropped << ", written "
            << c.bytes_written << " B, EAGAIN " << c.write_would_block << "\n";
  EXPECT_LT(max_send_ms, 50.0);  // a blocking write would hang here for good
  EXPECT_GT(c.frames_dropped, 0u);
  EXPECT_GT(c.write_would_block, 0u);
  EXPECT_EQ(c.frames_queued + c.frames_dropped, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(c.bytes_dropped, static_cast<std::uint64_t>(kFrames) * 245u - queued_bytes);
  EXPECT_EQ(c.bytes_written + (*port)->queuedBytes(), queued_bytes);
  EXPECT_EQ(c.write_errors, 0u);

  // The reader wakes up: everything that was queued arrives as whole, valid frames.
  std::vector<std::uint8_t> got;
  mavlink::Decoder decoder;
  std::vector<mavlink::Frame> frames;
  for (int round = 0; round < 200 && (*port)->queuedBytes() > 0; ++round) {
    pty.read(&got, 5);
    ASSERT_TRUE((*port)->flush(monotonicNs()).isOk());
  }
  pty.read(&got, 50);
  EXPECT_EQ((*port)->queuedBytes(), 0u);
  EXPECT_EQ(got.size(), queued_bytes);
  frames = decodeAll(got, &decoder);
  EXPECT_EQ(frames.size(), c.frames_queued);
  EXPECT_EQ(decoder.counters().crc_errors, 0u);
  EXPECT_EQ(decoder.counters().bytes_skipped, 0u);
  EXPECT_EQ(c.frames_written, c.frames_queued);
}

TEST(SerialPort, RejectsAFrameLargerThanTheRing) {
  PseudoTerminal pty;
  ASSERT_TRUE(pty.ok()) << pty.error();
  auto port = SerialPort::open(optionsFor(pty, 128));
  ASSERT_TRUE(port) << port.status().toString();
  const auto frame = odometryFrame(1, 1.0f);
  const Status s = (*port)->send(frame.data(), frame.size(), monotonicNs());
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("serial.tx_buffer_bytes"), std::string::npos);
}

TEST(SerialPort, LostDeviceIsCountedAndReopenedWithBackoff) {
  // The port opens a symlink, as with /dev/serial/by-id/...: on unplug the device node and its
  // link vanish; on replug a new node appears behind the same link.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("sunvo_serial_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path link = dir / "ttyRover";
  std::filesystem::remove(link);
  auto pty1 = std::make_unique<PseudoTerminal>();
  ASSERT_TRUE(pty1->ok()) << pty1->error();
  std::filesystem::create_symlink(pty1->slavePath(), link);

  SerialOptions o;
  o.device = link.string();
  o.reopen_initial_ms = 100;
  o.reopen_max_ms = 400;
  auto opened = SerialPort::open(o);
  ASSERT_TRUE(opened) << opened.status().toString();
  SerialPort& port = **opened;
  constexpr TimeNs kMs = 1'000'000;
  TimeNs now = 1'000 * kMs;  // the caller's clock, simulated
  auto f1 = odometryFrame(1, 1.0f);
  ASSERT_TRUE(port.send(f1.data(), f1.size(), now).isOk());
  std::vector<std::uint8_t> got;
  pty1->readAtLeast(&got, f1.size(), 2000);
  EXPECT_EQ(got, f1);

  // Unplug: the master goes away, the slave reports EIO on the next write.
  pty1->closeMaster();
  std::filesystem::remove(link);
  now += 10 * kMs;
  const Status lost = port.send(f1.data(), f1.size(), now);
  EXPECT_EQ(lost.code(), StatusCode::kDeviceError) << lost.toString();
  EXPECT_NE(lost.message().find("write"), std::string::npos);
  EXPECT_FALSE(port.isOpen());
  EXPECT_EQ(port.counters().write_errors, 1u);
  const TimeNs lost_at = now;

  // While closed, frames are dropped at once; no reopen before the first backoff has passed.
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(port.send(f1.data(), f1.size(), lost_at + 50 * kMs).isOk());
  const auto t1 = std::chrono::steady_clock::now();
  const double send_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  EXPECT_LT(send_ms, 50.0);
  EXPECT_EQ(port.counters().reopen_failures, 0u);
  // Attempts at +100 ms, then +200 (100 * 2), then +400 (capped), +400, ...
  const TimeNs attempts[] = {100, 300, 700, 1100};
  for (TimeNs ms : attempts) {
    EXPECT_TRUE(port.flush(lost_at + (ms - 1) * kMs).isOk());  // just before: nothing happens
    const Status s = port.flush(lost_at + ms * kMs);
    EXPECT_EQ(s.code(), StatusCode::kNotFound) << s.toString();
  }
  EXPECT_EQ(port.counters().reopen_failures, 4u);
  EXPECT_EQ(port.counters().reopens, 0u);

  // Replug: a new pseudo-terminal behind the same link; the next due attempt reopens it.
  PseudoTerminal pty2;
  ASSERT_TRUE(pty2.ok()) << pty2.error();
  std::filesystem::create_symlink(pty2.slavePath(), link);
  EXPECT_TRUE(port.flush(lost_at + 1499 * kMs).isOk());
  EXPECT_FALSE(port.isOpen());
  EXPECT_TRUE(port.flush(lost_at + 1500 * kMs).isOk());
  EXPECT_TRUE(port.isOpen());
  EXPECT_EQ(port.counters().reopens, 1u);
  auto f2 = odometryFrame(2, 2.0f);
  ASSERT_TRUE(port.send(f2.data(), f2.size(), lost_at + 1501 * kMs).isOk());
  got.clear();
  pty2.readAtLeast(&got, f2.size(), 2000);
  EXPECT_EQ(got, f2);
  EXPECT_EQ(port.lastByteWrittenNs(), lost_at + 1501 * kMs);
  std::filesystem::remove_all(dir);
}

// Streams n ODOMETRY frames as fast as the port takes them while a thread drains the master.
// Returns MB/s of decoded payload-carrying frames; every frame must arrive intact.
double streamThroughput(int baud, int n_frames) {
  PseudoTerminal pty;
  EXPECT_TRUE(pty.ok()) << pty.error();
  SerialOptions o = optionsFor(pty);
  o.baud = baud;
  auto port = SerialPort::open(o);
  EXPECT_TRUE(port) << port.status().toString();
  if (!port) return 0.0;
  std::atomic<bool> done{false};
  std::vector<std::uint8_t> got;
  std::thread reader([&] {
    while (!done.load() || pty.read(&got, 20) > 0) pty.read(&got, 5);
  });
  const auto t0 = std::chrono::steady_clock::now();
  std::uint8_t buf[mavlink::kMaxFrameBytes];
  mavlink::Odometry m;
  m.quality = 90;
  std::size_t bytes = 0;
  for (int i = 0; i < n_frames; ++i) {
    m.x = static_cast<float>(i);
    const std::size_t n =
        mavlink::encodeOdometry(m, mavlink::Endpoint{}, static_cast<std::uint8_t>(i), buf);
    bytes += n;
    // Pace by the ring: wait (outside the port) until the frame fits, so nothing is dropped.
    while ((*port)->queuedBytes() + n > o.tx_buffer_bytes) {
      EXPECT_TRUE((*port)->flush(monotonicNs()).isOk());
      std::this_thread::yield();
    }
    EXPECT_TRUE((*port)->send(buf, n, monotonicNs()).isOk());
  }
  while ((*port)->queuedBytes() > 0) EXPECT_TRUE((*port)->flush(monotonicNs()).isOk());
  // Wait until the reader has every byte, then stop the clock.
  while (true) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (got.size() >= bytes || std::chrono::steady_clock::now() - t0 > std::chrono::seconds(20)) {
      break;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  done.store(true);
  reader.join();
  EXPECT_EQ(got.size(), bytes);
  mavlink::Decoder decoder;
  EXPECT_EQ(decodeAll(got, &decoder).size(), static_cast<std::size_t>(n_frames));
  EXPECT_EQ(decoder.counters().crc_errors, 0u);
  EXPECT_EQ((*port)->counters().frames_dropped, 0u);
  const double mb_per_s = static_cast<double>(bytes) / seconds / 1e6;
  std::cout << "pty at " << baud << " baud (termios setting): " << n_frames << " frames, " << bytes
            << " B in " << seconds * 1e3 << " ms = " << mb_per_s
            << " MB/s = " << static_cast<double>(n_frames) / seconds << " frames/s (a real UART at "
            << baud << " 8N1 carries " << baud / 10.0 / 245.0 << " frames/s)\n";
  return mb_per_s;
}

TEST(SerialPort, ThroughputOverAPseudoTerminal) {
  // A pty ignores the baud rate, so both settings run at memory speed; a real UART moves
  // baud / 10 bytes per second (8N1). The bound only proves the pty is not paced at 921600 baud
  // (92 kB/s), which is what docs/telemetry.md says.
  const double fast = streamThroughput(921600, 4000);
  const double slow = streamThroughput(115200, 4000);
  EXPECT_GT(fast, 0.0921600);
  EXPECT_GT(slow, 0.0115200);
}

}  // namespace
}  // namespace sunvo::serial
