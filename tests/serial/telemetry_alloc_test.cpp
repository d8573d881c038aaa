// The telemetry path of the firmware (pose -> ODOMETRY -> frame -> SerialPort) makes no heap
// allocation after SerialPort::open, including when the port is full and frames are dropped.
// Counted with the process-wide malloc shim of firmware_app/alloc_counter (not available in sanitizer builds).

#include <gtest/gtest.h>

#include <vector>

#include "../support/pty.hpp"
#include "../support/telemetry.hpp"
#include "sunvo/runtime/alloc_counter.hpp"
#include "sunvo/mavlink/conventions.hpp"
#include "sunvo/mavlink/mavlink.hpp"
#include "sunvo/serial/serial_port.hpp"

namespace sunvo::serial {
namespace {

using sunvo::testing::PseudoTerminal;

using sunvo::testing::monotonicNs;

TEST(TelemetryAlloc, CounterIsActive) {
  EXPECT_TRUE(runtime::allocCounterActive());
}

TEST(TelemetryAlloc, NoHeapAllocationAfterOpen) {
  PseudoTerminal pty;
  ASSERT_TRUE(pty.ok()) << pty.error();
  SerialOptions o;
  o.device = pty.slavePath();
  o.tx_buffer_bytes = 2048;
  auto port = SerialPort::open(o);
  ASSERT_TRUE(port) << port.status().toString();
  std::vector<std::uint8_t> sink;
  sink.reserve(1 << 20);
  std::uint8_t buf[mavlink::kMaxFrameBytes];
  const Eigen::Matrix3d C_b_c = mavlink::cameraForwardC_b_c();
  mavlink::OdometryInput in;
  in.cov_pose.setIdentity();
  in.v_w = Eigen::Vector3d(1, 0, 0);
  in.omega_c = Eigen::Vector3d(0, 0.1, 0);
  std::size_t allocations = 0;
  std::uint8_t seq = 0;
  for (int k = 0; k < 600; ++k) {
    const runtime::AllocationScope scope;
    // The firmware's telemetry step: pose -> ODOMETRY -> frame -> port, HEARTBEAT every 10th.
    in.time_ns = static_cast<TimeNs>(k) * 100'000'000;
    in.T_w_c.translation().x() = 0.1 * k;
    const mavlink::Odometry m = mavlink::toOdometry(in, mavlink::WorldConvention::kEnu, C_b_c);
    std::size_t n = mavlink::encodeOdometry(m, mavlink::Endpoint{}, seq++, buf);
    const Status sent = (*port)->send(buf, n, monotonicNs());
    if (k % 10 == 0) {
      n = mavlink::encodeHeartbeat(mavlink::Heartbeat{}, mavlink::Endpoint{}, seq++, buf);
      (void)(*port)->send(buf, n, monotonicNs());
    }
    const Status flushed = (*port)->flush(monotonicNs());
    allocations += scope.count();
    ASSERT_TRUE(sent.isOk() && flushed.isOk());
    // The reader is away for frames 200..399 (EAGAIN, ring full, drops), then catches up.
    if (k < 200 || k >= 400) pty.read(&sink, 0);
  }
  EXPECT_GT((*port)->counters().frames_dropped, 0u);
  EXPECT_GT((*port)->counters().write_would_block, 0u);
  EXPECT_EQ(allocations, 0u);
}

}  // namespace
}  // namespace sunvo::serial
