#pragma once
// The telemetry thread's output: a pose stream to the vehicle. The MAVLink-over-serial link
// (mavlink_link.hpp) implements it; nothing in the app knows the protocol.

#include <cstdint>
#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::rover {

// One estimator output, as the estimator thread hands it to telemetry (trivially copyable: it
// travels through an SPSC ring).
struct PoseRecord {
  std::uint64_t sequence = 0;
  TimeNs utc_ns = 0;               // frame time (UTC)
  TimeNs trigger_mono_ns = 0;      // trigger time (monotonic), for the deadline check
  double p_w[3] = {0, 0, 0};       // camera position in the world, m
  double q_w_c[4] = {0, 0, 0, 1};  // C_w_c as a quaternion (x, y, z, w)
  double v_w[3] = {0, 0, 0};       // m/s, camera velocity in the world
  double omega_c[3] = {0, 0, 0};   // rad/s, angular velocity in the camera frame
  bool velocity_valid = false;     // false for the first frame and after a loss
  int tracking = 0;                // vo::TrackingStatus as int
  int ransac_inliers = 0;
  std::uint8_t reset_counter = 0;  // incremented at each tracking recovery
};

class PoseLink {
 public:
  virtual ~PoseLink() = default;
  // Queues one pose and writes what the port takes now; never blocks.
  virtual Status sendPose(const PoseRecord& pose, TimeNs now_mono_ns) = 0;
  virtual Status sendHeartbeat(TimeNs now_mono_ns) = 0;
  // Writes pending bytes, reopens a lost port; never blocks.
  virtual Status service(TimeNs now_mono_ns) = 0;
  // True when every queued byte has been written.
  virtual bool drained() const = 0;
  // Monotonic ns when the last byte of the last complete frame was written (0 = none yet).
  virtual TimeNs lastByteWrittenNs() const = 0;
  // One line of counters for the summary.
  virtual std::string countersText() const = 0;
};

}  // namespace sunvo::rover
