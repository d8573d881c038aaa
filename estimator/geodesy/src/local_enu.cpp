#include "sunvo/geodesy/local_enu.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace sunvo::geodesy {

Status validate(const GeodeticPoint& p) {
  if (!std::isfinite(p.lat_deg) || p.lat_deg < -90.0 || p.lat_deg > 90.0) {
    return invalidArgument("lat_deg: " + std::to_string(p.lat_deg) + " outside [-90, 90] deg");
  }
  if (!std::isfinite(p.lon_deg)) return invalidArgument("lon_deg: not finite");
  if (!std::isfinite(p.alt_m) || std::abs(p.alt_m) > 1e7) {
    return invalidArgument("alt_m: not finite or beyond 1e7 m");
  }
  return Status::ok();
}

Expected<LocalEnuFrame> LocalEnuFrame::create(const GeodeticPoint& origin) {
  Status s = validate(origin);
  if (!s) return invalidArgument("origin " + s.message());
  return LocalEnuFrame(origin);
}

Expected<Eigen::Vector3d> LocalEnuFrame::toEnu(const GeodeticPoint& p) const {
  Eigen::Matrix3d C_w_lev;
  return toEnu(p, C_w_lev);
}

Expected<Eigen::Vector3d> LocalEnuFrame::toEnu(const GeodeticPoint& p,
                                               Eigen::Matrix3d& C_w_lev) const {
  SUNVO_RETURN_IF_ERROR(validate(p));
  Eigen::Vector3d p_w;
  // GeographicLib: v_origin = M v_point for a vector given in the ENU axes at the point, i.e.
  // M = C_w_lev, row-major.
  std::vector<double> M(9);
  lc_.Forward(p.lat_deg, p.lon_deg, p.alt_m, p_w.x(), p_w.y(), p_w.z(), M);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) C_w_lev(r, c) = M[static_cast<std::size_t>(3 * r + c)];
  }
  return p_w;
}

Expected<GeodeticPoint> LocalEnuFrame::toGeodetic(const Eigen::Vector3d& p_w) const {
  if (!p_w.allFinite()) return invalidArgument("p_w: not finite");
  GeodeticPoint out;
  lc_.Reverse(p_w.x(), p_w.y(), p_w.z(), out.lat_deg, out.lon_deg, out.alt_m);
  return out;
}

// Rz(yaw) Ry(pitch) Rx(roll): first roll about the body x (forward) axis, then pitch about y
// (left), then yaw about z (up), each right-handed. Checks of the KITTI sign conventions:
// Ry(pitch) e_x = (cos p, 0, -sin p): positive pitch puts the front down;
// Rx(roll) e_y = (0, cos r, sin r): positive roll lifts the left side;
// Rz(yaw) e_x = (cos y, sin y, 0) in ENU: yaw 0 = east, 90 deg = north.
Eigen::Matrix3d levelFromImu(double roll_rad, double pitch_rad, double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Expected<Isometry3> imuPoseInWorld(const LocalEnuFrame& world, const GeodeticPoint& fix,
                                   double roll_rad, double pitch_rad, double yaw_rad) {
  if (!std::isfinite(roll_rad) || !std::isfinite(pitch_rad) || !std::isfinite(yaw_rad)) {
    return invalidArgument("roll/pitch/yaw: not finite");
  }
  Eigen::Matrix3d C_w_lev;
  auto p_w = world.toEnu(fix, C_w_lev);
  if (!p_w) return p_w.status();
  Isometry3 T_w_imu = Isometry3::Identity();
  T_w_imu.linear() = orthonormalize(C_w_lev * levelFromImu(roll_rad, pitch_rad, yaw_rad));
  T_w_imu.translation() = *p_w;
  return T_w_imu;
}

Isometry3 cam0RectFromImu(const Eigen::Matrix3d& R_rect_00, const Isometry3& T_cam0_velo,
                          const Isometry3& T_velo_imu) {
  // R_rect_00 padded to 4x4 = a pure rotation (unrectified cam0 -> rectified cam0); the file
  // keeps 7 digits, so re-orthonormalise it to keep the product an isometry.
  Isometry3 T_cam0rect_cam0 = Isometry3::Identity();
  T_cam0rect_cam0.linear() = orthonormalize(R_rect_00);
  return T_cam0rect_cam0 * T_cam0_velo * T_velo_imu;
}

}  // namespace sunvo::geodesy
