#include "sunvo/rover/app.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "rover_state.hpp"
#include "stages.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/rover/device_sources.hpp"
#include "sunvo/rover/fault_injection.hpp"
#include "sunvo/rover/mavlink_link.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo::rover {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The world frame and the first camera pose in it.
struct WorldSetup {
  geodesy::GeodeticPoint origin;
  Isometry3 T_w_c0 = Isometry3::Identity();
};

// world.init config: ENU at the configured origin, the camera's attitude from heading, pitch and
// roll. world.init oxts: the replay drive's own world (dataset seam: ENU at the first fix of the
// range, the first camera pose through the calibration chain).
Expected<WorldSetup> setUpWorld(const RoverConfig& c, const KittiReplaySource* kitti_source) {
  WorldSetup w;
  if (c.world.init == WorldInit::kOxts) {
    const dataset::Dataset& ds = kitti_source->dataset();
    if (!ds.origin()) {
      return invalidArgument("world.init: oxts, but " + ds.folder() + " has no GPS fixes");
    }
    w.origin = *ds.origin();
    w.T_w_c0 = ds.T_w_c0();
    return w;
  }
  w.origin = {c.world.latitude_deg, c.world.longitude_deg, c.world.altitude_m};
  // Optical axis from heading (from north, clockwise) and pitch; right stays level before roll.
  const double h = c.world.camera_heading_deg * kDeg, p = c.world.camera_pitch_deg * kDeg;
  const double r = c.world.camera_roll_deg * kDeg;
  const Eigen::Vector3d forward(std::sin(h) * std::cos(p), std::cos(h) * std::cos(p), std::sin(p));
  const Eigen::Vector3d right0(std::cos(h), -std::sin(h), 0.0);
  const Eigen::Vector3d down0 = forward.cross(right0);
  const Eigen::Vector3d right = std::cos(r) * right0 + std::sin(r) * down0;
  Eigen::Matrix3d C_w_c;
  C_w_c.col(0) = right;
  C_w_c.col(1) = forward.cross(right);
  C_w_c.col(2) = forward;
  w.T_w_c0.linear() = orthonormalize(C_w_c);
  return w;
}

// printf into a string (summary lines).
__attribute__((format(printf, 2, 3))) void appendf(std::string* out, const char* fmt, ...) {
  char line[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof(line), fmt, args);
  va_end(args);
  *out += line;
}

}  // namespace

// The wiring: what the stages share, the stages themselves and their threads.
struct RoverApp::Impl {
  explicit Impl(const RoverConfig& c)
      : config(c),
        period_ns(static_cast<TimeNs>(1e9 / c.trigger.rate_hz)),
        channels(c.queues),
        profiler(static_cast<std::size_t>(c.profiling.ring_frames)) {}

  RoverConfig config;
  TimeNs period_ns;
  Channels channels;
  Health health;
  runtime::LatencyProfiler profiler;
  AttitudeMailbox attitude;
  std::unique_ptr<TriggerSource> trigger;
  std::unique_ptr<FrameSource> source;
  InjectedFaults injected;  // source.faults: what the fault decorators injected
  std::shared_ptr<const ReplaySchedule> schedule;
  std::unique_ptr<runtime::FramePool> pool;
  std::unique_ptr<runtime::FramePool> sun_pool;  // only when the provider needs images
  std::unique_ptr<StageContext> ctx;
  std::unique_ptr<EstimatorStage> estimator;
  std::unique_ptr<CaptureStage> capture;
  std::unique_ptr<SunStage> sun;  // null without a sun provider
  std::unique_ptr<TelemetryStage> telemetry;

  std::vector<std::thread> threads;
  std::vector<std::string> thread_warnings;  // written by each thread before its loop
  std::atomic<int> threads_ready{0};
  TimeNs start_mono_ns = 0;
  TimeNs end_mono_ns = 0;

  Status openDevices(const RoverDevices& devices, bool needs_images);
};

