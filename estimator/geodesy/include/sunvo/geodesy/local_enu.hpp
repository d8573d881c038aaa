#pragma once
// Geodesy: a local East-North-Up world frame and GPS/INS fixes as poses in it.
//
// Frames:
//   w     local ENU frame: origin at a geodetic point (normally the first GPS fix), x east,
//         y north, z up, tangent to the WGS84 ellipsoid at the origin (GeographicLib
//         LocalCartesian). Exact (no map projection) at any distance.
//   lev   the local-level frame at a fix: east, north, up at the fix itself. It differs from w by
//         the curvature of the earth between origin and fix (about 1.6e-4 rad per km).
//   imu   KITTI OXTS body frame: x forward, y left, z up.
//         C_lev_imu = Rz(yaw) Ry(pitch) Rx(roll), yaw 0 = east, counter-clockwise positive,
//         pitch positive = front down, roll positive = left side up (oxts/dataformat.txt).
//   cam0  the rectified left camera of KITTI: x right, y down, z forward.
// Poses: T_a_b maps points from b to a (p_a = T_a_b p_b).

#include <Eigen/Core>
#include <GeographicLib/LocalCartesian.hpp>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::geodesy {

struct GeodeticPoint {
  double lat_deg = 0.0;  // deg, [-90, 90]
  double lon_deg = 0.0;  // deg, any finite value (wrapped)
  double alt_m = 0.0;    // m above the WGS84 ellipsoid, finite
};

// Checks the ranges above; the error names the bad field ("lat_deg").
Status validate(const GeodeticPoint& p);

class LocalEnuFrame {
 public:
  static Expected<LocalEnuFrame> create(const GeodeticPoint& origin);

  const GeodeticPoint& origin() const { return origin_; }
  // p_w of a geodetic point.
  Expected<Eigen::Vector3d> toEnu(const GeodeticPoint& p) const;
  // p_w and C_w_lev, the rotation from the local-level ENU axes at p into w.
  Expected<Eigen::Vector3d> toEnu(const GeodeticPoint& p, Eigen::Matrix3d& C_w_lev) const;
  // The geodetic point at p_w (the inverse of toEnu), for writers of GPS records.
  Expected<GeodeticPoint> toGeodetic(const Eigen::Vector3d& p_w) const;

 private:
  explicit LocalEnuFrame(const GeodeticPoint& origin)
      : origin_(origin), lc_(origin.lat_deg, origin.lon_deg, origin.alt_m) {}
  GeodeticPoint origin_;
  GeographicLib::LocalCartesian lc_;
};

// C_lev_imu = Rz(yaw) Ry(pitch) Rx(roll) (angles in rad).
Eigen::Matrix3d levelFromImu(double roll_rad, double pitch_rad, double yaw_rad);

// T_w_imu of an INS fix: translation p_w of the fix, rotation C_w_lev(fix) C_lev_imu.
Expected<Isometry3> imuPoseInWorld(const LocalEnuFrame& world, const GeodeticPoint& fix,
                                   double roll_rad, double pitch_rad, double yaw_rad);

// KITTI raw chain T_cam0rect_imu = R_rect_00 (padded to 4x4) T_cam0_velo T_velo_imu.
Isometry3 cam0RectFromImu(const Eigen::Matrix3d& R_rect_00, const Isometry3& T_cam0_velo,
                          const Isometry3& T_velo_imu);

// T_w_cam0 = T_w_imu T_imu_cam0 = T_w_imu (T_cam0rect_imu)^-1.
inline Isometry3 cam0PoseInWorld(const Isometry3& T_w_imu, const Isometry3& T_cam0rect_imu) {
  return T_w_imu * T_cam0rect_imu.inverse();
}

}  // namespace sunvo::geodesy
