#include "sunvo/dataset/dataset.hpp"

#include <cstdio>
#include <filesystem>

#include "loader.hpp"
#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/tracks_io.hpp"

namespace sunvo::dataset {
namespace fs = std::filesystem;

namespace {
constexpr std::int64_t kMaxUtcOffsetS = 14 * 3600;

// <dir>/<date>/<date>_drive_NNNN_sync: the one drive folder that sunvo_render writes under its
// output folder; empty if there is none, an error if there are several.
Expected<fs::path> renderedDriveUnder(const fs::path& dir) {
  fs::path found;
  std::error_code ec;
  for (const fs::directory_entry& day : fs::directory_iterator(dir, ec)) {
    if (!day.is_directory()) continue;
    for (const fs::directory_entry& drive : fs::directory_iterator(day.path(), ec)) {
      if (!drive.is_directory() || !fs::is_directory(drive.path() / "image_00")) continue;
      if (!found.empty()) {
        return invalidArgument(dir.string() + ": holds several drives (" + found.string() + ", " +
                               drive.path().string() + "); name one");
      }
      found = drive.path();
    }
  }
  return found;
}
}  // namespace

const char* toString(DatasetKind kind) {
  switch (kind) {
    case DatasetKind::kSunvoRender:
      return "sunvo render";
    case DatasetKind::kKittiRaw:
      return "KITTI raw drive";
    case DatasetKind::kKittiOdometry:
      return "KITTI odometry sequence";
    case DatasetKind::kTrackFolder:
      return "feature-track folder";
    case DatasetKind::kTrajectory:
      return "trajectory route";
  }
  return "?";
}

Status DatasetOptions::validate() const {
  if (path.empty()) return invalidArgument("dataset.path: empty");
  if (utc_offset_s && (*utc_offset_s < -kMaxUtcOffsetS || *utc_offset_s > kMaxUtcOffsetS)) {
    return invalidArgument("dataset.utc_offset_s: " + std::to_string(*utc_offset_s) +
                           " outside [-50400, 50400] s");
  }
  if (odometry_start_utc_ns < 0) return invalidArgument("dataset.odometry_start_utc_ns: < 0");
  if (first_frame < 0) return invalidArgument("dataset.first_frame: must be >= 0");
  files::TrackReadOptions track;
  track.image_width = image_width;
  track.image_height = image_height;
  track.border_tolerance_px = border_tolerance_px;
  if (Status s = track.validate(); !s.isOk()) {
    return invalidArgument("dataset.image_width/image_height/border_tolerance_px: " + s.message());
  }
  if (last_frame < -1 || (last_frame != -1 && last_frame < first_frame)) {
    return invalidArgument("dataset.last_frame: must be -1 (to the end) or >= first_frame");
  }
  return Status::ok();
}

Expected<Dataset> Dataset::open(const DatasetOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  fs::path path(options.path);
  if (path.filename().empty()) path = path.parent_path();  // a trailing '/'
  if (fs::is_directory(path)) {
    if (fs::is_directory(path / "image_00") && fs::is_directory(path / "oxts")) {
      return DatasetLoader::raw(options, path);
    }
    if (fs::is_directory(path / "image_0") && fs::exists(path / "calib.txt")) {
      return DatasetLoader::odometry(options, path);
    }
    if (fs::exists(path / "tracks.csv")) return DatasetLoader::tracks(options, path);
    if (fs::exists(path / "times.txt") &&
        (fs::exists(path / "gt_poses.txt") || fs::exists(path / "poses.txt"))) {
      return DatasetLoader::trajectory(options, path);
    }
    auto drive = renderedDriveUnder(path);
    if (!drive) return drive.status();
    if (!drive->empty()) return DatasetLoader::raw(options, *drive);
  } else if (fs::exists(path.string() + "_gt_poses.txt")) {
    return DatasetLoader::trajectory(options, path);
  }
  return notFound(options.path +
                  ": not a dataset: expected a KITTI raw drive (image_00/, oxts/), a sunvo_render "
                  "output, a KITTI odometry sequence (image_0/, calib.txt), a track folder "
                  "(tracks.csv), a trajectory folder (times.txt, gt_poses.txt) or a KITTI "
                  "odometry prefix DIR/NN (NN_gt_poses.txt)");
}

Eigen::Vector3d Dataset::worldUp() const {
  if (world_ == WorldFrame::kEnu) return Eigen::Vector3d::UnitZ();
  return -Eigen::Vector3d::UnitY();
}

kitti::KittiSourceOptions Dataset::imageSourceOptions() const {
  kitti::KittiSourceOptions o;
  o.root = folder_;
  o.first_frame = first_;
  o.last_frame = first_ + static_cast<std::int64_t>(times_ns_.size()) - 1;
  o.use_color = options_.color;
  o.drop_bad_frames = options_.drop_bad_frames;
  if (kind_ == DatasetKind::kKittiOdometry) {
    o.layout = kitti::KittiLayout::kOdometry;
    o.odometry_start_time_ns = options_.odometry_start_utc_ns;
  } else {
    o.layout = kitti::KittiLayout::kRaw;
    o.utc_offset_s = options_.utc_offset_s.value_or(0);
  }
  return o;
}

std::string Dataset::describe() const {
  char buf[768];
  std::snprintf(
      buf, sizeof(buf), "%s '%s': %zu frames, camera %dx%d fu %.2f b %.4f m, world %s%s%s%s%s",
      toString(kind_), name_.c_str(), size(), camera_.width, camera_.height, camera_.fu,
      camera_.baseline_m, world_ == WorldFrame::kEnu ? "ENU at the first fix" : "first camera",
      hasGroundTruth() ? ", ground truth" : ", no ground truth",
      sunKnown() ? ", true sun" : ", sun unknown", hasImages() ? ", images" : "",
      hasFeatures() ? ", feature tracks" : "");
  std::string out = buf;
  if (kind_ == DatasetKind::kTrackFolder) {
    out += " (image size from " + image_size_source_ + "; " + std::to_string(dropped_past_border_) +
           " observations dropped past the border)";
  }
  return out;
}

std::vector<TrueSun> sunFromWorld(const std::vector<Eigen::Vector3d>& sun_w,
                                  const std::vector<Isometry3>& T_w_c) {
  std::vector<TrueSun> out(std::min(sun_w.size(), T_w_c.size()));
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].sun_w = sun_w[k].normalized();
    out[k].sun_c = (T_w_c[k].linear().transpose() * out[k].sun_w).normalized();
  }
  return out;
}

