#include "sunvo/geodesy/local_enu.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <random>

#include "sunvo/core/geometry.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/oxts.hpp"

namespace sunvo::geodesy {
namespace {

constexpr double kDeg = M_PI / 180.0;
const GeodeticPoint kKarlsruhe{49.015003823272, 8.4342971002335, 116.43032836914};

TEST(LocalEnu, OriginMapsToZero) {
  auto w = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(w);
  auto p = w->toEnu(kKarlsruhe);
  ASSERT_TRUE(p);
  EXPECT_LT(p->norm(), 1e-9);
}

TEST(LocalEnu, NorthOffsetMatchesGeodesicDistance) {
  // Independent reference: the geodesic distance on the WGS84 ellipsoid along the meridian.
  // At height h above the ellipsoid a short arc is longer by the factor (M + h) / M (M = meridian
  // radius of curvature, ~6.37e6 m here): 1.8e-5 relative for KITTI's 116 m, so test on the
  // ellipsoid (h = 0) and at the real height with that factor.
  for (const double h : {0.0, kKarlsruhe.alt_m}) {
    const GeodeticPoint origin{kKarlsruhe.lat_deg, kKarlsruhe.lon_deg, h};
    auto w = LocalEnuFrame::create(origin);
    ASSERT_TRUE(w);
    const GeodeticPoint north{origin.lat_deg + 0.001, origin.lon_deg, h};
    auto p = w->toEnu(north);
    ASSERT_TRUE(p);
    double s12 = 0.0;
    GeographicLib::Geodesic::WGS84().Inverse(origin.lat_deg, origin.lon_deg, north.lat_deg,
                                             north.lon_deg, s12);
    EXPECT_NEAR(s12, 111.2, 0.1);
    // The tangent-plane chord and the arc differ by ~ s^2 / (24 R^2) ~ 1e-11 relative; the point
    // sits ~ s^2 / (2 R) ~ 1 mm below the tangent plane.
    EXPECT_NEAR(p->y() / s12, 1.0 + h / 6.37e6, 1e-6) << "h = " << h;
    EXPECT_NEAR(p->x(), 0.0, 1e-6);
    EXPECT_NEAR(p->z(), -s12 * s12 / (2.0 * 6.371e6), 2e-4);
  }
}

TEST(LocalEnu, GeodeticRoundTrip) {
  auto w = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(w);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> horiz(-20000.0, 20000.0), up(-200.0, 500.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d p_w(horiz(rng), horiz(rng), up(rng));
    auto g = w->toGeodetic(p_w);
    ASSERT_TRUE(g);
    auto back = w->toEnu(*g);
    ASSERT_TRUE(back);
    EXPECT_LT((*back - p_w).norm(), 1e-6);
  }
  EXPECT_FALSE(w->toGeodetic(Eigen::Vector3d(NAN, 0, 0)));
}

TEST(LocalEnu, RejectsBadPoints) {
  auto w = LocalEnuFrame::create({91.0, 0.0, 0.0});
  ASSERT_FALSE(w);
  EXPECT_NE(w.status().message().find("lat_deg"), std::string::npos);
  auto ok = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(ok);
  EXPECT_FALSE(ok->toEnu({0.0, NAN, 0.0}));
  EXPECT_FALSE(imuPoseInWorld(*ok, kKarlsruhe, 0.0, NAN, 0.0));
}

TEST(ImuPose, LevelAndEastIsIdentityAtTheOrigin) {
  auto w = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(w);
  auto T = imuPoseInWorld(*w, kKarlsruhe, 0.0, 0.0, 0.0);
  ASSERT_TRUE(T);
  EXPECT_LT((T->linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(T->translation().norm(), 1e-9);
}

TEST(ImuPose, KittiSignConventions) {
  auto w = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(w);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  // yaw = 90 deg (counter-clockwise from east): IMU x points north.
  auto T = imuPoseInWorld(*w, kKarlsruhe, 0.0, 0.0, 90.0 * kDeg);
  ASSERT_TRUE(T);
  EXPECT_LT((T->linear() * x - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
  EXPECT_LT((T->linear() * y - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-12);  // left = west
  // pitch > 0 = front down.
  T = imuPoseInWorld(*w, kKarlsruhe, 0.0, 10.0 * kDeg, 0.0);
  ASSERT_TRUE(T);
  EXPECT_NEAR((T->linear() * x).z(), -std::sin(10.0 * kDeg), 1e-12);
  // roll > 0 = left side up.
  T = imuPoseInWorld(*w, kKarlsruhe, 10.0 * kDeg, 0.0, 0.0);
  ASSERT_TRUE(T);
  EXPECT_NEAR((T->linear() * y).z(), std::sin(10.0 * kDeg), 1e-12);
}

TEST(ImuPose, LevelFrameTiltsWithEarthCurvatureAwayFromTheOrigin) {
  auto w = LocalEnuFrame::create(kKarlsruhe);
  ASSERT_TRUE(w);
  // 0.01 deg north (~1.11 km): "up" there leans north by ~ s / R in w.
  const GeodeticPoint far{kKarlsruhe.lat_deg + 0.01, kKarlsruhe.lon_deg, kKarlsruhe.alt_m};
  auto T = imuPoseInWorld(*w, far, 0.0, 0.0, 0.0);
  ASSERT_TRUE(T);
  const double s = T->translation().y();
  const double tilt = rotationAngle(T->linear());
  EXPECT_NEAR(tilt, s / 6.37e6, 0.01 * s / 6.37e6);  // within 1 % (radius of curvature varies)
  EXPECT_GT((T->linear() * Eigen::Vector3d::UnitZ()).y(), 0.0);  // leans north
}

// The real OXTS record of 2011_09_26_drive_0001 through the real calibration chain.
TEST(CameraPose, RealSampleCameraLooksAlongTheImuHeading) {
  const std::string day = std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26";
  auto calib = kitti::readRawCalibration(day);
  ASSERT_TRUE(calib) << calib.status().toString();
  auto rec = kitti::readOxtsRecord(kitti::oxtsRecordPath(day + "/2011_09_26_drive_0001_sync", 0));
  ASSERT_TRUE(rec) << rec.status().toString();
  const GeodeticPoint fix{rec->lat, rec->lon, rec->alt};
  auto w = LocalEnuFrame::create(fix);
  ASSERT_TRUE(w);
  auto T_w_imu = imuPoseInWorld(*w, fix, rec->roll, rec->pitch, rec->yaw);
  ASSERT_TRUE(T_w_imu);
  const Isometry3 T_cam0rect_imu =
      cam0RectFromImu(calib->cam_to_cam.cameras[0].R_rect, calib->velo_to_cam.transform(),
                      calib->imu_to_velo.transform());
  const Isometry3 T_w_cam0 = cam0PoseInWorld(*T_w_imu, T_cam0rect_imu);
  EXPECT_LT(((T_w_cam0 * T_cam0rect_imu).matrix() - T_w_imu->matrix()).cwiseAbs().maxCoeff(), 1e-9);

  // The camera sits ~1.1 m forward-ish and ~0.7 m up of the IMU (KITTI's rig): |t| in [0.5, 2] m.
  const double lever = (T_w_cam0.translation() - T_w_imu->translation()).norm();
  EXPECT_GT(lever, 0.5);
  EXPECT_LT(lever, 2.0);

  // Calibration angles: camera z vs IMU x, camera x vs -IMU y, camera y vs -IMU z. The
  // calibration's rotations (R_rect_00, velo->cam, imu->velo) are each within ~1 deg of the
  // axis permutation, so each pair must agree within 2 deg.
  const Eigen::Matrix3d C_w_cam0 = T_w_cam0.linear();
  const Eigen::Matrix3d C_w_imu = T_w_imu->linear();
  const double fwd = angleBetween(C_w_cam0.col(2), C_w_imu.col(0));
  const double right = angleBetween(C_w_cam0.col(0), -C_w_imu.col(1));
  const double down = angleBetween(C_w_cam0.col(1), -C_w_imu.col(2));
  std::printf("camera z vs IMU x: %.4f deg, x vs -y: %.4f deg, y vs -z: %.4f deg\n", fwd / kDeg,
              right / kDeg, down / kDeg);
  EXPECT_LT(fwd, 2.0 * kDeg);
  EXPECT_LT(right, 2.0 * kDeg);
  EXPECT_LT(down, 2.0 * kDeg);
  // Horizontal-ish: camera z elevation within |pitch| + |roll| + 2 deg of level.
  const double elevation = std::asin(C_w_cam0.col(2).z());
  std::printf("camera z elevation: %.4f deg (pitch %.4f deg, roll %.4f deg)\n", elevation / kDeg,
              rec->pitch / kDeg, rec->roll / kDeg);
  EXPECT_LT(std::abs(elevation), std::abs(rec->pitch) + std::abs(rec->roll) + 2.0 * kDeg);
  // Heading of the camera's forward axis in the EN plane vs the OXTS yaw (east = 0, CCW).
  const double cam_yaw = std::atan2(C_w_cam0.col(2).y(), C_w_cam0.col(2).x());
  const double dyaw = std::remainder(cam_yaw - rec->yaw, 2.0 * M_PI);
  std::printf("camera heading - OXTS yaw: %.4f deg\n", dyaw / kDeg);
  EXPECT_LT(std::abs(dyaw), 2.0 * kDeg);
}

}  // namespace
}  // namespace sunvo::geodesy
