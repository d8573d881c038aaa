#include "datasets.hpp"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/kitti/calibration.hpp"

namespace sunvo::suneval {
namespace fs = std::filesystem;
namespace {

std::string framePng(const fs::path& dir, std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof(name), "%010zu.png", k);
  return (dir / name).string();
}

std::string odometryPng(const fs::path& dir, std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", k);
  return (dir / name).string();
}

// DIR/<date>/<date>_drive_<n>_sync with a gt/sun_cam0.csv, or empty.
fs::path findRenderedDrive(const fs::path& dir) {
  std::error_code ec;
  for (const fs::directory_entry& day : fs::directory_iterator(dir, ec)) {
    if (!day.is_directory()) continue;
    for (const fs::directory_entry& drive : fs::directory_iterator(day.path(), ec)) {
      if (drive.is_directory() && fs::exists(drive.path() / "gt" / "sun_cam0.csv")) {
        return drive.path();
      }
    }
  }
  return {};
}

Expected<EvalDataset> loadRendered(const fs::path& dir, const fs::path& drive, int max_frames) {
  EvalDataset ds;
  ds.name = dir.filename().string();
  Expected<kitti::CamToCamCalibration> calib =
      kitti::readCamToCam((drive.parent_path() / "calib_cam_to_cam.txt").string());
  if (!calib) return calib.status();
  Expected<StereoCamera> cam = kitti::rawStereoCamera(*calib, 2, 3);
  if (!cam) return cam.status();
  ds.camera = *cam;
  Expected<files::SunCsv> sun = files::readSunCsv((drive / "gt" / "sun_cam0.csv").string());
  if (!sun) return sun.status();
  Expected<files::Trajectory> poses =
      files::readKittiPoses((drive / "gt" / "poses_cam0_enu.txt").string());
  if (!poses) return poses.status();
  if (poses->size() != sun->sun_c.size()) {
    return invalidArgument((drive / "gt").string() + ": poses_cam0_enu.txt has " +
                           std::to_string(poses->size()) + " poses, sun_cam0.csv " +
                           std::to_string(sun->sun_c.size()) + " rows");
  }
  const fs::path images = drive / "image_02" / "data";
  for (std::size_t k = 0; k < sun->sun_c.size(); ++k) {
    if (max_frames > 0 && static_cast<int>(k) >= max_frames) break;
    EvalFrame f;
    f.image_path = framePng(images, k);
    f.true_sun_c = sun->sun_c[k].normalized();
    f.true_up_c = poses->T_w_c[k].rotation().transpose() * Eigen::Vector3d::UnitZ();
    ds.frames.push_back(f);
  }
  return ds;
}

Expected<EvalDataset> loadOdometry(const fs::path& dir, int max_frames) {
  EvalDataset ds;
  ds.name = dir.filename().string();
  ds.level_assumed = true;
  const bool colour = fs::is_directory(dir / "image_2");
  const fs::path images = dir / (colour ? "image_2" : "image_0");
  fs::path sun_path = dir / "sun_cam.csv";
  if (!fs::exists(sun_path)) {
    const std::string prefix = ds.name.substr(0, ds.name.find('_'));
    sun_path = dir.parent_path() / (prefix + "_sun_cam.csv");
  }
  Expected<files::SunCsv> sun = files::readSunCsv(sun_path.string());
  if (!sun) return sun.status();
  std::size_t n = 0;
  while (fs::exists(odometryPng(images, n))) ++n;
  if (n == 0) return notFound(images.string() + ": no 000000.png");
  if (n > sun->sun_c.size()) {
    return invalidArgument(sun_path.string() + ": " + std::to_string(sun->sun_c.size()) +
                           " rows, fewer than the " + std::to_string(n) + " images");
  }
  const cv::Mat first = cv::imread(odometryPng(images, 0), cv::IMREAD_UNCHANGED);
  if (first.empty()) return ioError((images / "000000.png").string() + ": cannot read");
  Expected<kitti::OdometryCalibration> calib =
      kitti::readOdometryCalibration((dir / "calib.txt").string());
  if (!calib) return calib.status();
  Expected<StereoCamera> cam =
      kitti::odometryStereoCamera(*calib, colour ? 2 : 0, colour ? 3 : 1, first.cols, first.rows);
  if (!cam) return cam.status();
  ds.camera = *cam;
  for (std::size_t k = 0; k < n; ++k) {
    if (max_frames > 0 && static_cast<int>(k) >= max_frames) break;
    EvalFrame f;
    f.image_path = odometryPng(images, k);
    f.true_sun_c = sun->sun_c[k].normalized();
    ds.frames.push_back(f);
  }
  return ds;
}
}  // namespace

Expected<EvalDataset> loadEvalDataset(const std::string& dir_in, int max_frames) {
  fs::path dir = fs::path(dir_in);
  if (dir.filename().empty()) dir = dir.parent_path();  // trailing '/'
  if (!fs::is_directory(dir)) return notFound(dir_in + ": not a folder");
  if (fs::is_directory(dir / "image_0") && fs::exists(dir / "calib.txt")) {
    return loadOdometry(dir, max_frames);
  }
  const fs::path drive = findRenderedDrive(dir);
  if (!drive.empty()) return loadRendered(dir, drive, max_frames);
  return notFound(dir_in +
                  ": neither a KITTI odometry folder (image_0/, calib.txt) nor a sunvo_render "
                  "drive (<date>/<date>_drive_<n>_sync/gt/sun_cam0.csv)");
}

}  // namespace sunvo::suneval
