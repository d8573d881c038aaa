#include "sunvo/replay/replay.hpp"

#include "sunvo/files/sun_csv.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/oxts.hpp"
#include "sunvo/kitti/stereo_source.hpp"
#include "sunvo/kitti/timestamps.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::replay {

Status ReplayOptions::validate() const {
  if (drive_dir.empty()) return invalidArgument("replay.drive_dir is empty");
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("replay.every_n_frames out of range [1, 1000]");
  }
  if (max_frames < 0) return invalidArgument("replay.max_frames must be >= 0");
  SUNVO_RETURN_IF_ERROR(pipeline.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  // The cap's range is the fusion's own (min <= cap <= 5), checked by the fusion itself.
  if (const Status s = imageFusion().validate(); !s.isOk()) {
    return invalidArgument("replay.image_max_drift_deg_per_frame: " + s.message());
  }
  return Status::ok();
}

sunfusion::SunFusionOptions ReplayOptions::imageFusion() const {
  sunfusion::SunFusionOptions f = fusion;
  f.max_drift_deg_per_frame = image_max_drift_deg_per_frame;
  return f;
}

Expected<ReplayData> loadReplayData(const ReplayOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  ReplayData data;
  auto gt = files::readKittiPoses(options.drive_dir + "/gt/poses_cam0_enu.txt");
  if (!gt) return gt.status();
  data.T_w_c_gt = gt->T_w_c;
  auto times = kitti::readRawTimestamps(options.drive_dir + "/image_00/timestamps.txt",
                                        options.utc_offset_s);
  if (!times) return times.status();
  data.times_ns = *times;
  auto oxts = kitti::readOxtsRecord(kitti::oxtsRecordPath(options.drive_dir, 0));
  if (!oxts) return oxts.status();
  data.origin = {oxts->lat, oxts->lon, oxts->alt};
  // The ground truth is in the ENU frame of gt/origin.txt; the replay's world is ENU at the first
  // GPS fix. Move each pose through WGS84: p_fix = fix(scene^-1(p_scene)), and rotate by the two
  // frames' local-level rotations at that point, C_fix_scene = C_fix_lev C_scene_lev^T.
  auto origin_file = files::TextFile::open(options.drive_dir + "/gt/origin.txt");
  if (!origin_file) return origin_file.status();
  std::string_view line;
  if (!origin_file->nextLine(line)) return parseError(origin_file->path() + ": empty");
  const auto fields = files::splitFields(line);
  if (fields.size() != 3) return origin_file->lineError("expected 'lat lon alt'");
  geodesy::GeodeticPoint scene_origin;
  auto lat = origin_file->parseDouble(fields[0], "lat");
  auto lon = origin_file->parseDouble(fields[1], "lon");
  auto alt = origin_file->parseDouble(fields[2], "alt");
  if (!lat || !lon || !alt) return !lat ? lat.status() : !lon ? lon.status() : alt.status();
  scene_origin = {*lat, *lon, *alt};
  auto scene = geodesy::LocalEnuFrame::create(scene_origin);
  if (!scene) return scene.status();
  auto fix = geodesy::LocalEnuFrame::create(data.origin);
  if (!fix) return fix.status();
  for (Isometry3& T : data.T_w_c_gt) {
    auto g = scene->toGeodetic(T.translation());
    if (!g) return g.status();
    Eigen::Matrix3d C_scene_lev, C_fix_lev;
    auto p_scene = scene->toEnu(*g, C_scene_lev);
    auto p_fix = fix->toEnu(*g, C_fix_lev);
    if (!p_scene || !p_fix) return !p_scene ? p_scene.status() : p_fix.status();
    T.linear() = orthonormalize(C_fix_lev * C_scene_lev.transpose() * T.linear());
    T.translation() = *p_fix;
  }
  if (data.T_w_c_gt.size() != data.times_ns.size()) {
    return invalidArgument(options.drive_dir + ": gt/poses_cam0_enu.txt has " +
                           std::to_string(data.T_w_c_gt.size()) + " poses for " +
                           std::to_string(data.times_ns.size()) + " frames");
  }
  return data;
}

