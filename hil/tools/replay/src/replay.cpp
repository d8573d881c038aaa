#include "sunvo/replay/replay.hpp"

#include <algorithm>
#include <cmath>

#include "sunvo/kitti/stereo_source.hpp"
#include "sunvo/metrics/metrics.hpp"

namespace sunvo::replay {

Status ReplayOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(dataset.validate());
  if (every_n_frames < 1 || every_n_frames > 1000) {
    return invalidArgument("replay.every_n_frames out of range [1, 1000]");
  }
  SUNVO_RETURN_IF_ERROR(pipeline.validate());
  SUNVO_RETURN_IF_ERROR(fusion.validate());
  SUNVO_RETURN_IF_ERROR(vertical.estimator.validate());
  if (world_up_alignment_frames < -1 || world_up_alignment_frames > 100000) {
    return invalidArgument("replay.world_up_alignment_frames out of range -1 or [0, 100000]");
  }
  if (!(std::abs(start_pitch_error_deg) <= 30.0) || !(std::abs(start_roll_error_deg) <= 30.0)) {
    return invalidArgument(
        "replay.start_pitch_error_deg / start_roll_error_deg out of range [-30, 30]");
  }
  if (max_consecutive_bad_frames < 0 || max_consecutive_bad_frames > 100000) {
    return invalidArgument("replay.max_consecutive_bad_frames out of range [0, 100000]");
  }
  // The image options' ranges are the fusion's own, checked by the fusion itself.
  if (const Status s = imageFusion().validate(); !s.isOk()) {
    return invalidArgument(
        "replay.image_max_drift_deg_per_frame / image_sun_bias_sigma_deg / "
        "image_sun_bias_length_frames: " +
        s.message());
  }
  return Status::ok();
}

sunfusion::SunFusionOptions ReplayOptions::imageFusion() const {
  sunfusion::SunFusionOptions f = fusion;
  f.max_drift_deg_per_frame = image_max_drift_deg_per_frame;
  f.sun_bias_sigma_deg = image_sun_bias_sigma_deg;
  f.sun_bias_length_frames = image_sun_bias_length_frames;
  return f;
}

Expected<dataset::Dataset> openReplayDataset(const ReplayOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  dataset::DatasetOptions d = options.dataset;
  d.drop_bad_frames = options.max_consecutive_bad_frames > 0;
  auto ds = dataset::Dataset::open(d);
  if (!ds) return ds.status();
  if (!ds->hasImages()) {
    return invalidArgument(options.dataset.path + ": a " + dataset::toString(ds->kind()) +
                           " has no images to replay (sunvo_experiment runs feature tracks)");
  }
  return ds;
}

