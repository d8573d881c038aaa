#pragma once
// KITTI calibration files, raw and odometry layouts.
//
// Raw layout (one folder per recording day, e.g. 2011_09_26/):
//   calib_cam_to_cam.txt  calib_time, corner_dist, and for cameras 00..03 the keys
//                         S_xx (2), K_xx (9), D_xx (5), R_xx (9), T_xx (3), S_rect_xx (2),
//                         R_rect_xx (9), P_rect_xx (12), all row-major.
//   calib_imu_to_velo.txt R (9), T (3): p_velo = R p_imu + T   (T_velo_imu)
//   calib_velo_to_cam.txt R (9), T (3): p_cam0 = R p_velo + T  (T_cam0_velo, unrectified cam0)
// Odometry layout (one file per sequence): calib.txt with P0..P3 (12 each, rectified projection
// matrices of cameras 0..3) and an optional Tr (12: velodyne -> rectified camera 0).
//
// Frames: camera x right, y down, z forward. R_rect_00 rotates unrectified cam0 into the rectified
// cam0 frame (the frame of the rectified images and of P_rect_xx, which all share it).
// Every parse error names the file, the line and the key ("calib_cam_to_cam.txt:9: field
// 'P_rect_00': expected 12 values, found 11").

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::kitti {

using Matrix34 = Eigen::Matrix<double, 3, 4>;

// One camera of calib_cam_to_cam.txt.
struct RawCameraCalibration {
  Eigen::Vector2d S = Eigen::Vector2d::Zero();  // px, unrectified size (width, height)
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  // unrectified intrinsics
  Eigen::Matrix<double, 5, 1> D = Eigen::Matrix<double, 5, 1>::Zero();  // distortion k1 k2 p1 p2 k3
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();       // rotation cam00 -> this camera
  Eigen::Vector3d T = Eigen::Vector3d::Zero();           // m, translation cam00 -> this camera
  Eigen::Vector2d S_rect = Eigen::Vector2d::Zero();      // px, rectified size (width, height)
  Eigen::Matrix3d R_rect = Eigen::Matrix3d::Identity();  // rectifying rotation
  Matrix34 P_rect = Matrix34::Zero();                    // rectified projection, cam0rect -> px
};

struct CamToCamCalibration {
  std::string calib_time;    // as written, e.g. "09-Jan-2012 13:57:47" (no zone; informative only)
  double corner_dist = 0.0;  // m, checkerboard corner distance used for calibration
  std::array<RawCameraCalibration, 4> cameras;  // index 0..3 = camera 00..03
};

// A rigid transform file (calib_imu_to_velo.txt, calib_velo_to_cam.txt): p_to = R p_from + T.
struct RigidCalibration {
  std::string calib_time;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d T = Eigen::Vector3d::Zero();  // m
  // [R | T] as an isometry, R re-orthonormalised (the files keep 7 significant digits).
  Isometry3 transform() const;
};

// All three files of a raw recording day.
struct RawCalibration {
  CamToCamCalibration cam_to_cam;
  RigidCalibration imu_to_velo;  // T_velo_imu
  RigidCalibration velo_to_cam;  // T_cam0_velo (unrectified camera 0)
};

Expected<CamToCamCalibration> readCamToCam(const std::string& path);
Expected<RigidCalibration> readRigidCalibration(const std::string& path);
// Reads calib_cam_to_cam.txt, calib_imu_to_velo.txt and calib_velo_to_cam.txt from `dir`.
Expected<RawCalibration> readRawCalibration(const std::string& dir);

// The rectified stereo pair (left, right) = (0, 1) for the gray pair or (2, 3) for the colour pair.
// fu, fv, cu, cv from P_rect_left; baseline b = (P_rect_left(0,3) - P_rect_right(0,3)) / fu, which
// is -P_rect_01(0,3) / P_rect_01(0,0) for the gray pair (P_rect_00(0,3) = 0). Width and height
// from S_rect_left. Fails if the two projections disagree on the intrinsics (not a rectified pair).
Expected<StereoCamera> rawStereoCamera(const CamToCamCalibration& calib, int left, int right);

struct OdometryCalibration {
  std::array<Matrix34, 4> P{Matrix34::Zero(), Matrix34::Zero(), Matrix34::Zero(),
                            Matrix34::Zero()};  // P0..P3, rectified cam0 -> px of camera i
  std::optional<Isometry3> T_cam0_velo;         // from Tr when present
};

Expected<OdometryCalibration> readOdometryCalibration(const std::string& path);

// The rectified pair (left, right) of an odometry calib.txt; the file carries no image size, so
// width and height come from the caller (the first image of the sequence).
Expected<StereoCamera> odometryStereoCamera(const OdometryCalibration& calib, int left, int right,
                                            int width, int height);

}  // namespace sunvo::kitti
