#include "sunvo/mavlink/conventions.hpp"

#include <algorithm>
#include <cmath>

namespace sunvo::mavlink {
namespace {

float toFloat(double v) {
  return static_cast<float>(v);
}

}  // namespace

Eigen::Matrix3d cameraForwardC_b_c() {
  Eigen::Matrix3d C_b_c;
  // Row i = body axis i in camera coordinates: forward = c.z, right = c.x, down = c.y.
  C_b_c << 0, 0, 1,  //
      1, 0, 0,       //
      0, 1, 0;
  return C_b_c;
}

Eigen::Matrix3d worldToLocal(WorldConvention world, const Eigen::Matrix3d& C_b_c) {
  if (world == WorldConvention::kCameraFirstFrame) {
    // l is the body frame of the first camera frame, where T_w_c = identity: C_l_w = C_b_c.
    return C_b_c;
  }
  // ENU -> NED: north = ENU y, east = ENU x, down = -ENU z.
  Eigen::Matrix3d C_l_w;
  C_l_w << 0, 1, 0,  //
      1, 0, 0,       //
      0, 0, -1;
  return C_l_w;
}

Eigen::Vector3d rollPitchYaw(const Eigen::Matrix3d& C_l_b) {
  // C = Rz(yaw) Ry(pitch) Rx(roll): C(2,0) = -sin(pitch), C(1,0)/C(0,0) = tan(yaw) (times
  // cos(pitch)), C(2,1)/C(2,2) = tan(roll) (times cos(pitch)).
  const double pitch = std::asin(std::clamp(-C_l_b(2, 0), -1.0, 1.0));
  const double yaw = std::atan2(C_l_b(1, 0), C_l_b(0, 0));
  const double roll = std::atan2(C_l_b(2, 1), C_l_b(2, 2));
  return {roll, pitch, yaw};
}

Odometry toOdometry(const OdometryInput& in, WorldConvention world, const Eigen::Matrix3d& C_b_c) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Odometry out;
  out.time_usec = in.time_ns > 0 ? static_cast<std::uint64_t>(in.time_ns / 1000) : 0;
  out.frame_id = world == WorldConvention::kEnu ? kMavFrameLocalNed : kMavFrameLocalFrd;
  out.child_frame_id = kMavFrameBodyFrd;
  out.estimator_type = kMavEstimatorVision;
  out.reset_counter = in.reset_counter;
  out.quality = static_cast<std::int8_t>(std::clamp(in.quality_percent, -1, 100));
  out.velocity_covariance.fill(0.0f);
  out.velocity_covariance[0] = toFloat(nan);  // the estimator gives no velocity covariance

  if (!allFinite(in.T_w_c) || !C_b_c.allFinite()) {
    // Nothing trustworthy to send: identity at the origin, marked failed.
    out.quality = -1;
    out.vx = out.vy = out.vz = toFloat(nan);
    out.rollspeed = out.pitchspeed = out.yawspeed = toFloat(nan);
    out.pose_covariance.fill(0.0f);
    out.pose_covariance[0] = toFloat(nan);
    return out;
  }

  const Eigen::Matrix3d C_l_w = worldToLocal(world, C_b_c);
  const Eigen::Matrix3d C_w_c = in.T_w_c.linear();
  const Eigen::Matrix3d C_l_b = C_l_w * C_w_c * C_b_c.transpose();
  const Eigen::Vector3d p_l = C_l_w * in.T_w_c.translation();
  out.x = toFloat(p_l.x());
  out.y = toFloat(p_l.y());
  out.z = toFloat(p_l.z());
  Eigen::Quaterniond q_l_b(C_l_b);
  q_l_b.normalize();
  if (q_l_b.w() < 0.0) q_l_b.coeffs() = -q_l_b.coeffs();  // one of the two signs: w >= 0
  out.q = {toFloat(q_l_b.w()), toFloat(q_l_b.x()), toFloat(q_l_b.y()), toFloat(q_l_b.z())};

  // Velocity in body FRD: v_b = C_b_w v_w = C_b_c C_c_w v_w. NaN input stays NaN (= unknown).
  const Eigen::Vector3d v_b = in.v_w.allFinite()
                                  ? Eigen::Vector3d(C_b_c * C_w_c.transpose() * in.v_w)
                                  : Eigen::Vector3d::Constant(nan);
  out.vx = toFloat(v_b.x());
  out.vy = toFloat(v_b.y());
  out.vz = toFloat(v_b.z());
  const Eigen::Vector3d omega_b =
      in.omega_c.allFinite() ? Eigen::Vector3d(C_b_c * in.omega_c) : Eigen::Vector3d::Constant(nan);
  out.rollspeed = toFloat(omega_b.x());
  out.pitchspeed = toFloat(omega_b.y());
  out.yawspeed = toFloat(omega_b.z());

  out.pose_covariance.fill(0.0f);
  if (!in.cov_pose.allFinite()) {
    out.pose_covariance[0] = toFloat(nan);
    return out;
  }
  // Rotation error. C_l_b = C_l_w Exp(dtheta_w) C_w_c C_c_b = Exp(C_l_w dtheta_w) C_l_b, so the
  // local-frame perturbation is dtheta_l = C_l_w dtheta_w. For C = Rz(y) Ry(p) Rx(r) the angular
  // increment in l is dtheta_l = M [dr, dp, dy] with the columns
  //   M_r = Rz(y) Ry(p) e_x = (cy cp, sy cp, -sp), M_p = Rz(y) e_y = (-sy, cy, 0), M_y = e_z,
  // so d(r, p, y) = M^-1 C_l_w dtheta_w. M is singular at pitch = +-90 deg (gimbal lock); cos(p)
  // is kept >= 1e-6 in magnitude so the covariance stays finite there (and huge, as it should).
  const Eigen::Vector3d rpy = rollPitchYaw(C_l_b);
  const double cp_raw = std::cos(rpy.y());
  const double cp = std::abs(cp_raw) < 1e-6 ? std::copysign(1e-6, cp_raw) : cp_raw;
  const double sp = std::sin(rpy.y()), cy = std::cos(rpy.z()), sy = std::sin(rpy.z());
  Eigen::Matrix3d M;
  M << cy * cp, -sy, 0,  //
      sy * cp, cy, 0,    //
      -sp, 0, 1;
  // Output states (x, y, z, roll, pitch, yaw) from input states (dtheta_w, dp_w).
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  A.block<3, 3>(0, 3) = C_l_w;
  A.block<3, 3>(3, 0) = M.inverse() * C_l_w;
  const Eigen::Matrix<double, 6, 6> cov_out = A * in.cov_pose * A.transpose();
  std::size_t k = 0;
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) out.pose_covariance[k++] = toFloat(cov_out(r, c));
  }
  return out;
}

void applyProfile(FrameProfile profile, Odometry* odo) {
  odo->child_frame_id = kMavFrameBodyFrd;
  if (profile == FrameProfile::kArduPilot) odo->frame_id = kMavFrameLocalFrd;
}

}  // namespace sunvo::mavlink
