#pragma once
// From the estimator's camera pose to the MAVLink ODOMETRY message: frames, quaternion and
// covariance conventions. docs/telemetry.md explains them with figures and examples.
//
// Frames:
//   c  camera: x right, y down, z forward (the estimator's frame).
//   b  body, MAV_FRAME_BODY_FRD: x forward, y right, z down. C_b_c is configurable; the default
//      (kCameraForward) is a camera looking forward: b.x = c.z, b.y = c.x, b.z = c.y.
//   w  the estimator's world: ENU (x east, y north, z up) at the first GPS fix (kEnu), or the
//      first camera frame when there is no GPS (kCameraFirstFrame).
//   l  the frame the pose is sent in:
//      kEnu              -> MAV_FRAME_LOCAL_NED: l.x = north = w.y, l.y = east = w.x, l.z = -w.z.
//      kCameraFirstFrame -> MAV_FRAME_LOCAL_FRD: the body frame at the first camera frame
//                           (x forward, y right, z down); l = b at time 0, so C_l_w = C_b_c.
// The body origin is the camera origin (no lever arm).

#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/mavlink/mavlink.hpp"

namespace sunvo::mavlink {

// b.x = c.z, b.y = c.x, b.z = c.y (rows are the body axes in camera coordinates).
Eigen::Matrix3d cameraForwardC_b_c();

struct OdometryInput {
  TimeNs time_ns = 0;  // UTC ns of the camera frame (sent as us; < 0 sent as 0)
  Isometry3 T_w_c = Isometry3::Identity();  // camera pose in the estimator's world
  Eigen::Vector3d v_w = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // ^ m/s, velocity of the camera in w; NaN = unknown (sent as NaN, which PX4 reads as unknown)
  Eigen::Vector3d omega_c = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // ^ rad/s, angular velocity of the camera in c; NaN = unknown
  // Covariance of the pose error [dtheta_w; dp_w]: rotation first (rad^2, a world-frame
  // perturbation C_w_c = Exp(dtheta_w) * C_w_c_est), then the camera position in w (m^2).
  // Any non-finite entry = unknown (pose_covariance[0] is sent as NaN).
  Eigen::Matrix<double, 6, 6> cov_pose =
      Eigen::Matrix<double, 6, 6>::Constant(std::numeric_limits<double>::quiet_NaN());
  int quality_percent = 0;         // 0..100 (0 = unknown), -1 = tracking failed
  std::uint8_t reset_counter = 0;  // incremented by the caller when the estimator re-initialises
};

enum class WorldConvention { kEnu, kCameraFirstFrame };

// Which autopilot reads the stream; only the frame ids differ (docs/telemetry.md, "Autopilot
// profiles", cites the receiving code of each):
//   kPx4       frame_id as toOdometry sets it: MAV_FRAME_LOCAL_NED (1) for kEnu, LOCAL_FRD (20)
//              for kCameraFirstFrame; child_frame_id MAV_FRAME_BODY_FRD (12).
//   kArduPilot frame_id MAV_FRAME_LOCAL_FRD (20), child_frame_id MAV_FRAME_BODY_FRD (12): the only
//              pair ArduPilot's ODOMETRY handler takes. For kEnu the numbers stay NED: a NED frame
//              is an earth-fixed FRD frame whose forward axis is north.
enum class FrameProfile { kPx4, kArduPilot };
void applyProfile(FrameProfile profile, Odometry* odo);

// Rotation from the estimator's world w to the sent frame l (see above).
Eigen::Matrix3d worldToLocal(WorldConvention world, const Eigen::Matrix3d& C_b_c);

// Fills ODOMETRY: position p_l = C_l_w * t_w_c; q = C_l_b = C_l_w * C_w_c * C_b_c^T as (w,x,y,z);
// velocity v_b = C_b_c * C_w_c^T * v_w; rates omega_b = C_b_c * omega_c; pose covariance of
// (x, y, z, roll, pitch, yaw) in l with roll/pitch/yaw the ZYX Euler angles of C_l_b, mapped
// from cov_pose by the first-order Jacobian; velocity covariance unknown (NaN). A non-finite
// pose is sent as the identity at the origin with quality -1 and unknown covariance, so the
// stream never carries a NaN position or attitude.
Odometry toOdometry(const OdometryInput& in, WorldConvention world, const Eigen::Matrix3d& C_b_c);

// ZYX Euler angles (roll, pitch, yaw) of a rotation C_l_b = Rz(yaw) * Ry(pitch) * Rx(roll).
Eigen::Vector3d rollPitchYaw(const Eigen::Matrix3d& C_l_b);

}  // namespace sunvo::mavlink
