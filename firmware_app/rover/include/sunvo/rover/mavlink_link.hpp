#pragma once
// PoseLink over a serial port with MAVLink v2: ODOMETRY (#331) per pose, HEARTBEAT (#0) on
// request (drivers/mavlink for the framing and the frame conventions, drivers/serial for the
// non-blocking port). The world is ENU at the first GPS fix (MAV_FRAME_LOCAL_NED on the wire),
// the body is the camera looking forward (MAV_FRAME_BODY_FRD). Covariance: the configured
// position and attitude sigmas while tracking, x10 after a recovery, unknown while lost.
// Quality: 100 * RANSAC inliers / full_quality_inliers (capped at 100) while tracking, half of
// that on a recovered frame, -1 while lost.

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
mavlink::OdometryInput odometryInput(const PoseRecord& pose, const TelemetryConfig& telemetry);

class MavlinkSerialLink final : public PoseLink {
 public:
  static Expected<std::unique_ptr<MavlinkSerialLink>> open(const SerialConfig& serial,
                                                           const TelemetryConfig& telemetry);
  Status sendPose(const PoseRecord& pose, TimeNs now_mono_ns) override;
  Status sendHeartbeat(TimeNs now_mono_ns) override;
  Status service(TimeNs now_mono_ns) override;
  bool drained() const override { return port_->queuedBytes() == 0; }
  TimeNs lastByteWrittenNs() const override { return port_->lastByteWrittenNs(); }
  std::string countersText() const override;

 private:
  MavlinkSerialLink(std::unique_ptr<serial::SerialPort> port, const TelemetryConfig& telemetry);

  std::unique_ptr<serial::SerialPort> port_;
  TelemetryConfig telemetry_;
  mavlink::Endpoint endpoint_;
  Eigen::Matrix3d C_b_c_;
  std::uint8_t seq_ = 0;
  std::array<std::uint8_t, mavlink::kMaxFrameBytes> buffer_{};
};

}  // namespace sunvo::rover
