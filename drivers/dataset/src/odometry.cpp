// KITTI odometry sequences, feature-track folders and trajectory routes: worlds without GPS, whose
// frame is the first camera of the ground truth.

#include <filesystem>

#include "loader.hpp"
#include "sunvo/dataset/kitti_rigs.hpp"
#include "sunvo/dataset/track_folder.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/kitti/calibration.hpp"

namespace sunvo::dataset {
namespace fs = std::filesystem;
namespace {

// "00_first_frames" -> "00"; "05" -> "05".
std::string sequencePrefix(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.substr(0, name.find('_'));
}

Expected<std::vector<Isometry3>> readPoses(const std::string& path) {
  if (path.empty()) return std::vector<Isometry3>();
  auto t = files::loadTrajectory(path);
  if (!t) return t.status();
  return t->T_w_c;
}

// Times in seconds from a file: absolute (track folders: KITTI's timestamps as written) or from
// the first frame (KITTI odometry times.txt), to UTC ns.
Expected<std::vector<TimeNs>> readSeconds(const std::string& path, TimeNs start_ns) {
  auto t = files::readTimes(path);
  if (!t) return t.status();
  for (TimeNs& v : *t) v += start_ns;
  return t;
}

// A route's calib.txt: the track folder's one line "fu fv cu cv baseline_m" or KITTI odometry's
// P0..P3; the image size (neither form holds it) from the KITTI rig of the sequence when known.
Expected<StereoCamera> readRouteCalib(const std::string& path, const std::string& sequence) {
  const std::optional<KittiRig> rig = kittiOdometryRig(sequence);
  const int width = rig ? rig->width : 1242, height = rig ? rig->height : 375;
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  std::string_view line;
  while (file->nextLine(line) && files::isBlank(line)) {
  }
  if (line.rfind("P0:", 0) == 0) {
    auto calib = kitti::readOdometryCalibration(path);
    if (!calib) return calib.status();
    return kitti::odometryStereoCamera(*calib, 0, 1, width, height);
  }
  auto again = files::TextFile::open(path);
  if (!again) return again.status();
  return files::parseTrackCalib(*again, width, height);
}

}  // namespace

Expected<Dataset> DatasetLoader::odometry(const DatasetOptions& options, const fs::path& dir) {
  Dataset ds;
  ds.options_ = options;
  ds.kind_ = DatasetKind::kKittiOdometry;
  ds.folder_ = dir.string();
  ds.name_ = dir.filename().string();
  ds.utc_known_ = options.odometry_start_utc_ns > 0;
  kitti::KittiSourceOptions so;
  so.root = ds.folder_;
  so.layout = kitti::KittiLayout::kOdometry;
  so.odometry_start_time_ns = options.odometry_start_utc_ns;
  so.use_color = options.color;
  so.drop_bad_frames = options.drop_bad_frames;
  auto source = kitti::KittiStereoSource::open(so);
  if (!source) return source.status();
  std::int64_t first = 0, last = 0;
  SUNVO_RETURN_IF_ERROR(range(options, static_cast<std::size_t>(source->frameCount()),
                              ds.folder_ + "/image_0", &first, &last));
  ds.first_ = first;
  ds.has_images_ = true;
  ds.camera_ = source->camera();
  ds.times_ns_.assign(source->frameTimes().begin() + first,
                      source->frameTimes().begin() + last + 1);
  if (fs::is_directory(dir / "image_2")) {
    auto calib = kitti::readOdometryCalibration((dir / "calib.txt").string());
    if (!calib) return calib.status();
    auto colour = kitti::odometryStereoCamera(*calib, 2, 3, ds.camera_.width, ds.camera_.height);
    if (!colour) return colour.status();
    ds.color_camera_ = *colour;
  }
  const std::string prefix = sequencePrefix(dir);
  const fs::path parent = dir.parent_path();
  const std::string gt_path =
      !options.ground_truth.empty()
          ? options.ground_truth
          : firstExisting({dir / "poses.txt", dir / "gt_poses.txt",
                           parent / (prefix + "_gt_poses.txt"),
                           parent.parent_path() / "poses" / (prefix + ".txt")});
  auto gt = readPoses(gt_path);
  if (!gt) return gt.status();
  const std::string sun_path =
      !options.sun_csv.empty()
          ? options.sun_csv
          : firstExisting({dir / "sun_cam.csv", parent / (prefix + "_sun_cam.csv")});
  SUNVO_RETURN_IF_ERROR(firstCameraWorld(ds, std::move(*gt), gt_path, sun_path, first, last));
  return ds;
}

Expected<Dataset> DatasetLoader::tracks(const DatasetOptions& options, const fs::path& dir) {
  Dataset ds;
  ds.options_ = options;
  ds.kind_ = DatasetKind::kTrackFolder;
  ds.folder_ = dir.string();
  ds.name_ = dir.filename().string();
  files::TrackReadOptions tro;
  tro.image_width = options.image_width;
  tro.image_height = options.image_height;
  tro.border_tolerance_px = options.border_tolerance_px;
  auto seq = dataset::readTrackFolder(ds.folder_, tro);
  if (!seq) return seq.status();
  ds.image_size_source_ = seq->image_size_source;
  ds.dropped_past_border_ = seq->dropped_past_border;
  std::int64_t first = 0, last = 0;
  SUNVO_RETURN_IF_ERROR(
      range(options, seq->frames.size(), ds.folder_ + "/times.txt", &first, &last));
  ds.first_ = first;
  ds.camera_ = seq->camera;
  // The track folder's times are the recording's civil timestamps as written.
  ds.utc_known_ = options.utc_offset_s.has_value();
  const TimeNs shift = -options.utc_offset_s.value_or(0) * 1'000'000'000LL;
  ds.features_.assign(seq->frames.begin() + first, seq->frames.begin() + last + 1);
  for (FrameFeatures& f : ds.features_) {
    f.time_ns += shift;
    ds.times_ns_.push_back(f.time_ns);
  }
  std::vector<Isometry3> gt = std::move(seq->gt_T_0_k);
  std::string gt_path = ds.folder_ + "/gt_poses.txt";
  if (!options.ground_truth.empty()) {
    gt_path = options.ground_truth;
    auto t = readPoses(gt_path);
    if (!t) return t.status();
    gt = std::move(*t);
  }
  const std::string sun_path =
      !options.sun_csv.empty() ? options.sun_csv : firstExisting({dir / "sun_cam.csv"});
  SUNVO_RETURN_IF_ERROR(firstCameraWorld(ds, std::move(gt), gt_path, sun_path, first, last));
  return ds;
}

Expected<Dataset> DatasetLoader::trajectory(const DatasetOptions& options, const fs::path& path) {
  Dataset ds;
  ds.options_ = options;
  ds.kind_ = DatasetKind::kTrajectory;
  const bool folder = fs::is_directory(path);
  const std::string prefix = sequencePrefix(path);
  // Folder: DIR/{gt_poses.txt|poses.txt, times.txt, sun_cam.csv, calib.txt}; prefix: DIR/NN_*.
  auto file = [&](const std::string& name) {
    return folder ? (path / name).string() : path.string() + "_" + name;
  };
  ds.folder_ = folder ? path.string() : path.parent_path().string();
  ds.name_ = path.filename().string();
  const std::string gt_path = !options.ground_truth.empty()
                                  ? options.ground_truth
                                  : firstExisting({file("gt_poses.txt"), file("poses.txt")});
  if (gt_path.empty()) return notFound(file("gt_poses.txt") + ": not found");
  auto gt = readPoses(gt_path);
  if (!gt) return gt.status();
  auto times = readSeconds(file("times.txt"), options.odometry_start_utc_ns);
  if (!times) return times.status();
  if (times->size() != gt->size()) {
    return invalidArgument(file("times.txt") + ": " + std::to_string(times->size()) +
                           " times for the " + std::to_string(gt->size()) + " poses of " + gt_path);
  }
  ds.utc_known_ = options.odometry_start_utc_ns > 0;
  std::int64_t first = 0, last = 0;
  SUNVO_RETURN_IF_ERROR(range(options, gt->size(), gt_path, &first, &last));
  ds.first_ = first;
  ds.times_ns_.assign(times->begin() + first, times->begin() + last + 1);

  // Calibration: a file of the route, else the KITTI rig that recorded the sequence.
  const std::string calib_path = firstExisting(
      {file("calib.txt"), folder ? fs::path() : fs::path(file("first_frames")) / "calib.txt"});
  if (!calib_path.empty()) {
    auto cam = readRouteCalib(calib_path, prefix);
    if (!cam) return cam.status();
    ds.camera_ = *cam;
  } else if (const std::optional<KittiRig> rig = kittiOdometryRig(prefix)) {
    ds.camera_ = rig->camera();
  } else {
    return notFound(
        file("calib.txt") + ": not found, and '" + prefix +
        "' is not a KITTI odometry sequence with ground truth (00-10) whose rig is known");
  }
  const std::string sun_path =
      !options.sun_csv.empty() ? options.sun_csv : firstExisting({file("sun_cam.csv")});
  SUNVO_RETURN_IF_ERROR(firstCameraWorld(ds, std::move(*gt), gt_path, sun_path, first, last));
  return ds;
}

}  // namespace sunvo::dataset
