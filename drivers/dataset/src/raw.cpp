// KITTI raw drives and sunvo renders (the same layout; a render adds gt/).

#include <filesystem>

#include "loader.hpp"
#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/oxts.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::dataset {
namespace fs = std::filesystem;
namespace {

Expected<geodesy::GeodeticPoint> readOrigin(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  std::string_view line;
  if (!file->nextLine(line)) return parseError(path + ": empty");
  const auto fields = files::splitFields(line);
  if (fields.size() != 3) return file->lineError("expected 'lat lon alt'");
  auto lat = file->parseDouble(fields[0], "lat");
  if (!lat) return lat.status();
  auto lon = file->parseDouble(fields[1], "lon");
  if (!lon) return lon.status();
  auto alt = file->parseDouble(fields[2], "alt");
  if (!alt) return alt.status();
  return geodesy::GeodeticPoint{*lat, *lon, *alt};
}

// A render's ground truth: camera 0 in the ENU frame of gt/origin.txt, moved into the world (ENU
// at the first fix of the range) through WGS84: p_w = world(scene^-1(p_scene)), and rotated by
// the two frames' local-level rotations at that point, C_w_scene = C_w_lev C_scene_lev^T.
Expected<std::vector<Isometry3>> renderGroundTruth(const fs::path& gt_dir,
                                                   const geodesy::LocalEnuFrame& world) {
  auto poses = files::readKittiPoses((gt_dir / "poses_cam0_enu.txt").string());
  if (!poses) return poses.status();
  auto origin = readOrigin((gt_dir / "origin.txt").string());
  if (!origin) return origin.status();
  auto scene = geodesy::LocalEnuFrame::create(*origin);
  if (!scene) return scene.status();
  std::vector<Isometry3> out = poses->T_w_c;
  for (Isometry3& T : out) {
    auto g = scene->toGeodetic(T.translation());
    if (!g) return g.status();
    Eigen::Matrix3d C_scene_lev, C_w_lev;
    auto p_scene = scene->toEnu(*g, C_scene_lev);
    if (!p_scene) return p_scene.status();
    auto p_w = world.toEnu(*g, C_w_lev);
    if (!p_w) return p_w.status();
    T.linear() = orthonormalize(C_w_lev * C_scene_lev.transpose() * T.linear());
    T.translation() = *p_w;
  }
  return out;
}

}  // namespace

