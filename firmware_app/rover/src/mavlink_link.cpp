#include "sunvo/rover/mavlink_link.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::rover {

mavlink::OdometryInput odometryInput(const PoseRecord& pose, const TelemetryConfig& telemetry,
                                     double distance_m) {
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
    in.cov_pose.setZero();  // [dtheta_w; dp_w]
    if (pose.cov_theta_valid) {
      const double* u = pose.cov_theta_w;  // xx xy xz yy yz zz
      in.cov_pose.topLeftCorner<3, 3>() << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
    } else {
      const double s_rot = telemetry.attitude_sigma_deg * M_PI / 180.0;
      in.cov_pose.topLeftCorner<3, 3>().diagonal().setConstant(s_rot * s_rot);
    }
    // sigma_p = sigma_0 + k * distance: VO position error grows roughly in proportion to the
    // path length; the same sigma on each axis.
    const double s_pos = telemetry.position_sigma_m + telemetry.position_sigma_per_m * distance_m;
    in.cov_pose.bottomRightCorner<3, 3>().diagonal().setConstant(s_pos * s_pos);
  }
  in.reset_counter = pose.reset_counter;
  return in;
}

Isometry3 bodyFromCamera(const BodyConfig& body, const Eigen::Matrix3d& C_c_l) {
  constexpr double kDeg = M_PI / 180.0;
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(body.camera_yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(body.camera_pitch_deg * kDeg, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(body.camera_roll_deg * kDeg, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Matrix3d C_b_l = turn * mavlink::cameraForwardC_b_c();
  Isometry3 T_b_c = Isometry3::Identity();
  T_b_c.linear() = C_b_l * C_c_l.transpose();
  T_b_c.translation() = Eigen::Vector3d(body.camera_x_m, body.camera_y_m, body.camera_z_m);
  return T_b_c;
}

void moveToBodyOrigin(const Eigen::Vector3d& t_b_c, const Eigen::Matrix3d& C_b_c,
                      mavlink::OdometryInput* in) {
  if (t_b_c.isZero(0.0)) return;
  const Eigen::Vector3d t_c_b = -C_b_c.transpose() * t_b_c;
  const Eigen::Matrix3d C_w_c = in->T_w_c.linear();
  in->T_w_c.translation() += C_w_c * t_c_b;
  if (in->v_w.allFinite() && in->omega_c.allFinite()) {
    in->v_w += C_w_c * in->omega_c.cross(t_c_b);
  }
}

mavlink::SetGpsGlobalOrigin globalOrigin(double lat_deg, double lon_deg, double alt_m) {
  mavlink::SetGpsGlobalOrigin o;
  o.latitude = static_cast<std::int32_t>(std::lround(lat_deg * 1e7));
  o.longitude = static_cast<std::int32_t>(std::lround(lon_deg * 1e7));
  o.altitude = static_cast<std::int32_t>(std::lround(alt_m * 1e3));
  o.target_system = 0;  // broadcast: the autopilot's system id is not configured
  o.time_usec = 0;
  return o;
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
  const auto status = static_cast<vo::TrackingStatus>(pose.tracking);
  const Eigen::Vector3d p_w(pose.p_w[0], pose.p_w[1], pose.p_w[2]);
  if (status == vo::TrackingStatus::kTracking && have_last_p_ && p_w.allFinite()) {
    distance_m_ += (p_w - last_p_w_).norm();
  }
  // A recovered frame restarts the chain: its jump is not distance travelled.
  have_last_p_ = status != vo::TrackingStatus::kLost && p_w.allFinite();
  if (have_last_p_) last_p_w_ = p_w;
  const bool lost = status == vo::TrackingStatus::kLost;
  if (lost && !lost_) queueText(mavlink::kMavSeverityCritical, "sunvo: VO tracking lost");
  if (status == vo::TrackingStatus::kRecovered) {
    char text[mavlink::kStatusTextChars + 1];
    std::snprintf(text, sizeof(text), "sunvo: VO recovered, reset %u",
                  static_cast<unsigned>(pose.reset_counter));
    queueText(mavlink::kMavSeverityNotice, text);
  }
  lost_ = lost;

  mavlink::OdometryInput in = odometryInput(pose, telemetry_, distance_m_);
  moveToBodyOrigin(t_b_c_, C_b_c_, &in);
  mavlink::Odometry odo = mavlink::toOdometry(in, mavlink::WorldConvention::kEnu, C_b_c_);
  mavlink::applyProfile(telemetry_.frame, &odo);
  const std::size_t n = mavlink::encodeOdometry(odo, endpoint_, seq_++, buffer_.data());
  Status st = port_->send(buffer_.data(), n, now_mono_ns);
  const Status text_st = sendPendingText(now_mono_ns);
  return st.isOk() ? text_st : st;
}

Status MavlinkSerialLink::sendHeartbeat(TimeNs now_mono_ns) {
  mavlink::Heartbeat hb;
  hb.system_status = lost_ || stale_ ? mavlink::kMavStateCritical : mavlink::kMavStateActive;
  const std::size_t n = mavlink::encodeHeartbeat(hb, endpoint_, seq_++, buffer_.data());
  return port_->send(buffer_.data(), n, now_mono_ns);
}

Status MavlinkSerialLink::sendOrigin(TimeNs now_mono_ns) {
  const std::size_t n =
      mavlink::encodeSetGpsGlobalOrigin(origin_, endpoint_, seq_++, buffer_.data());
  ++origins_sent_;
  return port_->send(buffer_.data(), n, now_mono_ns);
}

void MavlinkSerialLink::setWorldOrigin(double lat_deg, double lon_deg, double alt_m) {
  origin_ = globalOrigin(lat_deg, lon_deg, alt_m);
  have_origin_ = true;
  next_origin_ns_ = 0;  // at the next service()
}

void MavlinkSerialLink::setCameraMount(const Isometry3& T_b_c) {
  C_b_c_ = T_b_c.linear();
  t_b_c_ = T_b_c.translation();
}

void MavlinkSerialLink::setPoseStale(bool stale, TimeNs now_mono_ns) {
  if (stale == stale_) return;
  stale_ = stale;
  if (stale) {
    char text[mavlink::kStatusTextChars + 1];
    std::snprintf(text, sizeof(text), "sunvo: no pose for %.1f s", telemetry_.pose_timeout_s);
    queueText(mavlink::kMavSeverityError, text);
  } else {
    queueText(mavlink::kMavSeverityInfo, "sunvo: poses resumed");
  }
  (void)sendPendingText(now_mono_ns);
}

void MavlinkSerialLink::queueText(std::uint8_t severity, const char* text) {
  pending_text_.severity = severity;
  mavlink::setStatusText(text, &pending_text_);
  text_pending_ = true;
}

Status MavlinkSerialLink::sendPendingText(TimeNs now_mono_ns) {
  if (!text_pending_) return Status::ok();
  const auto min_gap = static_cast<TimeNs>(telemetry_.statustext_min_interval_s * 1e9);
  if (text_sent_once_ && now_mono_ns - last_text_ns_ < min_gap) return Status::ok();
  const std::size_t n = mavlink::encodeStatusText(pending_text_, endpoint_, seq_++, buffer_.data());
  text_pending_ = false;
  text_sent_once_ = true;
  last_text_ns_ = now_mono_ns;
  ++texts_sent_;
  return port_->send(buffer_.data(), n, now_mono_ns);
}

Status MavlinkSerialLink::service(TimeNs now_mono_ns) {
  Status st = Status::ok();
  if (have_origin_ && now_mono_ns >= next_origin_ns_) {
    st = sendOrigin(now_mono_ns);
    next_origin_ns_ = telemetry_.origin_period_s > 0.0
                          ? now_mono_ns + static_cast<TimeNs>(telemetry_.origin_period_s * 1e9)
                          : std::numeric_limits<TimeNs>::max();
  }
  const Status text_st = sendPendingText(now_mono_ns);
  const Status flush_st = port_->flush(now_mono_ns);
  if (!st.isOk()) return st;
  return text_st.isOk() ? flush_st : text_st;
}

std::string MavlinkSerialLink::countersText() const {
  const serial::SerialCounters& c = port_->counters();
  char line[400];
  std::snprintf(line, sizeof(line),
                "%s: frames queued %" PRIu64 ", written %" PRIu64 ", dropped %" PRIu64
                ", bytes written %" PRIu64 ", would-block %" PRIu64 ", write errors %" PRIu64
                ", reopens %" PRIu64 "; origins %" PRIu64 ", status texts %" PRIu64
                ", distance %.1f m",
                port_->options().device.c_str(), c.frames_queued, c.frames_written,
                c.frames_dropped, c.bytes_written, c.write_would_block, c.write_errors, c.reopens,
                origins_sent_, texts_sent_, distance_m_);
  return line;
}

}  // namespace sunvo::rover
