// MavlinkSerialLink's steady state makes no heap allocation: poses (tracking, lost, recovered),
// heartbeats, the periodic SET_GPS_GLOBAL_ORIGIN, STATUSTEXT on each transition (rate-limited and
// waiting), stale/resumed, with the reader away for a while so frames drop. Counted with the
// process-wide malloc shim of firmware_app/alloc_counter (not available in sanitizer builds).

#include <gtest/gtest.h>

#include <vector>

#include "../support/pty.hpp"
#include "sunvo/rover/mavlink_link.hpp"
#include "sunvo/runtime/alloc_counter.hpp"
#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::rover {
namespace {

TEST(MavlinkLinkAlloc, NoHeapAllocationAfterOpen) {
  ASSERT_TRUE(runtime::allocCounterActive());
  sunvo::testing::PseudoTerminal pty;
  ASSERT_TRUE(pty.ok()) << pty.error();
  SerialConfig serial;
  serial.device = pty.slavePath();
  serial.tx_buffer_bytes = 2048;
  TelemetryConfig telemetry;
  telemetry.frame = mavlink::FrameProfile::kArduPilot;
  telemetry.origin_period_s = 2.0;
  auto link = MavlinkSerialLink::open(serial, telemetry);
  ASSERT_TRUE(link) << link.status().toString();
  (*link)->setWorldOrigin(49.0, 8.4, 110.0);
  std::vector<std::uint8_t> sink;
  sink.reserve(1 << 20);
  PoseRecord pose;
  pose.cov_theta_valid = true;
  pose.cov_theta_w[0] = pose.cov_theta_w[3] = pose.cov_theta_w[5] = 1e-4;
  pose.velocity_valid = true;
  pose.v_w[0] = 1.0;
  pose.ransac_inliers = 100;
  std::size_t allocations = 0;
  for (int k = 0; k < 600; ++k) {
    const TimeNs now = static_cast<TimeNs>(k) * 100'000'000;
    // Lost every 50th frame, recovered on the next: a text pair each time, the second waiting.
    vo::TrackingStatus status = vo::TrackingStatus::kTracking;
    if (k % 50 == 20) status = vo::TrackingStatus::kLost;
    if (k % 50 == 21) {
      status = vo::TrackingStatus::kRecovered;
      ++pose.reset_counter;
    }
    pose.tracking = static_cast<int>(status);
    pose.p_w[0] = 0.1 * k;
    pose.utc_ns = now;
    const runtime::AllocationScope scope;
    const Status sent = (*link)->sendPose(pose, now);
    if (k % 10 == 0) (void)(*link)->sendHeartbeat(now);
    if (k % 100 == 60) (*link)->setPoseStale(true, now);
    if (k % 100 == 70) (*link)->setPoseStale(false, now);
    const Status serviced = (*link)->service(now);
    allocations += scope.count();
    ASSERT_TRUE(sent.isOk() && serviced.isOk());
    if (k < 200 || k >= 400) pty.read(&sink, 0);  // the reader is away for frames 200..399
  }
  EXPECT_GT((*link)->distanceM(), 50.0);
  EXPECT_EQ(allocations, 0u);
}

}  // namespace
}  // namespace sunvo::rover