Expected<ReplayRun> replayDrive(const ReplayOptions& options,
                                const std::optional<experiment::SunSourceSpec>& spec,
                                sunfusion::ImageSunEstimator* image_sun) {
  if (spec && image_sun != nullptr) {
    return invalidArgument("replayDrive: give an error-model sun source or an image estimator");
  }
  SUNVO_RETURN_IF_ERROR(options.validate());
  kitti::KittiSourceOptions src_opt;
  src_opt.root = options.drive_dir;
  src_opt.layout = kitti::KittiLayout::kRaw;
  src_opt.utc_offset_s = options.utc_offset_s;
  if (options.max_frames > 0) src_opt.last_frame = options.max_frames - 1;
  src_opt.use_color = image_sun != nullptr;
  auto source = kitti::KittiStereoSource::open(src_opt);
  if (!source) return source.status();

  // The world: local ENU at the first GPS fix. The first camera pose from the first OXTS record
  // through the drive's calibration chain, as on the rover at start-up.
  auto oxts = kitti::readOxtsSequence(options.drive_dir, options.utc_offset_s);
  if (!oxts) return oxts.status();
  if (oxts->empty()) return notFound(options.drive_dir + "/oxts: no records");
  const kitti::OxtsRecord& first = oxts->front().record;
  auto world = geodesy::LocalEnuFrame::create({first.lat, first.lon, first.alt});
  if (!world) return world.status();
  auto calib = kitti::readRawCalibration(source->calibrationDir());
  if (!calib) return calib.status();
  const Isometry3 T_c0rect_imu =
      geodesy::cam0RectFromImu(calib->cam_to_cam.cameras[0].R_rect, calib->velo_to_cam.transform(),
                               calib->imu_to_velo.transform());
  auto T_w_imu0 = geodesy::imuPoseInWorld(*world, {first.lat, first.lon, first.alt}, first.roll,
                                          first.pitch, first.yaw);
  if (!T_w_imu0) return T_w_imu0.status();
  const Isometry3 T_w_c0 = geodesy::cam0PoseInWorld(*T_w_imu0, T_c0rect_imu);

  pipeline::PipelineOptions popt = options.pipeline;
  popt.vo.window.max_solver_time_in_seconds = 60.0;  // replay: bounded by iterations only
  pipeline::StereoVisualOdometry vo;
  SUNVO_RETURN_IF_ERROR(vo.init(popt, source->camera(), T_w_c0));

  sunfusion::SunWindowTerm sun_term;
  std::optional<sunfusion::SimulatedSunSource> sun_source;
  std::vector<Eigen::Vector3d> sun_c_gt;
  if (image_sun != nullptr) {
    if (!source->colorCamera()) {
      return notFound(options.drive_dir + ": the image sun estimators need the colour images");
    }
    sunfusion::SunFusionOptions fusion = options.imageFusion();
    fusion.world_up = Eigen::Vector3d::UnitZ();  // ENU
    // An azimuth-only measurement (Sun-CNN) is gated in the x-z plane by gateSunMeasurement itself.
    SUNVO_RETURN_IF_ERROR(sun_term.init(fusion));
    sun_term.attach(vo.odometry().window());
  }
  if (spec) {
    auto sun_csv = files::readSunCsv(options.drive_dir + "/gt/sun_cam0.csv");
    if (!sun_csv) return sun_csv.status();
    sun_c_gt = sun_csv->sun_c;
    sunfusion::SunFusionOptions fusion = options.fusion;
    fusion.gate = spec->gate;
    fusion.world_up = Eigen::Vector3d::UnitZ();  // ENU
    SUNVO_RETURN_IF_ERROR(sun_term.init(fusion));
    sun_term.attach(vo.odometry().window());
    sun_source.emplace(spec->model);
  }

  ReplayRun run;
  run.name = spec                   ? spec->name
             : image_sun != nullptr ? "VO+Sun (" + std::string(image_sun->name()) + ")"
                                    : "Pure VO";
  Isometry3 T_w_c_last = T_w_c0;
  StereoFrame frame;
  std::vector<double> ms;
  for (std::size_t k = 0; !source->finished(); ++k) {
    const Status s = source->next(frame);
    if (source->finished()) break;
    SUNVO_RETURN_IF_ERROR(s);
    const bool sun_frame = (sun_source || image_sun != nullptr) && k > 0 &&
                           k % static_cast<std::size_t>(options.every_n_frames) == 0 &&
                           k < oxts->size();
    if (sun_frame) {
      // The sun in the world from the ephemeris at this frame's GPS fix and UTC time.
      const kitti::OxtsRecord& fix = (*oxts)[k].record;
      sun::SpaOptions spa;
      spa.latitude_deg = fix.lat;
      spa.longitude_deg = fix.lon;
      spa.elevation_m = fix.alt;
      auto sp = sun::computeSolarPosition(frame.trigger_time_ns, spa);
      if (!sp) return sp.status();
      if (sun_source && k < sun_c_gt.size()) {
        auto m = sun_source->measure(frame.sequence, frame.trigger_time_ns, sun_c_gt[k]);
        if (m) sun_term.addObservation({*m, sp->sun_enu});
      } else if (image_sun != nullptr) {
        // The prior from the last VO pose (Lalonde-VO); the colour camera is rectified to the
        // orientation of camera 0, so a direction in one is the same in the other.
        const Eigen::Matrix3d C_c_w = T_w_c_last.linear().transpose();
        sunfusion::ImageSunInput in{
            frame.left_color, *source->colorCamera(),
            sunfusion::SunPrior{C_c_w * sp->sun_enu, C_c_w * Eigen::Vector3d::UnitZ()}};
        auto e = image_sun->estimate(in);
        if (!e) return e.status();
        ++run.sun_calls;
        run.sun_ms.push_back(e->time_ms);
        if (e->valid) {
          sunfusion::SunMeasurement m = e->measurement;
          m.sequence = frame.sequence;
          m.time_ns = frame.trigger_time_ns;
          sun_term.addObservation({m, sp->sun_enu});
        }
      }
    }
    auto r = vo.process(frame);
    if (!r) return r.status();
    if (r->vo.status == vo::TrackingStatus::kLost) ++run.lost_frames;
    ms.push_back(r->times.total_ms);
    run.T_w_c.push_back(r->vo.T_w_c);
    T_w_c_last = r->vo.T_w_c;
  }
  run.gate = sun_term.counters();
  run.median_ms = metrics::percentile(ms, 0.5);
  run.p99_ms = metrics::percentile(ms, 0.99);
  return run;
}

}  // namespace sunvo::replay