Expected<ReplayRun> replayDrive(const dataset::Dataset& data, const ReplayOptions& options,
                                const std::optional<experiment::SunSourceSpec>& spec,
                                sunfusion::ImageSunEstimator* image_sun) {
  if (spec && image_sun != nullptr) {
    return invalidArgument("replayDrive: give an error-model sun source or an image estimator");
  }
  SUNVO_RETURN_IF_ERROR(options.validate());
  if (!data.hasImages()) return invalidArgument(data.folder() + ": no images to replay");
  const bool sun = spec.has_value() || image_sun != nullptr;
  // The sun in the world: the ephemeris at each fix (what the rover computes), else the truth.
  const bool ephemeris = !data.ephemerisSunWorld().empty();
  if (sun && !ephemeris && !data.sunKnown()) {
    return notFound(data.folder() + ": no sun for this drive: " + data.sunUnknownReason());
  }
  if (spec && !data.sunKnown()) {
    return notFound(data.folder() +
                    ": an error-model source needs the true sun: " + data.sunUnknownReason());
  }
  // An image estimator looks at the colour image when the drive has one, else at the gray one.
  kitti::KittiSourceOptions src_opt = data.imageSourceOptions();
  src_opt.use_color = image_sun != nullptr && data.colorCamera().has_value();
  src_opt.drop_bad_frames = options.max_consecutive_bad_frames > 0;
  if (image_sun != nullptr && !src_opt.use_color && !image_sun->acceptsGray()) {
    return notFound(data.folder() + ": " + image_sun->name() + " needs the colour images");
  }
  auto source = kitti::KittiStereoSource::open(src_opt);
  if (!source) return source.status();

  pipeline::SunAidedOptions sao;
  sao.pipeline = options.pipeline;
  sao.pipeline.vo.window.max_solver_time_in_seconds = 60.0;  // replay: bounded by iterations only
  // The front end's buffers are allocated for the largest image it accepts: at least the drive's
  // own (another rig's 1280x720 was refused), as the rover sizes them from its cameras.
  sao.pipeline.frontend.max_width = std::max(sao.pipeline.frontend.max_width, data.camera().width);
  sao.pipeline.frontend.max_height =
      std::max(sao.pipeline.frontend.max_height, data.camera().height);
  sao.use_sun = sun;
  sao.every_n_frames = options.every_n_frames;
  sao.vertical = options.vertical;
  sao.fusion = image_sun != nullptr ? options.imageFusion() : options.fusion;
  sao.fusion.world_up = data.worldUp();
  const bool level_start =
      sao.fusion.world_up_alignment_use == sunfusion::WorldUpAlignmentUse::kStartTilt;
  if (level_start && data.world() == dataset::WorldFrame::kFirstCamera) {
    return invalidArgument(data.folder() +
                           ": levelling the start needs a world whose up is known (ENU: a raw "
                           "drive or a render), not the first camera");
  }
  sao.fusion.world_up_alignment_frames =
      options.world_up_alignment_frames >= 0              ? options.world_up_alignment_frames
      : level_start                                       ? sunfusion::kStartTiltFrames
      : data.world() == dataset::WorldFrame::kFirstCamera ? sunfusion::kWorldUpAlignmentFrames
                                                          : 0;
  std::optional<sunfusion::SimulatedSunSource> sun_source;
  if (spec) {
    sao.fusion.gate = spec->gate;
    // An exact source has no correlated error to model.
    if (spec->model.azimuth_sigma_deg == 0.0) sao.fusion.sun_bias_sigma_deg = 0.0;
    SUNVO_RETURN_IF_ERROR(spec->model.validate());
    sun_source.emplace(spec->model);
  }
  const Isometry3 T_w_c0 = experiment::withStartTiltError(
      data.T_w_c0(), options.start_pitch_error_deg, options.start_roll_error_deg);
  pipeline::SunAidedOdometry vo;
  SUNVO_RETURN_IF_ERROR(vo.init(sao, data.camera(), T_w_c0));

  ReplayRun run;
  run.name = spec                   ? spec->name
             : image_sun != nullptr ? "VO+Sun (" + std::string(image_sun->name()) + ")"
                                    : "Pure VO";
  if (options.vertical.enabled)
    run.name = run.name == "Pure VO" ? "VO+vertical" : run.name + " +vertical";
  StereoFrame frame;
  std::vector<double> ms;
  int bad_in_a_row = 0;
  // k: the frame's index in the dataset's range (a dropped frame advances it too).
  for (std::size_t k = 0; !source->finished(); ++k) {
    const Status s = source->next(frame);
    if (source->finished()) break;
    if (!s.isOk()) {
      if (++bad_in_a_row > options.max_consecutive_bad_frames) {
        return Status(s.code(), s.message() + " (" + std::to_string(bad_in_a_row) +
                                    " bad frames in a row, replay.max_consecutive_bad_frames " +
                                    std::to_string(options.max_consecutive_bad_frames) + ")");
      }
      ++run.dropped_frames;
      continue;
    }
    bad_in_a_row = 0;
    if (vo.isSunFrame(frame.sequence) && k < data.size()) {
      const Eigen::Vector3d sun_w =
          ephemeris ? data.ephemerisSunWorld()[k] : data.trueSun()[k].sun_w;
      if (sun_source) {
        auto m =
            sun_source->measure(frame.sequence, frame.trigger_time_ns, data.trueSun()[k].sun_c);
        if (m) vo.addSun({*m, sun_w});
      } else {
        // The prior from the last VO pose (Lalonde-VO); the colour camera is rectified to the
        // orientation of camera 0, so a direction in one is the same in the other.
        const Eigen::Matrix3d C_c_w = vo.T_w_c().linear().transpose();
        const bool colour = !frame.left_color.empty();
        sunfusion::ImageSunInput in{colour ? frame.left_color : frame.left,
                                    colour ? *data.colorCamera() : data.camera(),
                                    sunfusion::SunPrior{C_c_w * sun_w, C_c_w * data.worldUp()}};
        auto e = image_sun->estimate(in);
        if (!e) return e.status();
        ++run.sun_calls;
        run.sun_ms.push_back(e->time_ms);
        if (e->valid) {
          sunfusion::SunMeasurement m = e->measurement;
          m.sequence = frame.sequence;
          m.time_ns = frame.trigger_time_ns;
          vo.addSun({m, sun_w});
        }
      }
    }
    auto r = vo.process(frame);
    if (!r) return r.status();
    if (r->vo.status == vo::TrackingStatus::kLost) ++run.lost_frames;
    ms.push_back(r->times.total_ms);
    run.T_w_c.push_back(r->vo.T_w_c);
    run.times_ns.push_back(frame.trigger_time_ns);
    run.frame_index.push_back(k);
    run.self_calibration = r->self_calibration;
    if (options.pipeline.self_calibration.enabled) {
      run.self_calibration_log.push_back(r->self_calibration);
    }
    if (options.record_features) run.features.push_back(vo.lastFeatures());
    if (vo.options().use_sun || vo.options().vertical.enabled) {
      const sunfusion::SunWindowTerm& term = vo.sunTerm();
      ReplayRun::WalkSample w{term.tiltDriftDegPerFrame(), term.headingDriftDegPerFrame()};
      if (term.tiltByLikelihood()) {
        w.bank_tilt_deg = term.tiltBank().tiltWalk() * 180.0 / 3.141592653589793;
        w.noise_scale = term.tiltBank().noiseScale();
      }
      w.up_bias_x_deg = term.upBias().x() * 180.0 / 3.141592653589793;
      w.up_bias_z_deg = term.upBias().y() * 180.0 / 3.141592653589793;
      run.walk_log.push_back(w);
    }
  }
  run.gate = vo.sunCounters();
  run.vertical_gate = vo.verticalCounters();
  run.vertical_stats = vo.verticalStats();
  run.world_up_answers = vo.sunTerm().worldUpAlignment().used();
  run.world_up_tilt_deg = vo.sunTerm().worldUpAlignment().tiltDeg();
  run.world_up = vo.worldUp();
  run.start_tilt_judged = vo.sunTerm().startTiltJudged();
  run.start_levelled = vo.sunTerm().startLevelled();
  run.median_ms = metrics::percentile(ms, 0.5);
  run.p99_ms = metrics::percentile(ms, 0.99);
  return run;
}

}  // namespace sunvo::replay
