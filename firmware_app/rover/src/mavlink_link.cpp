#include "sunvo/rover/mavlink_link.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::rover {

mavlink::OdometryInput odometryInput(const PoseRecord& pose, const TelemetryConfig& telemetry) {
  mavlink::OdometryInput in;
  in.time_ns = pose.utc_ns;
  in.T_w_c.translation() = Eigen::Vector3d(pose.p_w[0], pose.p_w[1], pose.p_w[2]);
  in.T_w_c.linear() = Eigen::Quaterniond(pose.q_w_c[3], pose.q_w_c[0], pose.q_w_c[1], pose.q_w_c[2])
                          .normalized()
                          .toRotationMatrix();
  if (pose.velocity_valid) {
    in.v_w = Eigen::Vector3d(pose.v_w[0], pose.v_w[1], pose.v_w[2]);
    in.omega_c = Eigen::Vector3d(pose.omega_c[0], pose.omega_c[1], pose.omega_c[2]);
  }
  const auto status = static_cast<vo::TrackingStatus>(pose.tracking);
  const double share = std::min(1.0, static_cast<double>(pose.ransac_inliers) /
                                         static_cast<double>(telemetry.full_quality_inliers));
  const int quality = std::max(1, static_cast<int>(std::lround(100.0 * share)));
  switch (status) {
    case vo::TrackingStatus::kLost:
      in.quality_percent = -1;
      break;
    case vo::TrackingStatus::kRecovered:
      in.quality_percent = std::max(1, quality / 2);
      break;
    case vo::TrackingStatus::kInitializing:
      in.quality_percent = 0;  // unknown: the first frame
      break;
    case vo::TrackingStatus::kTracking:
      in.quality_percent = quality;
      break;
  }
  if (status != vo::TrackingStatus::kLost) {
    const double inflate = status == vo::TrackingStatus::kRecovered ? 10.0 : 1.0;
    const double s_rot = telemetry.attitude_sigma_deg * M_PI / 180.0 * inflate;
    const double s_pos = telemetry.position_sigma_m * inflate;
    in.cov_pose.setZero();  // [dtheta_w; dp_w]
    in.cov_pose.diagonal() << s_rot * s_rot, s_rot * s_rot, s_rot * s_rot, s_pos * s_pos,
        s_pos * s_pos, s_pos * s_pos;
  }
  in.reset_counter = pose.reset_counter;
  return in;
}

MavlinkSerialLink::MavlinkSerialLink(std::unique_ptr<serial::SerialPort> port,
                                     const TelemetryConfig& telemetry)
    : port_(std::move(port)), telemetry_(telemetry), C_b_c_(mavlink::cameraForwardC_b_c()) {
  endpoint_.system_id = static_cast<std::uint8_t>(telemetry.system_id);
  endpoint_.component_id = static_cast<std::uint8_t>(telemetry.component_id);
}

Expected<std::unique_ptr<MavlinkSerialLink>> MavlinkSerialLink::open(
    const SerialConfig& serial, const TelemetryConfig& telemetry) {
  serial::SerialOptions so;
  so.device = serial.device;
  so.baud = serial.baud;
  so.tx_buffer_bytes = static_cast<std::size_t>(serial.tx_buffer_bytes);
  auto port = serial::SerialPort::open(so);
  if (!port) return port.status();
  return std::unique_ptr<MavlinkSerialLink>(new MavlinkSerialLink(std::move(*port), telemetry));
}

Status MavlinkSerialLink::sendPose(const PoseRecord& pose, TimeNs now_mono_ns) {
  const mavlink::Odometry odo =
      mavlink::toOdometry(odometryInput(pose, telemetry_), mavlink::WorldConvention::kEnu, C_b_c_);
  const std::size_t n = mavlink::encodeOdometry(odo, endpoint_, seq_++, buffer_.data());
  return port_->send(buffer_.data(), n, now_mono_ns);
}

Status MavlinkSerialLink::sendHeartbeat(TimeNs now_mono_ns) {
  const std::size_t n =
      mavlink::encodeHeartbeat(mavlink::Heartbeat{}, endpoint_, seq_++, buffer_.data());
  return port_->send(buffer_.data(), n, now_mono_ns);
}

Status MavlinkSerialLink::service(TimeNs now_mono_ns) {
  return port_->flush(now_mono_ns);
}

std::string MavlinkSerialLink::countersText() const {
  const serial::SerialCounters& c = port_->counters();
  char line[320];
  std::snprintf(line, sizeof(line),
                "%s: frames queued %" PRIu64 ", written %" PRIu64 ", dropped %" PRIu64
                ", bytes written %" PRIu64 ", would-block %" PRIu64 ", write errors %" PRIu64
                ", reopens %" PRIu64,
                port_->options().device.c_str(), c.frames_queued, c.frames_written,
                c.frames_dropped, c.bytes_written, c.write_would_block, c.write_errors, c.reopens);
  return line;
}

}  // namespace sunvo::rover
