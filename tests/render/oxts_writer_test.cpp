#include "sunvo/render/oxts_writer.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/oxts.hpp"
#include "sunvo/render/drive.hpp"
#include "sunvo/render/scene.hpp"

namespace sunvo::render {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A rendered route's vehicle states -> OXTS records written to files -> read back -> through the
// KITTI calibration chain written by the renderer -> camera-0 poses, compared with the truth.
TEST(OxtsWriter, RenderedRouteRoundTripsThroughFilesAndCalibration) {
  const City city = generateCity(CityOptions{}, 3);
  auto route = generateRoute(city, RouteOptions{}, 300, 3);
  ASSERT_TRUE(route) << route.status().toString();
  Isometry3 T_b_imu = Isometry3::Identity();
  T_b_imu.translation() = Eigen::Vector3d(0, 0, 0.93);
  std::vector<Isometry3> T_enu_imu;
  std::vector<Eigen::Vector3d> v_enu;
  for (const VehicleState& vs : *route) {
    T_enu_imu.push_back(vs.T_enu_b * T_b_imu);
    v_enu.push_back(vs.v_enu);
  }
  const geodesy::GeodeticPoint origin{49.011, 8.4167, 115.0};  // Karlsruhe
  auto records = oxtsFromEnuPoses(origin, T_enu_imu, v_enu, 0.1);
  ASSERT_TRUE(records) << records.status().toString();

  const auto dir = std::filesystem::temp_directory_path() / "sunvo_oxts_roundtrip";
  std::filesystem::create_directories(dir / "drive");
  ASSERT_TRUE(writeKittiCalibration(dir.string(), Scenario{}.camera, CalibErrorOptions{}).isOk());
  auto calib = kitti::readRawCalibration(dir.string());
  ASSERT_TRUE(calib) << calib.status().toString();
  const Isometry3 T_c0rect_imu =
      geodesy::cam0RectFromImu(calib->cam_to_cam.cameras[0].R_rect, calib->velo_to_cam.transform(),
                               calib->imu_to_velo.transform());
  auto world = geodesy::LocalEnuFrame::create(origin);
  ASSERT_TRUE(world);
  double max_pos = 0.0, max_rot = 0.0;
  for (std::size_t k = 0; k < records->size(); ++k) {
    const std::string path = (dir / "drive" / "oxts.txt").string();
    ASSERT_TRUE(kitti::writeOxtsRecord(path, (*records)[k]).isOk());
    auto back = kitti::readOxtsRecord(path);
    ASSERT_TRUE(back) << back.status().toString();
    auto T_w_imu = geodesy::imuPoseInWorld(*world, {back->lat, back->lon, back->alt}, back->roll,
                                           back->pitch, back->yaw);
    ASSERT_TRUE(T_w_imu);
    const Isometry3 T_w_c0 = geodesy::cam0PoseInWorld(*T_w_imu, T_c0rect_imu);
    const Isometry3 T_w_c0_true = (*route)[k].T_enu_b * bodyFromCamera0();
    max_pos = std::max(max_pos, (T_w_c0.translation() - T_w_c0_true.translation()).norm());
    max_rot = std::max(max_rot, rotationAngle(T_w_c0.linear() * T_w_c0_true.linear().transpose()));
  }
  EXPECT_LT(max_pos, 0.001);         // < 1 mm
  EXPECT_LT(max_rot, 0.001 * kDeg);  // < 0.001 deg
  std::printf(
      "OXTS round trip over %zu frames: max position error %.3g m, max rotation error %.3g deg\n",
      records->size(), max_pos, max_rot / kDeg);
  std::filesystem::remove_all(dir);
}

TEST(OxtsWriter, KinematicFieldsAreConsistent) {
  // Straight drive north at 10 m/s, level: heading velocity 10 forward, specific force = gravity.
  std::vector<Isometry3> T;
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k < 10; ++k) {
    Isometry3 P = Isometry3::Identity();
    P.linear() =
        Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // x north
    P.translation() = Eigen::Vector3d(0, 1.0 * k, 0);
    T.push_back(P);
    v.emplace_back(0, 10.0, 0);
  }
  auto r = oxtsFromEnuPoses({49.0, 8.4, 100.0}, T, v, 0.1);
  ASSERT_TRUE(r);
  const kitti::OxtsRecord& m = (*r)[5];
  EXPECT_NEAR(m.yaw, M_PI / 2, 1e-4);  // meridian convergence near the origin is tiny
  EXPECT_NEAR(m.vf, 10.0, 1e-3);
  EXPECT_NEAR(m.vl, 0.0, 1e-3);
  EXPECT_NEAR(m.vn, 10.0, 1e-3);
  // A straight line in the flat ENU frame curves against the earth: v^2 / R = 1.57e-5 m/s^2.
  EXPECT_NEAR(m.az, 9.81, 1e-4);
  // The local level 5 m north of the origin is tilted by the earth curvature (7.8e-7 rad), so a
  // little of gravity shows up along x: 7.7e-6 m/s^2.
  EXPECT_NEAR(m.ax, 0.0, 1e-5);
  EXPECT_NEAR(m.wz, 0.0, 1e-9);
  EXPECT_EQ(m.navstat, 4);
  EXPECT_FALSE(oxtsFromEnuPoses({49.0, 8.4, 100.0}, T, {}, 0.1));
}

}  // namespace
}  // namespace sunvo::render
