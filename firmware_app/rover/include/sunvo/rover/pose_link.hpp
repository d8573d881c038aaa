#pragma once
// The telemetry thread's output: a pose stream to the vehicle. The MAVLink-over-serial link
// (mavlink_link.hpp) implements it; nothing in the app knows the protocol.

#include <cstdint>
#include <string>

#include "sunvo/core/geometry.hpp"
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
  // Attitude covariance of the world attitude (rad^2, world-frame perturbation, the estimator's
  // sun filter), upper triangle xx xy xz yy yz zz; valid only with the sun fusion on.
  double cov_theta_w[6] = {0, 0, 0, 0, 0, 0};
  bool cov_theta_valid = false;
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
  // The telemetry thread's view of the pose stream: stale = no pose for telemetry.pose_timeout_s
  // while the estimator runs. A MAVLink link reports it (HEARTBEAT, STATUSTEXT); default: ignored.
  virtual void setPoseStale(bool stale, TimeNs now_mono_ns) {
    (void)stale;
    (void)now_mono_ns;
  }
  // The geodetic origin of the world frame (deg, deg, m above MSL), set once before the stream
  // starts; a MAVLink link announces it (SET_GPS_GLOBAL_ORIGIN); default: ignored.
  virtual void setWorldOrigin(double lat_deg, double lon_deg, double alt_m) {
    (void)lat_deg;
    (void)lon_deg;
    (void)alt_m;
  }
  // Where the estimator's camera c sits in the body frame b the stream reports (T_b_c: rotation
  // C_b_c, lever arm t_b_c = c's origin in b, m), set once before the stream starts; a MAVLink
  // link sends the body's pose; default: ignored.
  virtual void setCameraMount(const Isometry3& T_b_c) { (void)T_b_c; }
  // One line of counters for the summary.
  virtual std::string countersText() const = 0;
};

}  // namespace sunvo::rover
