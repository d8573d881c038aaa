#include "sunvo/render/oxts_writer.hpp"

#include <algorithm>
#include <cmath>

namespace sunvo::render {
namespace {
constexpr double kGravity = 9.81;  // m/s^2

Eigen::Matrix3d yawOnly(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}
}  // namespace

Expected<std::vector<kitti::OxtsRecord>> oxtsFromEnuPoses(const geodesy::GeodeticPoint& origin,
                                                          const std::vector<Isometry3>& T_enu_imu,
                                                          const std::vector<Eigen::Vector3d>& v_enu,
                                                          double dt_s) {
  const std::size_t n = T_enu_imu.size();
  if (n == 0 || v_enu.size() != n)
    return invalidArgument("oxts: poses and velocities differ in count");
  if (!(dt_s > 0.0)) return invalidArgument("oxts: dt_s must be > 0");
  auto world = geodesy::LocalEnuFrame::create(origin);
  if (!world) return world.status();
  std::vector<kitti::OxtsRecord> out(n);
  std::vector<Eigen::Matrix3d> C_lev_imu(n);
  for (std::size_t k = 0; k < n; ++k) {
    auto fix = world->toGeodetic(T_enu_imu[k].translation());
    if (!fix) return fix.status();
    Eigen::Matrix3d C_w_lev;
    auto p = world->toEnu(*fix, C_w_lev);
    if (!p) return p.status();
    const Eigen::Matrix3d C = C_w_lev.transpose() * T_enu_imu[k].linear();
    C_lev_imu[k] = C;
    kitti::OxtsRecord& r = out[k];
    r.lat = fix->lat_deg;
    r.lon = fix->lon_deg;
    r.alt = fix->alt_m;
    // C = Rz(yaw) Ry(pitch) Rx(roll): C(1,0)/C(0,0) = tan(yaw), C(2,0) = -sin(pitch),
    // C(2,1)/C(2,2) = tan(roll).
    r.yaw = std::atan2(C(1, 0), C(0, 0));
    r.pitch = std::asin(std::clamp(-C(2, 0), -1.0, 1.0));
    r.roll = std::atan2(C(2, 1), C(2, 2));
    const Eigen::Vector3d v_lev = C_w_lev.transpose() * v_enu[k];
    r.ve = v_lev.x();
    r.vn = v_lev.y();
    r.vu = v_lev.z();
    const Eigen::Vector3d v_heading = yawOnly(r.yaw).transpose() * v_lev;
    r.vf = v_heading.x();
    r.vl = v_heading.y();
    r.pos_accuracy = 0.02;
    r.vel_accuracy = 0.02;
    r.navstat = 4;
    r.numsats = 10;
    r.posmode = 4;
    r.velmode = 4;
    r.orimode = 4;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1;
    const std::size_t b = k + 1 < n ? k + 1 : n - 1;
    if (a == b) break;  // a single record: no differences
    const double span = static_cast<double>(b - a) * dt_s;
    kitti::OxtsRecord& r = out[k];
    // Specific force in the level frame: kinematic acceleration plus the reaction to gravity.
    const Eigen::Vector3d accel_lev =
        (out[b].ve - out[a].ve) / span * Eigen::Vector3d::UnitX() +
        (out[b].vn - out[a].vn) / span * Eigen::Vector3d::UnitY() +
        ((out[b].vu - out[a].vu) / span + kGravity) * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d f_imu = C_lev_imu[k].transpose() * accel_lev;
    const Eigen::Vector3d f_heading = yawOnly(r.yaw).transpose() * accel_lev;
    r.ax = f_imu.x();
    r.ay = f_imu.y();
    r.az = f_imu.z();
    r.af = f_heading.x();
    r.al = f_heading.y();
    r.au = f_heading.z();
    // Body rate: C_a^T C_b = Exp(w_imu * span).
    const Eigen::Vector3d w_imu = logSO3(C_lev_imu[a].transpose() * C_lev_imu[b]) / span;
    const Eigen::Vector3d w_heading = yawOnly(r.yaw).transpose() * (C_lev_imu[k] * w_imu);
    r.wx = w_imu.x();
    r.wy = w_imu.y();
    r.wz = w_imu.z();
    r.wf = w_heading.x();
    r.wl = w_heading.y();
    r.wu = w_heading.z();
  }
  return out;
}

}  // namespace sunvo::render
