#include "sunvo/kitti/calibration.hpp"

#include <gtest/gtest.h>

#include <string>

#include "../support/temp_dir.hpp"

namespace sunvo::kitti {
namespace {

const std::string kRawDay = std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26";
const std::string kOdometry = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";

TEST(KittiCalibration, RealCamToCamValues) {
  auto c = readCamToCam(kRawDay + "/calib_cam_to_cam.txt");
  ASSERT_TRUE(c) << c.status().toString();
  EXPECT_EQ(c->calib_time, "09-Jan-2012 13:57:47");
  EXPECT_DOUBLE_EQ(c->corner_dist, 0.0995);
  const RawCameraCalibration& c0 = c->cameras[0];
  EXPECT_DOUBLE_EQ(c0.S.x(), 1392.0);
  EXPECT_DOUBLE_EQ(c0.K(0, 0), 984.2439);
  EXPECT_DOUBLE_EQ(c0.K(1, 2), 233.1966);
  EXPECT_DOUBLE_EQ(c0.D(4), -0.07233722);
  EXPECT_DOUBLE_EQ(c0.S_rect.y(), 375.0);
  EXPECT_DOUBLE_EQ(c0.R_rect(0, 1), 0.00983776);  // row-major: second value of the line
  EXPECT_DOUBLE_EQ(c0.R_rect(1, 0), -0.009869795);
  EXPECT_DOUBLE_EQ(c0.P_rect(0, 0), 721.5377);
  EXPECT_DOUBLE_EQ(c->cameras[1].T.x(), -0.537);
  EXPECT_DOUBLE_EQ(c->cameras[1].P_rect(0, 3), -387.5744);
  EXPECT_DOUBLE_EQ(c->cameras[3].P_rect(1, 3), 2.199936);
}

TEST(KittiCalibration, RawGrayAndColourStereoCameras) {
  auto c = readCamToCam(kRawDay + "/calib_cam_to_cam.txt");
  ASSERT_TRUE(c);
  auto gray = rawStereoCamera(*c, 0, 1);
  ASSERT_TRUE(gray) << gray.status().toString();
  EXPECT_DOUBLE_EQ(gray->fu, 721.5377);
  EXPECT_DOUBLE_EQ(gray->fv, 721.5377);
  EXPECT_DOUBLE_EQ(gray->cu, 609.5593);
  EXPECT_DOUBLE_EQ(gray->cv, 172.854);
  EXPECT_NEAR(gray->baseline_m, 387.5744 / 721.5377, 1e-12);
  EXPECT_NEAR(gray->baseline_m, 0.5372, 1e-4);
  EXPECT_EQ(gray->width, 1242);
  EXPECT_EQ(gray->height, 375);
  auto colour = rawStereoCamera(*c, 2, 3);
  ASSERT_TRUE(colour) << colour.status().toString();
  EXPECT_NEAR(colour->baseline_m, (44.85728 + 339.5242) / 721.5377, 1e-12);  // 0.5327 m
  EXPECT_FALSE(rawStereoCamera(*c, 0, 0));
  EXPECT_FALSE(rawStereoCamera(*c, 0, 4));
}

TEST(KittiCalibration, RealRigidTransforms) {
  auto all = readRawCalibration(kRawDay);
  ASSERT_TRUE(all) << all.status().toString();
  EXPECT_EQ(all->imu_to_velo.calib_time, "25-May-2012 16:47:16");
  EXPECT_DOUBLE_EQ(all->imu_to_velo.R(0, 0), 0.9999976);
  EXPECT_DOUBLE_EQ(all->imu_to_velo.T.z(), -0.7997231);
  EXPECT_DOUBLE_EQ(all->velo_to_cam.R(0, 1), -0.9999714);
  EXPECT_DOUBLE_EQ(all->velo_to_cam.T.y(), -0.07631618);
  const Isometry3 T = all->velo_to_cam.transform();
  EXPECT_NEAR((T.linear() * T.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0,
              1e-12);
  EXPECT_NEAR((T.linear() - all->velo_to_cam.R).cwiseAbs().maxCoeff(), 0.0, 1e-5);
}

TEST(KittiCalibration, OdometryCalibAndCamera) {
  auto c = readOdometryCalibration(kOdometry + "/calib.txt");
  ASSERT_TRUE(c) << c.status().toString();
  EXPECT_FALSE(c->T_cam0_velo.has_value());
  EXPECT_DOUBLE_EQ(c->P[2](2, 3), 0.003779761);
  auto cam = odometryStereoCamera(*c, 0, 1, 1241, 376);
  ASSERT_TRUE(cam) << cam.status().toString();
  EXPECT_DOUBLE_EQ(cam->fu, 718.856);
  EXPECT_DOUBLE_EQ(cam->cv, 185.2157);
  EXPECT_NEAR(cam->baseline_m, 386.1448 / 718.856, 1e-12);
  EXPECT_FALSE(odometryStereoCamera(*c, 0, 1, 0, 376));
}

TEST(KittiCalibration, OdometryTrIsOptionalAndParsed) {
  testing::TempDir dir;
  std::string text = testing::readText(kOdometry + "/calib.txt");
  text += "Tr: 0 -1 0 0.1 0 0 -1 0.2 1 0 0 0.3\n";
  testing::writeText(dir.file("calib.txt"), text);
  auto c = readOdometryCalibration(dir.file("calib.txt"));
  ASSERT_TRUE(c) << c.status().toString();
  ASSERT_TRUE(c->T_cam0_velo.has_value());
  const Eigen::Vector3d p_cam = *c->T_cam0_velo * Eigen::Vector3d(1.0, 0.0, 0.0);  // velo forward
  EXPECT_NEAR((p_cam - Eigen::Vector3d(0.1, 0.2, 1.3)).norm(), 0.0, 1e-12);
}

// Rewrites line `line_no` (1-based) of `text` with `f(line)`.
template <typename F>
std::string editLine(const std::string& text, int line_no, F f) {
  std::string out;
  int n = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    std::string line = text.substr(pos, end - pos);
    if (++n == line_no) line = f(line);
    out += line + "\n";
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return out;
}

TEST(KittiCalibration, MissingValueNamesFileLineAndKey) {
  testing::TempDir dir;
  const std::string text = testing::readText(kRawDay + "/calib_cam_to_cam.txt");
  // Line 10 is P_rect_00: drop its last value.
  const std::string bad = editLine(text, 10, [](std::string l) {
    EXPECT_EQ(l.rfind("P_rect_00:", 0), 0u);
    return l.substr(0, l.find_last_of(' '));
  });
  const std::string path = dir.file("calib_cam_to_cam.txt");
  testing::writeText(path, bad);
  auto c = readCamToCam(path);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.status().code(), StatusCode::kParseError);
  EXPECT_EQ(c.status().message(), path + ":10: field 'P_rect_00': expected 12 values, found 11");
}

TEST(KittiCalibration, NonNumericValueMissingKeyAndDuplicateKey) {
  testing::TempDir dir;
  const std::string path = dir.file("calib_imu_to_velo.txt");
  testing::writeText(path, "calib_time: x\nR: 1 0 0 0 1 0 0 0 1\nT: 0 abc 0\n");
  auto c = readRigidCalibration(path);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.status().message(), path + ":3: field 'T[1]': not a number: 'abc'");

