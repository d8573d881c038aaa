// MavlinkSerialLink, the rover's pose stream, through a pseudo-terminal: the bytes read from the
// master are decoded with drivers/mavlink's decoder and each ODOMETRY is put through the
// acceptance rules of the autopilot its profile is for, as docs/telemetry.md ("Autopilot
// profiles") states them from the autopilots' receiving code:
//   PX4 MavlinkReceiver::handle_message_odometry: estimator_type UNKNOWN/NAIVE/VISION/VIO is
//     published as visual odometry; the position is used only when finite and frame_id is a
//     local frame it knows (LOCAL_NED -> NED pose, LOCAL_FRD -> FRD pose); the variances are read
//     from pose_covariance[0, 6, 11] and [15, 18, 20]; q only when all four are finite; the
//     velocity only when finite and child_frame_id is one it knows (BODY_FRD -> body velocity).
//   ArduPilot GCS_MAVLINK::handle_odometry: dropped unless frame_id LOCAL_FRD and child_frame_id
//     BODY_FRD; posErr / angErr are the cube roots of the sums of the squared diagonal variances
//     when pose_covariance[0] is not NaN (else 0); the velocity is rotated by q from body to the
//     local frame.
// Time is simulated (now_ns passed in), so rate limits and periods are exact.

#include "sunvo/rover/mavlink_link.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "../support/pty.hpp"
#include "../support/telemetry.hpp"
#include "sunvo/mavlink/mavlink.hpp"
#include "sunvo/vo/stereo_track_odometry.hpp"