Status RoverApp::Impl::openDevices(const RoverDevices& devices, bool needs_images) {
  if (config.source.type == SourceType::kKitti) {
    auto src = KittiReplaySource::open(config.source.kitti, needs_images);
    if (!src) return Status(src.status().code(), "source.kitti: " + src.status().message());
    const KittiSourceConfig& k = config.source.kitti;
    schedule =
        std::make_shared<ReplaySchedule>((*src)->rangeTimes(), k.first_frame, k.end, k.total_frames,
                                         period_ns, config.trigger.follow_recording);
    (*src)->setSchedule(schedule);
    source = std::move(*src);
  }
  // UTC of a monotonic stamp (strobe edges, V4L2 buffers): t_utc = t_mono + (UTC - monotonic),
  // the offset taken once here (the middle of two monotonic reads around the UTC read).
  const TimeNs mono_before = runtime::monotonicNs();
  const TimeNs utc_now = runtime::utcNowNs();
  const TimeNs mono_after = runtime::monotonicNs();
  const TimeNs utc_minus_mono_ns = utc_now - (mono_before + (mono_after - mono_before) / 2);
  if (config.source.type == SourceType::kV4l2) {
    if (devices.io == nullptr) return invalidArgument("source.type: v4l2 needs a SysIo");
    auto src = V4l2FrameSource::open(config, *devices.io, utc_minus_mono_ns);
    if (!src) return src.status();
    source = std::move(*src);
  }
  if (config.trigger.type == TriggerType::kGpio) {
    if (devices.gpio == nullptr) return invalidArgument("trigger.type: gpio needs a GpioApi");
    const auto wait_ns =
        static_cast<TimeNs>(config.trigger.timeout_factor * static_cast<double>(period_ns));
    auto trig = StrobeTrigger::open(config.trigger, wait_ns, *devices.gpio, utc_minus_mono_ns);
    if (!trig) return trig.status();
    trigger = std::move(*trig);
  }
  if (config.trigger.type == TriggerType::kSimulated) {
    if (!schedule) return invalidArgument("trigger.type: simulated needs a replay source");
    trigger = std::make_unique<SimulatedTrigger>(schedule);
  }
  if (!source || !trigger) {
    return invalidArgument("source.type / trigger.type: no such source in this build");
  }
  return Status::ok();
}

RoverDevices productionDevices() {
  return RoverDevices{&sysio::linuxSysIo(), &gpio::libgpiodApi()};
}

