#pragma once
// OXTS records (KITTI raw, 30 fields) from IMU poses in a local ENU frame.
//
// Position: the IMU origin, ENU -> WGS84 through GeographicLib (LocalEnuFrame::toGeodetic).
// Attitude: roll, pitch, yaw of the IMU relative to the local level frame at the fix (not the
// origin's ENU axes: they differ by the meridian convergence), decomposed as KITTI defines it,
// C_lev_imu = Rz(yaw) Ry(pitch) Rx(roll) with IMU axes x forward, y left, z up; yaw 0 = east,
// positive pitch = front down.
// Velocity: vn, ve, vu from the ENU velocity; vf, vl from it in the heading frame.
// Acceleration (specific force, gravity 9.81 m/s^2 included as an accelerometer reports it) and
// angular rate: central differences of the velocity and the attitude (one-sided at the ends),
// in the IMU frame (ax ay az, wx wy wz) and in the heading-level frame (af al au, wf wl wu).
// Status fields are those of a good RTK fix (navstat 4, 10 satellites, modes 4, 2 cm / 2 cm/s).

#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/kitti/oxts.hpp"

namespace sunvo::render {

Expected<std::vector<kitti::OxtsRecord>> oxtsFromEnuPoses(const geodesy::GeodeticPoint& origin,
                                                          const std::vector<Isometry3>& T_enu_imu,
                                                          const std::vector<Eigen::Vector3d>& v_enu,
                                                          double dt_s);

}  // namespace sunvo::render