namespace sunvo::rover {
namespace {

using mavlink::Frame;
using mavlink::Odometry;

// --- PX4: what reaches EKF2's external-vision input from one ODOMETRY.
struct Px4View {
  bool published = false;  // estimator_type accepted
  int pose_frame = 0;      // 0 unknown, 1 NED, 2 FRD (vehicle_odometry POSE_FRAME_*)
  bool position = false;
  bool attitude = false;
  int velocity_frame = 0;  // 0 unknown, 1 NED, 2 FRD, 3 BODY_FRD
  Eigen::Vector3f position_variance = Eigen::Vector3f::Constant(NAN);
  Eigen::Vector3f orientation_variance = Eigen::Vector3f::Constant(NAN);
};

Px4View px4Receives(const Odometry& m) {
  Px4View v;
  v.published = m.estimator_type <= 3;  // UNKNOWN 0, NAIVE 1, VISION 2, VIO 3
  const bool naive = m.estimator_type == 1;
  if (std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z)) {
    if (m.frame_id == mavlink::kMavFrameLocalNed) v.pose_frame = 1;
    if (m.frame_id == mavlink::kMavFrameLocalFrd) v.pose_frame = 2;
    v.position = v.pose_frame != 0;
    if (v.position && !naive) {
      v.position_variance << m.pose_covariance[0], m.pose_covariance[6], m.pose_covariance[11];
    }
  }
  if (std::isfinite(m.q[0]) && std::isfinite(m.q[1]) && std::isfinite(m.q[2]) &&
      std::isfinite(m.q[3])) {
    v.attitude = true;
    if (!naive) {
      v.orientation_variance << m.pose_covariance[15], m.pose_covariance[18], m.pose_covariance[20];
    }
  }
  if (std::isfinite(m.vx) && std::isfinite(m.vy) && std::isfinite(m.vz)) {
    if (m.child_frame_id == mavlink::kMavFrameLocalNed) v.velocity_frame = 1;
    if (m.child_frame_id == mavlink::kMavFrameLocalFrd) v.velocity_frame = 2;
    if (m.child_frame_id == mavlink::kMavFrameBodyFrd) v.velocity_frame = 3;
  }
  return v;
}

// --- ArduPilot: what AP_VisualOdom gets from one ODOMETRY (nothing when dropped).
struct ArduPilotView {
  bool accepted = false;
  float pos_err = 0.0f, ang_err = 0.0f;
  Eigen::Vector3f velocity_local = Eigen::Vector3f::Zero();  // q * v_body
};

ArduPilotView ardupilotReceives(const Odometry& m) {
  ArduPilotView v;
  if (m.frame_id != mavlink::kMavFrameLocalFrd || m.child_frame_id != mavlink::kMavFrameBodyFrd) {
    return v;
  }
  v.accepted = true;
  const auto& c = m.pose_covariance;
  if (!std::isnan(c[0])) {
    v.pos_err = std::cbrt(c[0] * c[0] + c[6] * c[6] + c[11] * c[11]);
    v.ang_err = std::cbrt(c[15] * c[15] + c[18] * c[18] + c[20] * c[20]);
  }
  const Eigen::Quaternionf q(m.q[0], m.q[1], m.q[2], m.q[3]);
  v.velocity_local = q * Eigen::Vector3f(m.vx, m.vy, m.vz);
  return v;
}

// Everything read from the pty so far, decoded and sorted by message.
struct Received {
  std::vector<Odometry> odometry;
  std::vector<mavlink::Heartbeat> heartbeats;
  std::vector<mavlink::SetGpsGlobalOrigin> origins;
  std::vector<mavlink::StatusText> texts;
};

void readInto(sunvo::testing::PseudoTerminal& pty, mavlink::Decoder* decoder, Received* r) {
  std::vector<std::uint8_t> bytes;
  pty.read(&bytes, 5);
  for (const Frame& f : sunvo::testing::decodeAll(bytes, decoder)) {
    Odometry o;
    mavlink::Heartbeat h;
    mavlink::SetGpsGlobalOrigin g;
    mavlink::StatusText t;
    if (mavlink::decodeOdometry(f, &o)) r->odometry.push_back(o);
    if (mavlink::decodeHeartbeat(f, &h)) r->heartbeats.push_back(h);
    if (mavlink::decodeSetGpsGlobalOrigin(f, &g)) r->origins.push_back(g);
    if (mavlink::decodeStatusText(f, &t)) r->texts.push_back(t);
  }
}

std::string textOf(const mavlink::StatusText& t) {
  std::string s(t.text.data(), t.text.size());
  return s.substr(0, s.find('\0'));
}

// A camera looking east (ENU x), level, driving east at 5 m/s, 10 Hz: 0.5 m per frame.
PoseRecord drivePose(int k, vo::TrackingStatus status, std::uint8_t reset_counter) {
  PoseRecord p;
  p.sequence = static_cast<std::uint64_t>(k);
  p.utc_ns = 1'317'380'000'000'000'000 + static_cast<TimeNs>(k) * 100'000'000;
  p.p_w[0] = 0.5 * k;
  Eigen::Matrix3d C_w_c;  // columns: camera x (right) = south, y (down) = -up, z = east
  C_w_c << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Quaterniond q(C_w_c);
  p.q_w_c[0] = q.x();
  p.q_w_c[1] = q.y();
  p.q_w_c[2] = q.z();
  p.q_w_c[3] = q.w();
  p.v_w[0] = 5.0;
  p.velocity_valid = k > 0 && status == vo::TrackingStatus::kTracking;
  p.tracking = static_cast<int>(status);
  p.ransac_inliers = 120;
  p.reset_counter = reset_counter;
  // The sun filter's world attitude covariance, rad^2: diag(1e-4, 2e-4, 3e-4) about east, north,
  // up.
  p.cov_theta_w[0] = 1e-4;
  p.cov_theta_w[3] = 2e-4;
  p.cov_theta_w[5] = 3e-4;
  p.cov_theta_valid = true;
  return p;
}

struct StreamRun {
  Received r;
  std::vector<TimeNs> text_times;  // simulated time at which each STATUSTEXT was read
};

// 20 tracked frames, one lost, one recovered, 18 tracked; origin and heartbeats in between; then
// a stale period. Returns what the master side read.
StreamRun driveThroughPty(mavlink::FrameProfile profile) {
  StreamRun run;
  sunvo::testing::PseudoTerminal pty;
  EXPECT_TRUE(pty.ok()) << pty.error();
  SerialConfig serial;
  serial.device = pty.slavePath();
  TelemetryConfig telemetry;
  telemetry.frame = profile;
  auto link = MavlinkSerialLink::open(serial, telemetry);
  EXPECT_TRUE(link) << link.status().toString();
  if (!link) return run;
  (*link)->setWorldOrigin(49.0112345, 8.4123456, 112.5);
  mavlink::Decoder decoder;
  const TimeNs t0 = 1'000'000'000;
  std::uint8_t resets = 0;
  for (int k = 0; k < 40; ++k) {
    const TimeNs now = t0 + static_cast<TimeNs>(k) * 100'000'000;
    vo::TrackingStatus status = vo::TrackingStatus::kTracking;
    if (k == 0) status = vo::TrackingStatus::kInitializing;
    if (k == 20) status = vo::TrackingStatus::kLost;
    if (k == 21) {
      status = vo::TrackingStatus::kRecovered;
      ++resets;
    }
    EXPECT_TRUE((*link)->sendPose(drivePose(k, status, resets), now).isOk());
    EXPECT_TRUE((*link)->service(now).isOk());
    if (k % 10 == 0) {
      EXPECT_TRUE((*link)->sendHeartbeat(now).isOk());
    }
    const std::size_t texts = run.r.texts.size();
    readInto(pty, &decoder, &run.r);
    for (std::size_t i = texts; i < run.r.texts.size(); ++i) run.text_times.push_back(now);
  }
  // No pose for a while (the caller decides; here at t0 + 5 s), then poses again at + 11 s.
  const TimeNs t_stale = t0 + 5'000'000'000;
  (*link)->setPoseStale(true, t_stale);
  EXPECT_TRUE((*link)->sendHeartbeat(t_stale).isOk());
  EXPECT_TRUE((*link)->service(t_stale).isOk());
  (*link)->setPoseStale(false, t0 + 11'000'000'000);
  EXPECT_TRUE((*link)->service(t0 + 11'000'000'000).isOk());  // also the 10 s origin resend
  EXPECT_TRUE((*link)->sendHeartbeat(t0 + 11'000'000'000).isOk());
  readInto(pty, &decoder, &run.r);
  EXPECT_EQ(decoder.counters().crc_errors, 0u);
  EXPECT_EQ(decoder.counters().unknown_msgid, 0u);
  return run;
}

// What both profiles share: origin, heartbeat states, texts, covariance growth.
void checkCommon(const StreamRun& run) {
  const Received& r = run.r;
  ASSERT_EQ(r.odometry.size(), 40u);
  // SET_GPS_GLOBAL_ORIGIN at the first service() and again 10 s later.
  ASSERT_EQ(r.origins.size(), 2u);
  for (const auto& o : r.origins) {
    EXPECT_EQ(o.latitude, 490112345);  // degE7
    EXPECT_EQ(o.longitude, 84123456);
    EXPECT_EQ(o.altitude, 112500);  // mm
    EXPECT_EQ(o.target_system, 0);
  }
  // HEARTBEAT: active at k = 0 and 10, critical while lost (k = 20), active again at k = 30,
  // critical while stale, active once poses resume.
  ASSERT_EQ(r.heartbeats.size(), 6u);
  EXPECT_EQ(r.heartbeats[0].system_status, mavlink::kMavStateActive);
  EXPECT_EQ(r.heartbeats[1].system_status, mavlink::kMavStateActive);
  EXPECT_EQ(r.heartbeats[2].system_status, mavlink::kMavStateCritical);  // lost
  EXPECT_EQ(r.heartbeats[3].system_status, mavlink::kMavStateActive);
  EXPECT_EQ(r.heartbeats[4].system_status, mavlink::kMavStateCritical);  // stale
  EXPECT_EQ(r.heartbeats[5].system_status, mavlink::kMavStateActive);
  // STATUSTEXT: lost at 2.0 s; recovered (2.1 s) waits out the 1 s limit to 3.0 s; stale; resumed.
  ASSERT_EQ(r.texts.size(), 4u);
  EXPECT_EQ(textOf(r.texts[0]), "sunvo: VO tracking lost");
  EXPECT_EQ(r.texts[0].severity, mavlink::kMavSeverityCritical);
  EXPECT_EQ(textOf(r.texts[1]), "sunvo: VO recovered, reset 1");
  EXPECT_EQ(run.text_times[1] - run.text_times[0], 1'000'000'000);
  EXPECT_EQ(textOf(r.texts[2]), "sunvo: no pose for 1.0 s");
  EXPECT_EQ(r.texts[2].severity, mavlink::kMavSeverityError);
  EXPECT_EQ(textOf(r.texts[3]), "sunvo: poses resumed");
  // reset_counter and quality follow tracking.
  EXPECT_EQ(r.odometry[19].reset_counter, 0);
  EXPECT_EQ(r.odometry[20].quality, -1);
  EXPECT_TRUE(std::isnan(r.odometry[20].pose_covariance[0]));
  EXPECT_EQ(r.odometry[21].reset_counter, 1);
  EXPECT_EQ(r.odometry[39].reset_counter, 1);
  // Position sigma = 0.1 m + 2 % of the path: 0.5 m per tracked frame; the lost frame and the
  // recovery jump add nothing (frames 20 and 21), so frame 39 has 19 + 18 steps.
  float previous = 0.0f;
  for (int k = 0; k < 40; ++k) {
    if (k == 20) continue;
    const int steps = k < 20 ? k : k - 2;
    const double sigma = 0.1 + 0.02 * 0.5 * steps;
    const Odometry& o = r.odometry[static_cast<std::size_t>(k)];
    EXPECT_NEAR(o.pose_covariance[0], sigma * sigma, 1e-6) << "frame " << k;
    EXPECT_NEAR(o.pose_covariance[6], sigma * sigma, 1e-6) << "frame " << k;
    EXPECT_NEAR(o.pose_covariance[11], sigma * sigma, 1e-6) << "frame " << k;
    EXPECT_GE(o.pose_covariance[0], previous) << "frame " << k;
    previous = o.pose_covariance[0];
    // Attitude: facing east, roll is about east (1e-4), pitch about south (2e-4), yaw about
    // down (3e-4): the world covariance rotated into (roll, pitch, yaw).
    EXPECT_NEAR(o.pose_covariance[15], 1e-4, 1e-9) << "frame " << k;
    EXPECT_NEAR(o.pose_covariance[18], 2e-4, 1e-9) << "frame " << k;
    EXPECT_NEAR(o.pose_covariance[20], 3e-4, 1e-9) << "frame " << k;
    const Eigen::Vector4f q(o.q[0], o.q[1], o.q[2], o.q[3]);
    EXPECT_NEAR(q.norm(), 1.0f, 1e-6f) << "frame " << k;
  }
  EXPECT_GT(r.odometry[39].pose_covariance[0], 4.0f * r.odometry[1].pose_covariance[0]);
}

// body.*: the mount turns the forward-looking camera about the body axes, the rectification's
// rotation is undone, and the lever arm moves position and velocity to the body origin.
TEST(MavlinkLink, CameraMountAndLeverArmGiveTheBodyPose) {
  constexpr double kDeg = M_PI / 180.0;
  const Eigen::Vector3d optical_axis_c(0, 0, 1);
  BodyConfig body;
  Isometry3 T_b_c = bodyFromCamera(body, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(T_b_c.linear().isApprox(mavlink::cameraForwardC_b_c()));
  EXPECT_TRUE(T_b_c.translation().isZero());
  body.camera_yaw_deg = 90.0;  // looking right: the optical axis is body y
  EXPECT_TRUE((bodyFromCamera(body, Eigen::Matrix3d::Identity()).linear() * optical_axis_c)
                  .isApprox(Eigen::Vector3d::UnitY()));
  body.camera_yaw_deg = 0.0;
  body.camera_pitch_deg = 10.0;  // tilted up: -z is up in FRD
  const Eigen::Vector3d up =
      bodyFromCamera(body, Eigen::Matrix3d::Identity()).linear() * optical_axis_c;
  EXPECT_NEAR(up.z(), -std::sin(10.0 * kDeg), 1e-12);
  EXPECT_NEAR(up.x(), std::cos(10.0 * kDeg), 1e-12);
  // A rectified camera c turned from the physical one l: C_b_c = C_b_l C_c_l^T.
  const Eigen::Matrix3d C_c_l =
      Eigen::AngleAxisd(0.02, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  body.camera_pitch_deg = 0.0;
  body.camera_x_m = 0.5;
  body.camera_z_m = -0.2;
  T_b_c = bodyFromCamera(body, C_c_l);
  EXPECT_TRUE((T_b_c.linear() * C_c_l).isApprox(mavlink::cameraForwardC_b_c()));
  EXPECT_TRUE(T_b_c.translation().isApprox(Eigen::Vector3d(0.5, 0.0, -0.2)));

  // Lever arm: the body origin's pose is T_w_b = T_w_c T_c_b; its velocity is the camera's plus
  // omega x r for the rigid arm.
  mavlink::OdometryInput in;
  in.T_w_c.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1.0, 0.3).normalized()).toRotationMatrix();
  in.T_w_c.translation() = Eigen::Vector3d(10.0, -4.0, 2.0);
  in.v_w = Eigen::Vector3d(1.0, 0.5, 0.0);
  in.omega_c = Eigen::Vector3d(0.0, 0.3, 0.0);
  const Isometry3 T_w_b = in.T_w_c * T_b_c.inverse();
  moveToBodyOrigin(T_b_c.translation(), T_b_c.linear(), &in);
  EXPECT_TRUE(in.T_w_c.translation().isApprox(T_w_b.translation(), 1e-12));
  const Eigen::Vector3d t_c_b = T_b_c.inverse().translation();
  const Eigen::Vector3d v_expected =
      Eigen::Vector3d(1.0, 0.5, 0.0) +
      in.T_w_c.linear() * Eigen::Vector3d(0.0, 0.3, 0.0).cross(t_c_b);
  EXPECT_TRUE(in.v_w.isApprox(v_expected, 1e-12));
  EXPECT_GT((in.v_w - Eigen::Vector3d(1.0, 0.5, 0.0)).norm(), 0.05);  // the arm is felt
}

TEST(MavlinkLink, Px4ProfilePassesPx4sOdometryHandler) {
  const StreamRun run = driveThroughPty(mavlink::FrameProfile::kPx4);
  checkCommon(run);
  if (HasFatalFailure()) return;
  for (std::size_t k = 0; k < run.r.odometry.size(); ++k) {
    const Odometry& o = run.r.odometry[k];
    const Px4View v = px4Receives(o);
    EXPECT_EQ(o.frame_id, mavlink::kMavFrameLocalNed);
    EXPECT_EQ(o.child_frame_id, mavlink::kMavFrameBodyFrd);
    EXPECT_TRUE(v.published) << k;
    EXPECT_TRUE(v.position && v.pose_frame == 1) << k;  // NED: GPS-aligned, origin at 48
    EXPECT_TRUE(v.attitude) << k;
    if (k == 20) continue;  // lost: quality -1, unknown covariance
    EXPECT_TRUE(v.position_variance.allFinite() && (v.position_variance.array() > 0).all()) << k;
    EXPECT_TRUE(v.orientation_variance.allFinite()) << k;
    if (k == 0 || k == 21) continue;      // no velocity on the first and the recovered frame
    ASSERT_EQ(v.velocity_frame, 3) << k;  // BODY_FRD
    EXPECT_NEAR(o.vx, 5.0f, 1e-5f);       // forward
    EXPECT_NEAR(o.vy, 0.0f, 1e-5f);
    // NED position: east grows.
    EXPECT_NEAR(o.y, 0.5f * static_cast<float>(k), 1e-4f);
    EXPECT_NEAR(o.x, 0.0f, 1e-5f);
  }
  // The same stream would be dropped by ArduPilot: the profile matters.
  EXPECT_FALSE(ardupilotReceives(run.r.odometry[5]).accepted);
}

TEST(MavlinkLink, ArduPilotProfilePassesArduPilotsOdometryHandler) {
  const StreamRun run = driveThroughPty(mavlink::FrameProfile::kArduPilot);
  checkCommon(run);
  if (HasFatalFailure()) return;
  float previous_err = 0.0f;
  for (std::size_t k = 0; k < run.r.odometry.size(); ++k) {
    const Odometry& o = run.r.odometry[k];
    const ArduPilotView v = ardupilotReceives(o);
    ASSERT_TRUE(v.accepted) << k;
    EXPECT_EQ(o.frame_id, mavlink::kMavFrameLocalFrd);
    EXPECT_EQ(o.child_frame_id, mavlink::kMavFrameBodyFrd);
    if (k == 20) {  // lost: NaN covariance -> errors 0, quality -1 (AP_VisualOdom: failed)
      EXPECT_EQ(v.pos_err, 0.0f);
      EXPECT_EQ(o.quality, -1);
      continue;
    }
    EXPECT_TRUE(std::isfinite(v.pos_err) && v.pos_err > 0.0f) << k;
    EXPECT_TRUE(std::isfinite(v.ang_err) && v.ang_err > 0.0f) << k;
    if (k != 21) {
      EXPECT_GE(v.pos_err, previous_err) << k;  // grows with distance
    }
    previous_err = v.pos_err;
    if (k == 0 || k == 21) continue;
    // ArduPilot rotates the body velocity by q: east at 5 m/s in the local (NED-valued) frame.
    EXPECT_NEAR(v.velocity_local.x(), 0.0f, 1e-5f) << k;
    EXPECT_NEAR(v.velocity_local.y(), 5.0f, 1e-5f) << k;
    EXPECT_NEAR(v.velocity_local.z(), 0.0f, 1e-5f) << k;
  }
  // PX4 takes this stream too, as an FRD pose (heading not tied to north).
  EXPECT_EQ(px4Receives(run.r.odometry[5]).pose_frame, 2);
}

}  // namespace
}  // namespace sunvo::rover