  testing::writeText(path, "R: 1 0 0 0 1 0 0 0 1\n");
  c = readRigidCalibration(path);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.status().message(), path + ": missing key 'T'");

  testing::writeText(path, "R: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\nR: 1 0 0 0 1 0 0 0 1\n");
  c = readRigidCalibration(path);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.status().message(), path + ":3: field 'R': duplicate key");

  testing::writeText(path, "R: 1 0 0 0 1 0 0 0 2\nT: 0 0 0\n");
  c = readRigidCalibration(path);
  ASSERT_FALSE(c);
  EXPECT_NE(c.status().message().find("not a rotation"), std::string::npos);

  testing::writeText(path, "R 1 0 0 0 1 0 0 0 1\n");
  c = readRigidCalibration(path);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.status().message(), path + ":1: expected 'key: values'");

  EXPECT_EQ(readRigidCalibration(dir.file("absent.txt")).status().code(), StatusCode::kNotFound);
}

TEST(KittiCalibration, MismatchedIntrinsicsAreNotARectifiedPair) {
  auto c = readCamToCam(kRawDay + "/calib_cam_to_cam.txt");
  ASSERT_TRUE(c);
  c->cameras[1].P_rect(0, 0) += 1.0;
  auto cam = rawStereoCamera(*c, 0, 1);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.status().message().find("P_rect_00/P_rect_01"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::kitti