std::string firstExisting(std::initializer_list<fs::path> candidates) {
  for (const fs::path& p : candidates) {
    if (!p.empty() && fs::exists(p)) return p.string();
  }
  return {};
}

Status DatasetLoader::range(const DatasetOptions& options, std::size_t n, const std::string& what,
                            std::int64_t* first, std::int64_t* last) {
  const auto count = static_cast<std::int64_t>(n);
  if (count == 0) return invalidArgument(what + ": no frames");
  if (options.first_frame >= count) {
    return invalidArgument("dataset.first_frame: " + std::to_string(options.first_frame) +
                           " is past the last frame of " + what + " (" + std::to_string(count - 1) +
                           ")");
  }
  if (options.last_frame >= count) {
    return invalidArgument("dataset.last_frame: " + std::to_string(options.last_frame) +
                           " is past the last frame of " + what + " (" + std::to_string(count - 1) +
                           ")");
  }
  *first = options.first_frame;
  *last = options.last_frame < 0 ? count - 1 : options.last_frame;
  return Status::ok();
}

Status DatasetLoader::firstCameraWorld(Dataset& ds, std::vector<Isometry3> T_gt_all,
                                       const std::string& gt_path, const std::string& sun_csv,
                                       std::int64_t first, std::int64_t last) {
  ds.world_ = WorldFrame::kFirstCamera;
  const auto n = static_cast<std::size_t>(last - first + 1);
  if (!T_gt_all.empty()) {
    if (T_gt_all.size() < static_cast<std::size_t>(last + 1)) {
      return invalidArgument(gt_path + ": " + std::to_string(T_gt_all.size()) +
                             " poses, fewer than the " + std::to_string(last + 1) +
                             " frames up to the end of the range");
    }
    // The world is the first camera of the recording; a range starting later keeps it, so poses
    // and the sun stay comparable with the whole recording's.
    ds.T_w_c_gt_.assign(T_gt_all.begin() + first, T_gt_all.begin() + last + 1);
    ds.T_w_c0_ = ds.T_w_c_gt_.front();
  }
  if (sun_csv.empty()) {
    ds.sun_reason_ = "no sun file (give one: a frame,sx,sy,sz csv of the true sun in camera 0)";
    return Status::ok();
  }
  auto sun = files::readSunCsv(sun_csv);
  if (!sun) return sun.status();
  if (sun->sun_c.size() < static_cast<std::size_t>(last + 1)) {
    return invalidArgument(sun_csv + ": " + std::to_string(sun->sun_c.size()) +
                           " rows, fewer than the " + std::to_string(last + 1) +
                           " frames up to the end of the range");
  }
  if (ds.T_w_c_gt_.empty()) {
    ds.sun_reason_ = sun_csv + ": the sun in the world needs the ground truth";
    return Status::ok();
  }
  ds.sun_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    TrueSun& s = ds.sun_[k];
    s.sun_c = sun->sun_c[static_cast<std::size_t>(first) + k].normalized();
    s.sun_w = (ds.T_w_c_gt_[k].linear() * s.sun_c).normalized();
  }
  return Status::ok();
}

}  // namespace sunvo::dataset