Expected<Dataset> DatasetLoader::raw(const DatasetOptions& options, const fs::path& drive) {
  if (!options.ground_truth.empty()) {
    return invalidArgument(
        "dataset.ground_truth: a KITTI raw drive or a render carries its own "
        "(OXTS, gt/); it is not replaced");
  }
  Dataset ds;
  ds.options_ = options;
  ds.folder_ = drive.string();
  ds.name_ = drive.filename().string();
  const fs::path gt_dir = drive / "gt";
  const bool render = fs::exists(gt_dir / "poses_cam0_enu.txt");
  ds.kind_ = render ? DatasetKind::kSunvoRender : DatasetKind::kKittiRaw;
  // A render writes UTC; a KITTI raw drive's zone must be stated.
  if (render && !ds.options_.utc_offset_s) ds.options_.utc_offset_s = 0;
  ds.utc_known_ = ds.options_.utc_offset_s.has_value();
  const std::int64_t offset = ds.options_.utc_offset_s.value_or(0);

  // Images and their timestamps: the source checks every file of the range exists.
  kitti::KittiSourceOptions so;
  so.root = ds.folder_;
  so.layout = kitti::KittiLayout::kRaw;
  so.utc_offset_s = offset;
  so.use_color = options.color;
  so.drop_bad_frames = options.drop_bad_frames;
  auto source = kitti::KittiStereoSource::open(so);
  if (!source) return source.status();
  std::int64_t first = 0, last = 0;
  SUNVO_RETURN_IF_ERROR(range(options, static_cast<std::size_t>(source->frameCount()),
                              ds.folder_ + "/image_00", &first, &last));
  ds.first_ = first;
  ds.has_images_ = true;
  ds.camera_ = source->camera();
  ds.times_ns_.assign(source->frameTimes().begin() + first,
                      source->frameTimes().begin() + last + 1);
  auto calib = kitti::readRawCalibration(source->calibrationDir());
  if (!calib) return calib.status();
  if (fs::is_directory(drive / "image_02")) {
    auto colour = kitti::rawStereoCamera(calib->cam_to_cam, 2, 3);
    if (!colour) return colour.status();
    ds.color_camera_ = *colour;
  }

  // OXTS: one record per frame; the world is ENU at the fix of the first frame of the range.
  auto oxts = kitti::readOxtsSequence(ds.folder_, offset);
  if (!oxts) return oxts.status();
  if (oxts->size() != static_cast<std::size_t>(source->frameCount())) {
    return invalidArgument(ds.folder_ + "/oxts/timestamps.txt: " + std::to_string(oxts->size()) +
                           " records for " + std::to_string(source->frameCount()) + " images");
  }
  for (std::int64_t i = first; i <= last; ++i) {
    const kitti::OxtsRecord& r = (*oxts)[static_cast<std::size_t>(i)].record;
    ds.fixes_.push_back({r.lat, r.lon, r.alt});
  }
  ds.world_ = WorldFrame::kEnu;
  ds.origin_ = ds.fixes_.front();
  auto world = geodesy::LocalEnuFrame::create(*ds.origin_);
  if (!world) return world.status();
  const Isometry3 T_c0rect_imu =
      geodesy::cam0RectFromImu(calib->cam_to_cam.cameras[0].R_rect, calib->velo_to_cam.transform(),
                               calib->imu_to_velo.transform());
  std::vector<Isometry3> T_w_c_oxts;
  for (std::int64_t i = first; i <= last; ++i) {
    const kitti::OxtsRecord& r = (*oxts)[static_cast<std::size_t>(i)].record;
    auto T_w_imu = geodesy::imuPoseInWorld(*world, {r.lat, r.lon, r.alt}, r.roll, r.pitch, r.yaw);
    if (!T_w_imu) {
      return Status(T_w_imu.status().code(),
                    kitti::oxtsRecordPath(ds.folder_, i) + ": " + T_w_imu.status().message());
    }
    T_w_c_oxts.push_back(geodesy::cam0PoseInWorld(*T_w_imu, T_c0rect_imu));
  }
  ds.T_w_c0_ = T_w_c_oxts.front();

  // The sun from the ephemeris at each fix and UTC time, as the rover computes it.
  if (ds.utc_known_) {
    for (std::size_t k = 0; k < ds.size(); ++k) {
      sun::SpaOptions spa;
      spa.latitude_deg = ds.fixes_[k].lat_deg;
      spa.longitude_deg = ds.fixes_[k].lon_deg;
      spa.elevation_m = ds.fixes_[k].alt_m;
      auto sp = sun::computeSolarPosition(ds.times_ns_[k], spa);
      if (!sp) return sp.status();
      // SPA gives the sun in the fix's local-level ENU axes; C_w_lev turns it into the world's.
      Eigen::Matrix3d C_w_lev;
      auto p_w = world->toEnu(ds.fixes_[k], C_w_lev);
      if (!p_w) return p_w.status();
      ds.ephemeris_sun_w_.push_back(C_w_lev * sp->sun_enu);
    }
  }
  if (!render) {
    // KITTI devkit convention: the ground truth is the OXTS pose through the calibration chain.
    ds.T_w_c_gt_ = std::move(T_w_c_oxts);
    if (!ds.utc_known_) {
      ds.sun_reason_ = ds.folder_ +
                       ": the timestamps' offset to UTC is not given (KITTI's files name no zone; "
                       "state it with utc_offset_s, e.g. --utc-offset-s 0 or 7200)";
      return ds;
    }
    ds.sun_ = sunFromWorld(ds.ephemeris_sun_w_, ds.T_w_c_gt_);
    return ds;
  }

  auto gt = renderGroundTruth(gt_dir, *world);
  if (!gt) return gt.status();
  if (gt->size() != static_cast<std::size_t>(source->frameCount())) {
    return invalidArgument((gt_dir / "poses_cam0_enu.txt").string() + ": " +
                           std::to_string(gt->size()) + " poses for " +
                           std::to_string(source->frameCount()) + " frames");
  }
  ds.T_w_c_gt_.assign(gt->begin() + first, gt->begin() + last + 1);
  const std::string sun_path =
      options.sun_csv.empty() ? (gt_dir / "sun_cam0.csv").string() : options.sun_csv;
  auto sun = files::readSunCsv(sun_path);
  if (!sun) return sun.status();
  if (sun->sun_c.size() != static_cast<std::size_t>(source->frameCount())) {
    return invalidArgument(sun_path + ": " + std::to_string(sun->sun_c.size()) + " rows for " +
                           std::to_string(source->frameCount()) + " frames");
  }
  std::vector<Eigen::Vector3d> sun_w;
  for (std::size_t k = 0; k < ds.size(); ++k) {
    sun_w.push_back(ds.T_w_c_gt_[k].linear() *
                    sun->sun_c[static_cast<std::size_t>(first) + k].normalized());
  }
  ds.sun_ = sunFromWorld(sun_w, ds.T_w_c_gt_);
  return ds;
}

}  // namespace sunvo::dataset
