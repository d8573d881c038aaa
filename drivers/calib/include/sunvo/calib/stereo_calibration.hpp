#pragma once
// The raw (unrectified) calibration of a stereo rig, read from the files that calibration tools
// write. Two formats:
//
// OpenCV stereo YAML or JSON as cv::FileStorage writes them (the layout of OpenCV's stereo_calib
// sample and of most scripts around cv::stereoCalibrate; a YAML file without the "%YAML" line is
// read too), parsed with yaml-cpp: OpenCV 4.6's own parsers loop forever or crash on damaged
// input (docs/hardening.md). An XML file is refused with a hint to write YAML.
// Matrices as !!opencv-matrix or as flat lists of numbers, row-major. Accepted keys
// (the first spelling present wins):
//   left intrinsics   K1 | M1 | cameraMatrix1 | camera_matrix_left      3x3
//   left distortion   D1 | distCoeffs1 | dist_coeffs_left               4, 5, 8, 12 or 14 values
//   right             K2 | M2 | cameraMatrix2 | camera_matrix_right, D2 | distCoeffs2 | ...right
//   extrinsics        R (3x3), T (3): p_right = R p_left + T, T in metres
//   image size        image_width + image_height | width + height | image_size | imageSize
//                     | size ([w, h]), px per eye
//   distortion_model  optional string: radtan (default; also plumb_bob, pinhole) | equidistant
//                     (also fisheye; then D has 4 values k1..k4)
//
// Kalibr camchain.yaml, read with yaml-cpp (cam0 = left, cam1 = right):
//   camN.camera_model       pinhole (the only one accepted)
//   camN.intrinsics         [fu, fv, pu, pv]
//   camN.distortion_model   radtan ([k1, k2, r1, r2]) | equidistant ([k1, k2, k3, k4])
//   camN.distortion_coeffs  as above
//   camN.resolution         [width, height]
//   cam1.T_cn_cnm1          4x4 rows: p_cam1 = T p_cam0 (metres)
//
// Frames: camera x right, y down, z forward (both files use it). The right camera's centre in
// the left frame is -R^T T; a rectifiable pair has it mostly along +x (calib::StereoRectifier).
// Every error names the file and the key ("rig.yaml: D1: expected 4, 5, 8, 12 or 14 values,
// found 3"); a YAML syntax error and every Kalibr error also name the line.

#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <string_view>

#include "sunvo/core/status.hpp"

namespace sunvo::calib {

enum class DistortionModel {
  kRadTan,       // OpenCV's pinhole model: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1..s4 [tx ty]]]]
  kEquidistant,  // OpenCV's fisheye model (Kalibr's equidistant): k1 k2 k3 k4
};

// kKitti: calib_cam_to_cam.txt of an already rectified rig (P_rect_00/01; no rectification).
enum class CalibrationFormat { kAuto, kKitti, kOpenCv, kKalibr };

std::span<const std::string_view> enumNames(DistortionModel);
std::span<const std::string_view> enumNames(CalibrationFormat);  // auto kitti opencv kalibr

struct RawStereoCalibration {
  std::string file;  // where it was read from (for messages)
  cv::Size size;     // px per eye (width, height), both cameras
  DistortionModel model = DistortionModel::kRadTan;
  cv::Matx33d K_left = cv::Matx33d::eye();   // left intrinsics (fu 0 cu; 0 fv cv; 0 0 1)
  cv::Matx33d K_right = cv::Matx33d::eye();  // right intrinsics
  cv::Mat D_left;                            // 1 x N CV_64F distortion of the left camera
  cv::Mat D_right;                           // 1 x N CV_64F distortion of the right camera
  cv::Matx33d C_r_l = cv::Matx33d::eye();    // rotation left -> right: p_r = C_r_l p_l + t_r_l
  cv::Vec3d t_r_l;                           // m, the left camera's centre in the right frame

  // Positive focal lengths, finite values, a rotation matrix, a distortion length the model
  // takes, a baseline in (1 mm, 10 m) (a larger one is most likely millimetres). Names the file.
  Status validate() const;
};

// Reads an OpenCV stereo YAML / XML file (keys above).
Expected<RawStereoCalibration> readOpenCvStereo(const std::string& path);
// Reads a Kalibr camchain.yaml (cam0, cam1).
Expected<RawStereoCalibration> readKalibrCamchain(const std::string& path);
// kAuto: a name ending in ".txt" or a "P_rect_00" in the text -> kKitti; a top-level "cam0:" with
// "intrinsics:" -> kKalibr; otherwise kOpenCv. Other formats are returned as given.
Expected<CalibrationFormat> detectFormat(const std::string& path, CalibrationFormat format);
// Reads a raw calibration in the given (or detected) format; kKitti is refused (not raw).
Expected<RawStereoCalibration> readRawStereoCalibration(const std::string& path,
                                                        CalibrationFormat format);

}  // namespace sunvo::calib
