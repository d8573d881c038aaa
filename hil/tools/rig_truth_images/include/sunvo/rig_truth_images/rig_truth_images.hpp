#pragma once
// A rendered drive's right images with its injected rig error taken out (issue 15): the image
// counterpart of scripts/rig_truth_tracks.py, an oracle for diagnosis. The renderer turns the
// right camera by T_c1nom_c1 = Rz(roll) Rx(pitch) Ry(yaw) (gt/rig_error.csv, degrees per frame;
// hil/tools/render/src/drive.cpp). A direction r in the turned camera is R r in the nominal one,
// so the nominal camera's image is
//   I_nom(p) = I_turned(K R^T K^-1 p)        (K the rectified right camera, p in pixels),
// a homography of the turned image (bicubic). What it leaves is what the renderer draws
// differently for a turned camera (antialiasing, sampling), not the rig.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::rigtruth {

struct RigTurn {
  int frame = 0;
  double roll_deg = 0.0;   // about the optical axis (z)
  double pitch_deg = 0.0;  // about x
  double yaw_deg = 0.0;    // about y
};

// Which angles to take out (the others stay in the images).
struct Axes {
  bool roll = true;
  bool pitch = true;
  bool yaw = true;
};

// gt/rig_error.csv: header, then frame,right_roll_deg,right_pitch_deg,right_yaw_deg per line.
// A malformed line names the file and line.
Expected<std::vector<RigTurn>> readRigError(const std::string& path);

// R_c1nom_c1 = Rz(roll) Rx(pitch) Ry(yaw) of the chosen axes.
Eigen::Matrix3d rightCameraTurn(const RigTurn& turn, const Axes& axes);

// The nominal camera's image from the turned one (see above); same size and type.
void warpToNominal(const cv::Mat& turned, const StereoCamera& camera,
                   const Eigen::Matrix3d& R_c1nom_c1, cv::Mat& nominal);

// Writes OUT: the drive (a sunvo_render output) with the right images (image_01, and image_03
// when present) of every frame taken back to the nominal camera; every other file is a symbolic
// link to the drive's, except gt/rig_error.csv, rewritten with the taken-out angles at 0.
// `frames` gets the number of frames written.
Status writeNominalDrive(const std::string& drive, const std::string& out, const Axes& axes,
                         int* frames);

}  // namespace sunvo::rigtruth
