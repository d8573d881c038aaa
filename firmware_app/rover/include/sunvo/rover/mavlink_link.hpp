#pragma once
// PoseLink over a serial port with MAVLink v2 (drivers/mavlink for the framing and the frame
// conventions, drivers/serial for the non-blocking port). Sends:
//   ODOMETRY (#331) per pose. The world is ENU at the first GPS fix, sent as NED numbers; the
//     body (MAV_FRAME_BODY_FRD) is body.* (T_b_c: a forward-looking camera by default, lever arm
//     applied to position and velocity). frame_id by telemetry.frame:
//     px4 -> MAV_FRAME_LOCAL_NED, ardupilot -> MAV_FRAME_LOCAL_FRD. Covariance: attitude from the
//     sun filter (world frame, rotated into the sent frame by toOdometry) or the configured sigma
//     without the sun; position sigma = position_sigma_m + position_sigma_per_m * path length
//     since start (summed over tracked frames). Unknown (NaN) while lost. Quality: 100 * RANSAC
//     inliers / full_quality_inliers (capped at 100) while tracking, half of that on a recovered
//     frame, -1 while lost.
//   SET_GPS_GLOBAL_ORIGIN (#48) once the app has set the world origin (world.init config: world.*;
//     oxts: the drive's first fix), then every telemetry.origin_period_s. The port is write-only
//     here, so requests are not read: the periodic resend answers them.
//   HEARTBEAT (#0): system_status ACTIVE, CRITICAL while tracking is lost or poses are stale.
//   STATUSTEXT (#253) on fault transitions (lost, recovered, stale, resumed), at most one per
//     statustext_min_interval_s; a newer text replaces a waiting one. No allocation.

#include <array>
#include <memory>
#include <string>

#include "sunvo/mavlink/conventions.hpp"
#include "sunvo/mavlink/mavlink.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/pose_link.hpp"
#include "sunvo/serial/serial_port.hpp"

namespace sunvo::rover {

// The ODOMETRY input of a pose (also used by tests and the HIL reader's checks).
// distance_m: path length since start, m (position sigma grows with it).
mavlink::OdometryInput odometryInput(const PoseRecord& pose, const TelemetryConfig& telemetry,
                                     double distance_m);

// T_b_c of body.*: the rotation of the configured mount times C_c_l^T (the images' camera c from
// the physical left camera l, e.g. the rectification), the lever arm (camera_x_m, _y_m, _z_m).
Isometry3 bodyFromCamera(const BodyConfig& body, const Eigen::Matrix3d& C_c_l);

// Moves an ODOMETRY input from the camera's origin to the body's: with t_c_b = -C_b_c^T t_b_c
// (the body origin in c), p_w_b = p_w_c + C_w_c t_c_b and, for a rigid body,
// v_w_b = v_w_c + C_w_c (omega_c x t_c_b). The attitude stays C_w_c (toOdometry applies C_b_c);
// the covariance is kept (the lever arm's share of it is second order for small attitude errors).
void moveToBodyOrigin(const Eigen::Vector3d& t_b_c, const Eigen::Matrix3d& C_b_c,
                      mavlink::OdometryInput* in);

// The SET_GPS_GLOBAL_ORIGIN of a world origin (deg, deg, m above MSL); time_usec 0 (unknown).
mavlink::SetGpsGlobalOrigin globalOrigin(double lat_deg, double lon_deg, double alt_m);

class MavlinkSerialLink final : public PoseLink {
 public:
  static Expected<std::unique_ptr<MavlinkSerialLink>> open(const SerialConfig& serial,
                                                           const TelemetryConfig& telemetry);
  Status sendPose(const PoseRecord& pose, TimeNs now_mono_ns) override;
  Status sendHeartbeat(TimeNs now_mono_ns) override;
  Status service(TimeNs now_mono_ns) override;
  bool drained() const override { return port_->queuedBytes() == 0; }
  TimeNs lastByteWrittenNs() const override { return port_->lastByteWrittenNs(); }
  void setPoseStale(bool stale, TimeNs now_mono_ns) override;
  void setWorldOrigin(double lat_deg, double lon_deg, double alt_m) override;
  void setCameraMount(const Isometry3& T_b_c) override;
  std::string countersText() const override;
  double distanceM() const { return distance_m_; }

 private:
  MavlinkSerialLink(std::unique_ptr<serial::SerialPort> port, const TelemetryConfig& telemetry);
  Status sendOrigin(TimeNs now_mono_ns);
  // Queues a STATUSTEXT (replacing one that waits) and sends it when the rate limit allows.
  void queueText(std::uint8_t severity, const char* text);
  Status sendPendingText(TimeNs now_mono_ns);

  std::unique_ptr<serial::SerialPort> port_;
  TelemetryConfig telemetry_;
  mavlink::Endpoint endpoint_;
  Eigen::Matrix3d C_b_c_;                            // camera -> body rotation (setCameraMount)
  Eigen::Vector3d t_b_c_ = Eigen::Vector3d::Zero();  // m, the camera's origin in the body
  mavlink::SetGpsGlobalOrigin origin_;
  bool have_origin_ = false;
  std::uint8_t seq_ = 0;
  // Path length over tracked frames, m, and the last tracked position.
  double distance_m_ = 0.0;
  bool have_last_p_ = false;
  Eigen::Vector3d last_p_w_ = Eigen::Vector3d::Zero();
  bool lost_ = false;   // the last pose was kLost
  bool stale_ = false;  // setPoseStale(true) last
  TimeNs next_origin_ns_ = 0;
  mavlink::StatusText pending_text_;
  bool text_pending_ = false;
  bool text_sent_once_ = false;
  TimeNs last_text_ns_ = 0;
  std::uint64_t texts_sent_ = 0;
  std::uint64_t origins_sent_ = 0;
  std::array<std::uint8_t, mavlink::kMaxFrameBytes> buffer_{};
};

}  // namespace sunvo::rover
