#include "sunvo/rig_truth_images/rig_truth_images.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sunvo/dataset/dataset.hpp"
#include "sunvo/render/drive.hpp"

namespace sunvo::rigtruth {
namespace fs = std::filesystem;

Expected<std::vector<RigTurn>> readRigError(const std::string& path) {
  std::ifstream in(path);
  if (!in) return notFound(path + ": cannot open");
  std::vector<RigTurn> turns;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 || line.empty()) continue;  // the header
    std::stringstream ss(line);
    RigTurn t;
    char c1 = 0, c2 = 0, c3 = 0;
    if (!(ss >> t.frame >> c1 >> t.roll_deg >> c2 >> t.pitch_deg >> c3 >> t.yaw_deg) || c1 != ',' ||
        c2 != ',' || c3 != ',' || t.frame < 0 || !std::isfinite(t.roll_deg) ||
        !std::isfinite(t.pitch_deg) || !std::isfinite(t.yaw_deg)) {
      return parseError(path + ":" + std::to_string(line_no) +
                        ": expected frame,right_roll_deg,right_pitch_deg,right_yaw_deg");
    }
    turns.push_back(t);
  }
  if (turns.empty()) return invalidArgument(path + ": no frames");
  return turns;
}

Eigen::Matrix3d rightCameraTurn(const RigTurn& turn, const Axes& axes) {
  // The renderer's own composition, so the oracle undoes exactly what it did.
  return render::rightCameraTurn({axes.roll ? turn.roll_deg : 0.0,
                                  axes.pitch ? turn.pitch_deg : 0.0,
                                  axes.yaw ? turn.yaw_deg : 0.0});
}

void warpToNominal(const cv::Mat& turned, const StereoCamera& camera,
                   const Eigen::Matrix3d& R_c1nom_c1, cv::Mat& nominal) {
  Eigen::Matrix3d K;
  K << camera.fu, 0.0, camera.cu, 0.0, camera.fv, camera.cv, 0.0, 0.0, 1.0;
  // Maps a nominal pixel to the turned image's pixel (hence WARP_INVERSE_MAP).
  const Eigen::Matrix3d H = K * R_c1nom_c1.transpose() * K.inverse();
  cv::Mat h;
  cv::eigen2cv(H, h);
  cv::warpPerspective(turned, nominal, h, turned.size(), cv::INTER_CUBIC | cv::WARP_INVERSE_MAP,
                      cv::BORDER_REPLICATE);
}

namespace {

// Links every entry of `from` into `to` except those named in `skip`.
Status linkAllBut(const fs::path& from, const fs::path& to, const std::vector<std::string>& skip) {
  std::error_code ec;
  fs::create_directories(to, ec);
  if (ec) return ioError(to.string() + ": " + ec.message());
  for (const auto& e : fs::directory_iterator(from)) {
    const std::string name = e.path().filename().string();
    if (std::find(skip.begin(), skip.end(), name) != skip.end()) continue;
    fs::create_symlink(fs::absolute(e.path()), to / name, ec);
    if (ec) return ioError((to / name).string() + ": " + ec.message());
  }
  return Status::ok();
}

}  // namespace

Status writeNominalDrive(const std::string& drive, const std::string& out, const Axes& axes,
                         int* frames) {
  *frames = 0;
  dataset::DatasetOptions options;
  options.path = drive;
  auto data = dataset::Dataset::open(options);
  if (!data) return data.status();
  if (data->kind() != dataset::DatasetKind::kSunvoRender) {
    return invalidArgument(drive + ": not a sunvo_render drive (no gt/rig_error.csv to take out)");
  }
  const fs::path sync = fs::path(data->folder());
  const fs::path day = sync.parent_path();
  auto turns = readRigError((sync / "gt" / "rig_error.csv").string());
  if (!turns) return turns.status();
  const fs::path out_day = fs::path(out) / day.filename();
  const fs::path out_sync = out_day / sync.filename();
  if (fs::exists(out_sync)) return failedPrecondition(out_sync.string() + ": exists already");
  std::vector<std::string> day_skip;
  for (const auto& e : fs::directory_iterator(day)) {
    if (e.is_directory()) day_skip.push_back(e.path().filename().string());
  }
  SUNVO_RETURN_IF_ERROR(linkAllBut(day, out_day, day_skip));
  SUNVO_RETURN_IF_ERROR(linkAllBut(sync, out_sync, {"image_01", "image_03", "gt"}));
  SUNVO_RETURN_IF_ERROR(linkAllBut(sync / "gt", out_sync / "gt", {"rig_error.csv"}));
  {
    std::ofstream rig((out_sync / "gt" / "rig_error.csv").string());
    rig << "frame,right_roll_deg,right_pitch_deg,right_yaw_deg\n";
    for (const RigTurn& t : *turns) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "%d,%.6f,%.6f,%.6f\n", t.frame, axes.roll ? 0.0 : t.roll_deg,
                    axes.pitch ? 0.0 : t.pitch_deg, axes.yaw ? 0.0 : t.yaw_deg);
      rig << buf;
    }
    if (!rig) return ioError((out_sync / "gt" / "rig_error.csv").string() + ": write failed");
  }
  for (const char* image : {"image_01", "image_03"}) {
    const fs::path in_dir = sync / image;
    if (!fs::exists(in_dir)) continue;
    const bool colour = std::string(image) == "image_03";
    const StereoCamera& camera =
        colour && data->colorCamera() ? *data->colorCamera() : data->camera();
    SUNVO_RETURN_IF_ERROR(linkAllBut(in_dir, out_sync / image, {"data"}));
    std::error_code ec;
    fs::create_directories(out_sync / image / "data", ec);
    if (ec) return ioError((out_sync / image / "data").string() + ": " + ec.message());
    int written = 0;
    for (const RigTurn& t : *turns) {
      char name[32];
      std::snprintf(name, sizeof name, "%010d.png", t.frame);
      const fs::path src = in_dir / "data" / name;
      const cv::Mat turned = cv::imread(src.string(), cv::IMREAD_UNCHANGED);
      if (turned.empty()) return notFound(src.string() + ": cannot read the image");
      cv::Mat nominal;
      warpToNominal(turned, camera, rightCameraTurn(t, axes), nominal);
      const fs::path dst = out_sync / image / "data" / name;
      if (!cv::imwrite(dst.string(), nominal)) return ioError(dst.string() + ": write failed");
      ++written;
    }
    if (!colour) *frames = written;
  }
  return Status::ok();
}

}  // namespace sunvo::rigtruth
