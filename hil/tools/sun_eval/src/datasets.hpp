#pragma once
// The image sets sunvo_sun_eval reads, each frame with its true sun and "up" in camera 0.
//
// Two layouts, detected from the folder:
//  - a drive rendered by sunvo_render (DIR/<date>/<date>_drive_<n>_sync/...): colour camera 2
//    images (same centre and rectified frame as camera 0), intrinsics from P_rect_02 of
//    calib_cam_to_cam.txt, the sun from gt/sun_cam0.csv and "up" from gt/poses_cam0_enu.txt
//    (up_c = C_c_enu (0, 0, 1));
//  - a KITTI odometry folder (DIR/image_0, DIR/calib.txt): camera 2 when DIR/image_2 exists,
//    else the gray camera 0; the sun from DIR/sun_cam.csv or DIR/../<prefix>_sun_cam.csv (prefix
//    = the folder name up to its first '_', e.g. 00_first_frames -> 00_sun_cam.csv). KITTI
//    odometry poses carry no gravity: up_c is taken as the camera's -y (KITTI's rig is mounted
//    level to about a degree), which the dataset records in `level_assumed`.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::suneval {

struct EvalFrame {
  std::string image_path;
  Eigen::Vector3d true_sun_c = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d true_up_c = -Eigen::Vector3d::UnitY();
};

struct EvalDataset {
  std::string name;  // the folder's name
  StereoCamera camera;
  std::vector<EvalFrame> frames;
  bool level_assumed = false;
};

// max_frames > 0 keeps only the first max_frames frames.
Expected<EvalDataset> loadEvalDataset(const std::string& dir, int max_frames);

}  // namespace sunvo::suneval
