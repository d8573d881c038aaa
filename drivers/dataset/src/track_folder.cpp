#include "sunvo/dataset/track_folder.hpp"

#include <cmath>
#include <filesystem>

#include "sunvo/dataset/kitti_rigs.hpp"
#include "sunvo/kitti/calibration.hpp"

namespace sunvo::dataset {
namespace fs = std::filesystem;

Expected<files::TrackSequence> readTrackFolder(const std::string& folder,
                                               files::TrackReadOptions options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  if (options.image_width > 0) return files::readTrackFolder(folder, options);
  // The folder's own name even for "." or a trailing '/'.
  fs::path dir = fs::absolute(fs::path(folder)).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();
  auto calib_file = files::TextFile::open((dir / "calib.txt").string());
  if (!calib_file) return calib_file.status();
  bool has_size = false;
  auto calib = files::parseTrackCalibLine(*calib_file, &has_size);
  if (!calib) return calib.status();
  if (has_size) return files::readTrackFolder(folder, options);

  std::string source;
  for (const fs::path& p :
       {dir / "calib_cam_to_cam.txt", dir.parent_path() / "calib_cam_to_cam.txt"}) {
    if (!fs::exists(p)) continue;
    auto c2c = kitti::readCamToCam(p.string());
    if (!c2c) return c2c.status();
    const Eigen::Vector2d S = c2c->cameras[0].S_rect;
    if (!(S.x() >= 16.0 && S.y() >= 16.0)) {
      return invalidArgument(p.string() + ": field 'S_rect_00': missing or smaller than 16 px");
    }
    options.image_width = static_cast<int>(std::lround(S.x()));
    options.image_height = static_cast<int>(std::lround(S.y()));
    source = p.string() + " S_rect_00";
    break;
  }
  if (source.empty()) {
    const std::optional<KittiRig> rig = kittiRigOfDay(dir.filename().string());
    if (rig && std::abs(rig->fu - calib->fu) < 1.0 && std::abs(rig->cu - calib->cu) < 1.0 &&
        std::abs(rig->cv - calib->cv) < 1.0) {
      options.image_width = rig->width;
      options.image_height = rig->height;
      source = std::string("the KITTI ") + rig->date + " rig";
    }
  }
  auto seq = files::readTrackFolder(folder, options);
  if (!seq) return seq.status();
  if (!source.empty()) seq->image_size_source = source;
  return seq;
}

}  // namespace sunvo::dataset