Expected<std::unique_ptr<RoverApp>> RoverApp::create(const RoverConfig& config,
                                                     std::unique_ptr<PoseLink> link,
                                                     const RoverDevices& devices) {
  SUNVO_RETURN_IF_ERROR(config.validate());
  auto impl = std::make_unique<Impl>(config);
  const bool needs_images = sunProviderNeedsImages(config.sun.provider);
  // The vertical cue runs in the sun thread on a copy of the grey left image.
  const bool cue = config.estimator.vertical.enabled;
  SUNVO_RETURN_IF_ERROR(impl->openDevices(devices, needs_images));
  const StereoCamera camera = impl->source->camera();
  if (camera.width != config.frames.width || camera.height != config.frames.height) {
    return invalidArgument(config.path + ": frames.width/height " +
                           std::to_string(config.frames.width) + "x" +
                           std::to_string(config.frames.height) + " differ from the camera's " +
                           std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  auto world = setUpWorld(config, dynamic_cast<const KittiReplaySource*>(impl->source.get()));
  if (!world) return world.status();
  if (config.source.faults.enabled()) {
    impl->trigger = std::make_unique<FaultyTrigger>(std::move(impl->trigger), config.source.faults,
                                                    impl->injected);
    impl->source = std::make_unique<FaultyFrameSource>(std::move(impl->source),
                                                       config.source.faults, impl->injected);
  }

  runtime::FramePoolOptions frame_options = config.frames;
  // Colour slots where the source delivers colour (KITTI replay; V4L2 YUYV with
  // source.v4l2.left_color); otherwise the image providers get the grey left image.
  const bool colour_frames =
      needs_images && (config.source.type != SourceType::kV4l2 || config.source.v4l2.left_color);
  frame_options.color = colour_frames;  // the capture thread copies left_color for the provider
  auto pool = runtime::FramePool::create(frame_options);
  if (!pool) return pool.status();
  impl->pool = std::move(*pool);
  auto provider = makeSunProvider(config.sun, camera);
  if (!provider) return provider.status();
  if ((*provider && (*provider)->needsImages()) || cue) {
    runtime::FramePoolOptions so = config.frames;
    so.pool_depth = config.queues.sun_requests + 2;
    so.color = colour_frames;
    auto sp = runtime::FramePool::create(so);
    if (!sp) return sp.status();
    impl->sun_pool = std::move(*sp);
  }

  // The stages.
  impl->ctx.reset(new StageContext{impl->config, impl->period_ns, impl->channels, impl->health,
                                   impl->profiler, *impl->pool, impl->sun_pool.get()});
  impl->estimator = std::make_unique<EstimatorStage>(*impl->ctx, impl->attitude);
  SUNVO_RETURN_IF_ERROR(impl->estimator->init(camera, world->T_w_c0, *provider != nullptr));
  impl->capture = std::make_unique<CaptureStage>(*impl->ctx, *impl->trigger, *impl->source,
                                                 impl->estimator->odometry());
  if (*provider || cue) {
    impl->sun =
        std::make_unique<SunStage>(*impl->ctx, impl->attitude, std::move(*provider), world->origin);
    if (cue) {
      const Status s = impl->sun->initVerticalCue(config.estimator.vertical.estimator, camera);
      if (!s.isOk()) return Status(s.code(), config.path + ": estimator.vertical." + s.message());
    }
  }
  std::unique_ptr<TumPoseLog> pose_log;
  if (!config.telemetry.pose_log.empty()) {
    auto opened = TumPoseLog::open(
        config.telemetry.pose_log,
        static_cast<std::size_t>(config.telemetry.pose_log_buffer_kb) * 1024,
        "sunvo_rover started " + formatUtcIso(runtime::utcNowNs()) + ", config " + config.path +
            "; t tx ty tz qx qy qz qw: frame UTC (s), camera position in the world (ENU, m), "
            "C_w_c");
    if (!opened)
      return Status(opened.status().code(), "telemetry.pose_log: " + opened.status().message());
    pose_log = std::move(*opened);
  }
  if (link) {
    link->setWorldOrigin(world->origin.lat_deg, world->origin.lon_deg, world->origin.alt_m);
    link->setCameraMount(bodyFromCamera(config.body, impl->source->C_c_l()));
  }
  impl->telemetry =
      std::make_unique<TelemetryStage>(*impl->ctx, std::move(link), std::move(pose_log));
  const auto warmup = static_cast<std::uint64_t>(config.realtime.warmup_frames);
  impl->capture->meter().setWarmup(warmup);
  impl->telemetry->meter().setWarmup(warmup);
  if (impl->sun) {
    impl->sun->meter().setWarmup(warmup /
                                 static_cast<std::uint64_t>(config.estimator.every_n_frames));
  }

  std::error_code ec;
  std::filesystem::create_directories(config.profiling.output_dir, ec);
  if (ec) {
    return ioError("profiling.output_dir: cannot create " + config.profiling.output_dir + ": " +
                   ec.message());
  }
  return std::unique_ptr<RoverApp>(new RoverApp(std::move(impl)));
}

RoverApp::RoverApp(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

RoverApp::~RoverApp() {
  requestStop();
  join();
}

std::vector<std::string> RoverApp::start() {
  Impl& s = *impl_;
  std::vector<std::string> warnings;
  if (s.config.rt.lock_memory) {
    const std::string w = runtime::lockProcessMemory();
    if (!w.empty()) warnings.push_back(w);
  }
  s.thread_warnings.assign(4, std::string());
  s.start_mono_ns = runtime::monotonicNs();
  auto launch = [&](int i, const char* name, const runtime::ThreadPolicy& p, auto run) {
    s.threads.emplace_back([&s, i, name, p, run] {
      s.thread_warnings[static_cast<std::size_t>(i)] = runtime::applyThreadPolicy(
          std::string("rt.threads.") + name, std::string("sunvo_") + name, p);
      s.threads_ready.fetch_add(1, std::memory_order_release);
      run();
    });
  };
  const ThreadsConfig& t = s.config.rt.threads;
  launch(0, "telemetry", t.telemetry, [&s] { s.telemetry->run(); });
  launch(1, "estimator", t.estimator, [&s] { s.estimator->run(); });
  if (s.sun) {
    launch(2, "sun", t.sun, [&s] { s.sun->run(); });
  } else {
    s.threads_ready.fetch_add(1);
    s.channels.sun_done.store(true);
  }
  launch(3, "capture", t.capture, [&s] { s.capture->run(); });
  while (s.threads_ready.load(std::memory_order_acquire) < 4) std::this_thread::yield();
  for (const std::string& w : s.thread_warnings) {
    if (!w.empty()) warnings.push_back(w);
  }
  return warnings;
}

void RoverApp::requestStop() {
  impl_->channels.requestStop();
}

bool RoverApp::finished() const {
  const Impl& s = *impl_;
  if (s.config.source.type == SourceType::kKitti && s.config.source.kitti.end == EndAction::kHold &&
      !s.channels.stop.load() && !sourceFailed()) {
    return false;
  }
  return s.channels.telemetry_done.load(std::memory_order_acquire);
}

void RoverApp::join() {
  for (std::thread& t : impl_->threads) {
    if (t.joinable()) t.join();
  }
  if (impl_->end_mono_ns == 0 && !impl_->threads.empty()) {
    impl_->end_mono_ns = runtime::monotonicNs();
  }
}

Expected<std::string> RoverApp::writeProfile(const std::string& tag) const {
  const Impl& s = *impl_;
  const auto frames = s.profiler.snapshot();
  const std::string base = s.config.profiling.output_dir + "/" + tag;
  SUNVO_RETURN_IF_ERROR(runtime::LatencyProfiler::writeCsv(base + "_latency.csv", frames));
  SUNVO_RETURN_IF_ERROR(runtime::LatencyProfiler::writeChromeTrace(base + "_trace.json", frames));
  const std::string text =
      runtime::LatencyProfiler::formatSummary(runtime::LatencyProfiler::summarize(frames));
  std::ofstream out(base + "_latency_summary.txt");
  out << text;
  if (!out) return ioError(base + "_latency_summary.txt: write failed");
  return text;
}

bool RoverApp::sourceFailed() const {
  return impl_->health.source_fault_stop.load(std::memory_order_acquire);
}

std::uint64_t RoverApp::framesProcessed() const {
  return impl_->health.frames_processed.load(std::memory_order_relaxed);
}

HealthSample RoverApp::healthSample(TimeNs now) const {
  const Impl& s = *impl_;
  const Health& h = s.health;
  auto g = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  HealthSample out;
  out.now_ns = now;
  out.utc_ns = runtime::utcNowNs();
  out.frames_grabbed = g(h.frames_grabbed);
  out.grab_errors = g(h.grab_errors);
  out.trigger_timeouts = g(h.trigger_timeouts);
  out.frames_processed = g(h.frames_processed);
  out.lost_frames = g(h.lost_frames);
  out.poses_published = g(h.poses_published);
  out.source_ended = s.channels.capture_done.load(std::memory_order_acquire);
  out.estimator_done = s.channels.estimator_done.load(std::memory_order_acquire);
  out.start_tilt_answers = h.start_tilt_answers.load(std::memory_order_acquire);
  out.start_tilt_mdeg = h.start_tilt_mdeg.load(std::memory_order_relaxed);
  out.start_tilt_removed = h.start_tilt_removed.load(std::memory_order_relaxed);
  return out;
}

std::string RoverApp::cameraName() const {
  const SourceConfig& src = impl_->config.source;
  if (src.type == SourceType::kKitti) return "replay " + src.kitti.drive_dir;
  if (src.v4l2.layout == v4l2::V4l2Layout::kSideBySide) return src.v4l2.left_device;
  return src.v4l2.left_device + " + " + src.v4l2.right_device;
}

std::string RoverApp::summary() const {
  const Impl& s = *impl_;
  const Health& h = s.health;
  auto g = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  std::string o;
  const TimeNs end = s.end_mono_ns != 0 ? s.end_mono_ns : runtime::monotonicNs();
  appendf(&o, "summary (%.1f s):\n", static_cast<double>(end - s.start_mono_ns) * 1e-9);
  const StereoCamera& cam = s.source->camera();
  appendf(&o, "  camera %dx%d: fu %.2f fv %.2f cu %.2f cv %.2f px, baseline %.4f m (%s)\n",
          cam.width, cam.height, cam.fu, cam.fv, cam.cu, cam.cv, cam.baseline_m,
          s.source->rectifies() ? "rectified here" : "frames as delivered");
  appendf(&o,
          "  triggers %" PRIu64 " (timeouts %" PRIu64 ", missed %" PRIu64 ", duplicate %" PRIu64
          "), frames grabbed %" PRIu64 " (grab errors %" PRIu64 ", pool exhausted %" PRIu64 ")\n",
          g(h.triggers), g(h.trigger_timeouts), g(h.triggers_missed), g(h.triggers_duplicate),
          g(h.frames_grabbed), g(h.grab_errors), g(h.pool_exhausted));
  if (s.config.source.faults.enabled()) {
    appendf(&o,
            "  faults injected (source.faults): missed triggers %" PRIu64 ", bad frames %" PRIu64
            ", dark frames %" PRIu64 "\n",
            g(s.injected.missed_triggers), g(s.injected.bad_frames), g(s.injected.dark_frames));
  }
  appendf(&o, "  grab errors in a row: at most %" PRIu64 " (limit %d)%s\n",
          g(h.grab_errors_in_a_row_max), s.config.source.max_consecutive_bad_frames,
          h.source_fault_stop.load() ? ": capture stopped, the source fault persisted" : "");
  appendf(&o,
          "  frames processed %" PRIu64 ", estimator errors %" PRIu64 ", dropped at stop %" PRIu64
          ", late (age > 1 period) %" PRIu64 ", solver budget shrunk %" PRIu64 "\n",
          g(h.frames_processed), g(h.estimator_errors), g(h.frames_dropped_at_stop),
          g(h.late_frames), g(h.shrunk_budgets));
  auto queue = [&](const char* name, const runtime::QueueCounters& c) {
    appendf(&o,
            "  queue %-12s cap %" PRIu64 ": pushed %" PRIu64 ", dropped %" PRIu64
            ", popped %" PRIu64 ", high-water %" PRIu64 "\n",
            name, c.capacity, c.pushed, c.dropped, c.popped, c.high_water);
  };
  queue("frames", s.channels.frames.counters());
  queue("sun_requests", s.channels.sun_requests.counters());
  queue("sun_results", s.channels.sun_results.counters());
  queue("poses", s.channels.poses.counters());
  appendf(&o,
          "  poses published %" PRIu64 ", deadline misses (trigger -> last byte > %.0f ms) %" PRIu64
          ", heartbeats %" PRIu64 ", link errors %" PRIu64 "\n",
          g(h.poses_published), s.config.realtime.deadline_ms, g(h.deadline_misses),
          g(h.heartbeats), g(h.link_errors));
  appendf(&o, "  tracking: losses %" PRIu64 ", recoveries %" PRIu64 ", lost frames %" PRIu64 "\n",
          g(h.tracking_losses), g(h.recoveries), g(h.lost_frames));
  if (s.config.estimator.pipeline.self_calibration.enabled) {
    constexpr double kUradToDeg = 180.0 / 3.141592653589793 * 1e-6;
    appendf(&o, "  self-calibration: right pitch %+.4f deg, roll %+.4f deg, resets %" PRIu64 "\n",
            kUradToDeg * static_cast<double>(h.self_cal_pitch_urad.load()),
            kUradToDeg * static_cast<double>(h.self_cal_roll_urad.load()), g(h.self_cal_resets));
  }
  appendf(&o,
          "  sun (%s): requests %" PRIu64 ", measurements %" PRIu64 ", errors %" PRIu64
          ", late %" PRIu64 ", accepted %" PRIu64 ", rejected %" PRIu64 "\n",
          s.sun && s.sun->provider() ? s.sun->provider()->name() : "none", g(h.sun_requests),
          g(h.sun_measurements), g(h.sun_errors), g(h.sun_late), g(h.sun_accepted),
          g(h.sun_rejected));
  if (s.config.estimator.vertical.enabled) {
    appendf(&o,
            "  vertical cue (sun thread): calls %" PRIu64 ", valid %" PRIu64
            ", refused images %" PRIu64 ", accepted %" PRIu64 ", rejected %" PRIu64 "\n",
            g(h.vertical_calls), g(h.vertical_valid), g(h.vertical_errors), g(h.vertical_accepted),
            g(h.vertical_rejected));
  }
  if (s.config.estimator.fusion.levelsStartTilt()) {
    if (h.start_tilt_answers.load() > 0) {
      appendf(&o, "  start tilt: %.3f deg measured from %" PRIu64 " cue answers %s\n",
              1e-3 * static_cast<double>(h.start_tilt_mdeg.load()), g(h.start_tilt_answers),
              sunfusion::startTiltOutcome(h.start_tilt_removed.load()));
    } else {
      o += "  start tilt: not measured (fewer than 3 cue answers within "
           "fusion.start_tilt_max_deg of the configured tilt)\n";
    }
  }
  if (s.telemetry->link() != nullptr)
    o += "  serial: " + s.telemetry->link()->countersText() + "\n";
  if (const TumPoseLog* log = s.telemetry->poseLog()) {
    appendf(&o, "  pose log %s: %" PRIu64 " poses, errors %" PRIu64 "\n", log->path().c_str(),
            log->lines(), g(h.pose_log_errors));
  }
  if (runtime::allocationProbeInstalled()) {
    auto meter = [&](const char* name, const runtime::AllocationMeter& m) {
      appendf(&o,
              "  allocations after warm-up, %-9s %" PRIu64 " in %" PRIu64
              " frames (%.2f per frame)\n",
              name, m.allocationsAfterWarmup(), m.framesMeasured(), m.perFrame());
    };
    meter("capture", s.capture->meter());
    meter("estimator", s.estimator->meter());
    if (s.sun) meter("sun", s.sun->meter());
    meter("telemetry", s.telemetry->meter());
  } else {
    o += "  allocations: not measured (no allocation probe in this executable)\n";
  }
  const auto frames = s.profiler.snapshot();
  o += "  latency (" + std::to_string(frames.size()) + " frames in the profiler ring):\n";
  const std::string table =
      runtime::LatencyProfiler::formatSummary(runtime::LatencyProfiler::summarize(frames));
  std::size_t pos = 0;
  while (pos < table.size()) {
    const std::size_t nl = table.find('\n', pos);
    o += "    " + table.substr(pos, nl - pos) + "\n";
    pos = nl == std::string::npos ? table.size() : nl + 1;
  }
  return o;
}

}  // namespace sunvo::rover
