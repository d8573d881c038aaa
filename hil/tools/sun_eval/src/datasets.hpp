#pragma once
// The image sets sunvo_sun_eval reads, each frame with its true sun and "up" in camera 0, through
// the dataset seam (drivers/dataset): a sunvo render, a KITTI raw drive (the true sun from the SPA
// at each OXTS fix: give the recording's UTC offset), or a KITTI odometry folder with a sun file.
// The colour camera 2 (same centre and rectified frame as camera 0) when the set has it, else the
// gray camera 0. "Up" in the camera is C_c_w up_w: exact for ENU worlds; for KITTI odometry poses,
// which carry no gravity, up_w is the first camera's -y (KITTI's rig is mounted level to about a
// degree), which the set records in `level_assumed`.
//
// A set is named on the command line as DIR or DIR:CSV, CSV being a frame,sx,sy,sz file of the
// true sun in camera 0 that replaces the one the dataset would find (DIR/sun_cam.csv,
// DIR/../<NN>_sun_cam.csv, a render's gt/sun_cam0.csv).

#include <Eigen/Core>
#include <optional>
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
  bool color = false;  // colour camera 2 (else gray camera 0)
};

struct SetSpec {
  std::string dir;
  std::string sun_csv;  // "" = the dataset's own
};

// "DIR" or "DIR:CSV" (split at the last ':' unless the whole text is an existing path).
SetSpec parseSetSpec(const std::string& text);

enum class CameraChoice {
  kAuto,   // colour camera 2 when the set has it, else gray camera 0
  kColor,  // camera 2; a set without it is an error
  kGray,   // camera 0, also where the set has colour (e.g. for a gray model on a render)
};

struct EvalSetOptions {
  int max_frames = 0;  // > 0: only the first max_frames frames (all when there are fewer)
  std::optional<std::int64_t> utc_offset_s;  // see dataset::DatasetOptions
  std::string sun_csv;                       // see SetSpec
  CameraChoice camera = CameraChoice::kAuto;
};

Expected<EvalDataset> loadEvalDataset(const std::string& dir, const EvalSetOptions& options = {});

}  // namespace sunvo::suneval
