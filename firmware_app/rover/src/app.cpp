#include "sunvo/rover/app.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sunvo/core/geometry.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/oxts.hpp"
#include "sunvo/pipeline/stereo_visual_odometry.hpp"
#include "sunvo/rover/device_sources.hpp"
#include "sunvo/runtime/allocation_meter.hpp"
#include "sunvo/runtime/clock.hpp"
#include "sunvo/runtime/deadline.hpp"
#include "sunvo/runtime/event_count.hpp"
#include "sunvo/runtime/latency_profiler.hpp"
#include "sunvo/runtime/spsc_queue.hpp"
#include "sunvo/sun/spa.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"

namespace sunvo::rover {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr std::uint32_t kNoImage = 0xFFFFFFFFu;

struct FrameTicket {
  std::uint32_t slot = 0;
  std::uint64_t sequence = 0;
};

struct SunRequest {
  std::uint64_t sequence = 0;
  std::int64_t source_index = 0;
  TimeNs utc_ns = 0;
  std::uint32_t image_slot = kNoImage;  // slot of the sun image pool, or kNoImage
};

// The sun thread's answer (plain arrays: it travels through an SPSC ring).
struct SunResult {
  std::uint64_t sequence = 0;
  TimeNs utc_ns = 0;
  bool has_measurement = false;
  bool azimuth_only = false;
  double sun_c[3] = {0, 0, 1};
  double sigma = 0.1;
  double sun_w[3] = {0, 0, 1};
};

// The world frame and the first camera pose in it.
struct WorldSetup {
  geodesy::GeodeticPoint origin;
  Isometry3 T_w_c0 = Isometry3::Identity();
};

Expected<WorldSetup> setUpWorld(const RoverConfig& c, const KittiReplaySource* kitti_source) {
  WorldSetup w;
  if (c.world.init == WorldInit::kConfig) {
    w.origin = {c.world.latitude_deg, c.world.longitude_deg, c.world.altitude_m};
    // Optical axis from heading (from north, clockwise) and pitch; right stays level before roll.
    const double h = c.world.camera_heading_deg * kDeg, p = c.world.camera_pitch_deg * kDeg;
    const double r = c.world.camera_roll_deg * kDeg;
    const Eigen::Vector3d forward(std::sin(h) * std::cos(p), std::cos(h) * std::cos(p),
                                  std::sin(p));
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
  // From the drive's OXTS record of the first frame through the calibration chain, as the
  // replay (hil/tools/replay) does: ENU at that fix, camera 0 = T_w_imu * T_imu_cam0rect.
  const std::string& drive = c.source.kitti.drive_dir;
  auto oxts = kitti::readOxtsRecord(kitti::oxtsRecordPath(drive, c.source.kitti.first_frame));
  if (!oxts) return Status(oxts.status().code(), "world.init oxts: " + oxts.status().message());
  w.origin = {oxts->lat, oxts->lon, oxts->alt};
  auto world = geodesy::LocalEnuFrame::create(w.origin);
  if (!world) return world.status();
  auto calib = kitti::readRawCalibration(kitti_source->calibrationDir());
  if (!calib) return calib.status();
  const Isometry3 T_c0rect_imu =
      geodesy::cam0RectFromImu(calib->cam_to_cam.cameras[0].R_rect, calib->velo_to_cam.transform(),
                               calib->imu_to_velo.transform());
  auto T_w_imu0 = geodesy::imuPoseInWorld(*world, w.origin, oxts->roll, oxts->pitch, oxts->yaw);
  if (!T_w_imu0) return T_w_imu0.status();
  w.T_w_c0 = geodesy::cam0PoseInWorld(*T_w_imu0, T_c0rect_imu);
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

struct Health {
  std::atomic<std::uint64_t> triggers{0};
  std::atomic<std::uint64_t> trigger_timeouts{0};
  std::atomic<std::uint64_t> triggers_missed{0};
  std::atomic<std::uint64_t> triggers_duplicate{0};
  std::atomic<std::uint64_t> frames_grabbed{0};
  std::atomic<std::uint64_t> grab_errors{0};
  std::atomic<std::uint64_t> pool_exhausted{0};
  std::atomic<std::uint64_t> frames_processed{0};
  std::atomic<std::uint64_t> frames_dropped_at_stop{0};
  std::atomic<std::uint64_t> estimator_errors{0};
  std::atomic<std::uint64_t> late_frames{0};  // dequeued more than one period after the trigger
  std::atomic<std::uint64_t> shrunk_budgets{0};
  std::atomic<std::uint64_t> tracking_losses{0};
  std::atomic<std::uint64_t> recoveries{0};
  std::atomic<std::uint64_t> lost_frames{0};
  std::atomic<std::uint64_t> sun_requests{0};
  std::atomic<std::uint64_t> sun_measurements{0};
  std::atomic<std::uint64_t> sun_errors{0};
  std::atomic<std::uint64_t> sun_late{0};  // the estimator did not get it in time
  std::atomic<std::uint64_t> sun_accepted{0};
  std::atomic<std::uint64_t> sun_rejected{0};
  std::atomic<std::uint64_t> poses_published{0};
  std::atomic<std::uint64_t> deadline_misses{0};
  std::atomic<std::uint64_t> heartbeats{0};
  std::atomic<std::uint64_t> link_errors{0};
};

}  // namespace

struct RoverApp::Impl {
  RoverConfig config;
  TimeNs period_ns = 0;
  std::unique_ptr<TriggerSource> trigger;
  std::unique_ptr<FrameSource> source;
  std::shared_ptr<const ReplaySchedule> schedule;
  std::unique_ptr<SunProvider> sun_provider;
  // The latest camera attitude q_w_c (w, x, y, z) for the image estimators' prior, written by the
  // estimator thread, read by the sun thread: a seqlock (odd = being written), no allocation.
  std::atomic<std::uint64_t> attitude_seq{0};
  std::array<std::atomic<double>, 4> q_w_c{};
  void publishAttitude(const Eigen::Quaterniond& q);
  bool latestAttitude(Eigen::Quaterniond* q) const;
  std::unique_ptr<PoseLink> link;
  WorldSetup world;
  StereoCamera camera;

  std::unique_ptr<runtime::FramePool> pool;
  std::unique_ptr<runtime::FramePool> sun_pool;  // only when the provider needs images
  runtime::SpscQueue<FrameTicket> frames_q;
  runtime::SpscQueue<SunRequest> sun_req_q;
  runtime::SpscQueue<SunResult> sun_res_q;
  runtime::SpscQueue<PoseRecord> poses_q;
  runtime::EventCount frames_ev, sun_req_ev, sun_res_ev, poses_ev;
  runtime::LatencyProfiler profiler;
  runtime::AllocationMeter capture_meter, estimator_meter, sun_meter, telemetry_meter;

  pipeline::StereoVisualOdometry vo;
  sunfusion::SunWindowTerm sun_term;

  Health health;
  std::atomic<bool> stop{false};
  std::atomic<bool> capture_done{false};
  std::atomic<bool> estimator_done{false};
  std::atomic<bool> sun_done{false};
  std::atomic<bool> telemetry_done{false};
  std::vector<std::thread> threads;
  std::vector<std::string> thread_warnings;  // written by each thread before its loop
  std::atomic<int> threads_ready{0};
  TimeNs start_mono_ns = 0;
  TimeNs end_mono_ns = 0;

  explicit Impl(const RoverConfig& c)
      : config(c),
        frames_q(static_cast<std::size_t>(c.queues.frames), runtime::QueuePolicy::kDropOldest),
        sun_req_q(static_cast<std::size_t>(c.queues.sun_requests),
                  runtime::QueuePolicy::kDropOldest),
        sun_res_q(static_cast<std::size_t>(c.queues.sun_results),
                  runtime::QueuePolicy::kDropOldest),
        poses_q(static_cast<std::size_t>(c.queues.poses), runtime::QueuePolicy::kDropOldest),
        profiler(static_cast<std::size_t>(c.profiling.ring_frames)) {
    const auto warmup = static_cast<std::uint64_t>(c.estimator.warmup_frames);
    capture_meter.setWarmup(warmup);
    estimator_meter.setWarmup(warmup);
    sun_meter.setWarmup(warmup / static_cast<std::uint64_t>(c.sun.every_n_frames));
    telemetry_meter.setWarmup(warmup);
  }

  bool isSunFrame(std::uint64_t seq) const {
    return sun_provider && seq > 0 &&
           seq % static_cast<std::uint64_t>(config.sun.every_n_frames) == 0;
  }

  void setThreadPolicy(const std::string& name, const runtime::ThreadPolicy& p,
                       std::string* warning) {
    *warning = runtime::applyThreadPolicy("rt.threads." + name, "sunvo_" + name, p);
  }

  void captureLoop();
  void estimatorLoop();
  void sunLoop();
  void telemetryLoop();
  void takeSunResults(std::uint64_t waiting_for, bool* got);
};

void RoverApp::Impl::captureLoop() {
  TriggerMonitor monitor(period_ns);
  const auto timeout_ns =
      static_cast<TimeNs>(config.trigger.timeout_factor * static_cast<double>(period_ns));
  while (!stop.load(std::memory_order_acquire)) {
    TriggerEvent ev;
    const Status st = trigger->wait(timeout_ns, &ev);
    if (st.code() == StatusCode::kTimeout) {
      health.trigger_timeouts.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (st.code() == StatusCode::kNotFound) break;  // the replay's last frame has been triggered
    if (!st.isOk()) {
      health.trigger_timeouts.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    health.triggers.fetch_add(1, std::memory_order_relaxed);
    monitor.observe(ev.mono_ns);
    health.triggers_missed.store(monitor.missed(), std::memory_order_relaxed);
    health.triggers_duplicate.store(monitor.duplicates(), std::memory_order_relaxed);

    std::uint32_t index = 0;
    if (!pool->acquire(&index)) {
      health.pool_exhausted.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    runtime::FrameSlot& slot = pool->slot(index);
    profiler.begin(ev.sequence, ev.utc_ns, ev.mono_ns);
    if (!source->grab(ev, slot).isOk()) {
      health.grab_errors.fetch_add(1, std::memory_order_relaxed);
      pool->recycle(index);
      continue;
    }
    const TimeNs grabbed = runtime::monotonicNs();
    slot.meta.sequence = ev.sequence;
    slot.meta.trigger_mono_ns = ev.mono_ns;
    slot.meta.trigger_utc_ns = ev.utc_ns;
    slot.meta.grab_mono_ns = grabbed;
    profiler.stamp(ev.sequence, runtime::Stamp::kGrabEnd, grabbed);
    health.frames_grabbed.fetch_add(1, std::memory_order_relaxed);

    if (isSunFrame(ev.sequence)) {
      SunRequest req{ev.sequence, slot.meta.source_index, ev.utc_ns, kNoImage};
      if (sun_pool && sun_pool->acquire(&req.image_slot)) {
        StereoFrame& dst = sun_pool->slot(req.image_slot).frame;
        slot.frame.left.copyTo(dst.left);
        if (!slot.frame.left_color.empty()) slot.frame.left_color.copyTo(dst.left_color);
      }
      SunRequest dropped;
      bool did_drop = false;
      sun_req_q.push(req, &dropped, &did_drop);
      if (did_drop && dropped.image_slot != kNoImage) sun_pool->recycle(dropped.image_slot);
      health.sun_requests.fetch_add(1, std::memory_order_relaxed);
      sun_req_ev.notify();
    }

    FrameTicket dropped;
    bool did_drop = false;
    frames_q.push({index, ev.sequence}, &dropped, &did_drop);
    if (did_drop) pool->recycle(dropped.slot);
    frames_ev.notify();
    capture_meter.frameDone();
  }
  capture_done.store(true, std::memory_order_release);
  frames_ev.notify();
  sun_req_ev.notify();
}

void RoverApp::Impl::takeSunResults(std::uint64_t waiting_for, bool* got) {
  SunResult r;
  while (sun_res_q.pop(&r)) {
    if (r.sequence == waiting_for) *got = true;
    if (!r.has_measurement) continue;
    sunfusion::SunObservation obs;
    obs.measurement.time_ns = r.utc_ns;
    obs.measurement.sequence = r.sequence;
    obs.measurement.kind = r.azimuth_only ? sunfusion::SunMeasurementKind::kAzimuthOnly
                                          : sunfusion::SunMeasurementKind::kFull3d;
    obs.measurement.sun_c = Eigen::Vector3d(r.sun_c[0], r.sun_c[1], r.sun_c[2]);
    obs.measurement.sigma = r.sigma;
    obs.sun_w = Eigen::Vector3d(r.sun_w[0], r.sun_w[1], r.sun_w[2]);
    sun_term.addObservation(obs);
  }
}

void RoverApp::Impl::estimatorLoop() {
  const EstimatorConfig& ec = config.estimator;
  const auto sun_wait_ns = static_cast<TimeNs>(config.sun.wait_ms * 1e6);
  double front_ms_mean = 0.0;  // running mean of front end + RANSAC, ms
  bool have_prev = false;
  Isometry3 T_w_prev = Isometry3::Identity();
  TimeNs t_prev_ns = 0;
  std::uint8_t reset_counter = 0;
  vo::TrackingStatus last_status = vo::TrackingStatus::kInitializing;
  for (;;) {
    const std::uint32_t key = frames_ev.prepare();
    FrameTicket ticket;
    if (!frames_q.pop(&ticket)) {
      if (stop.load(std::memory_order_acquire) || capture_done.load(std::memory_order_acquire)) {
        if (frames_q.size() == 0) break;
        continue;
      }
      frames_ev.wait(key, 50'000'000);
      continue;
    }
    if (stop.load(std::memory_order_acquire)) {  // shutting down: queued frames are dropped
      pool->release(ticket.slot);
      health.frames_dropped_at_stop.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    runtime::FrameSlot& slot = pool->slot(ticket.slot);
    const std::uint64_t seq = slot.meta.sequence;
    const TimeNs t_start = runtime::monotonicNs();
    profiler.stamp(seq, runtime::Stamp::kEstimatorStart, t_start);

    // Solver budget from the frame's age.
    const TimeNs age = t_start - slot.meta.trigger_mono_ns;
    if (age > period_ns) health.late_frames.fetch_add(1, std::memory_order_relaxed);
    const double budget_ms =
        runtime::solverBudgetMs(ec.deadline_ms, static_cast<double>(age) * 1e-6, front_ms_mean,
                                ec.publish_margin_ms, ec.min_solver_time_ms, ec.max_solver_time_ms);
    if (budget_ms < ec.max_solver_time_ms) {
      health.shrunk_budgets.fetch_add(1, std::memory_order_relaxed);
    }
    vo.odometry().window().setSolverTimeBudget(budget_ms * 1e-3);
    profiler.setSolverBudget(seq, budget_ms);

    // Sun results; a sun frame waits a bounded time for its own.
    bool got = false;
    takeSunResults(seq, &got);
    if (isSunFrame(seq) && !got) {
      const TimeNs until = runtime::monotonicNs() + sun_wait_ns;
      for (;;) {
        const std::uint32_t skey = sun_res_ev.prepare();
        takeSunResults(seq, &got);
        const TimeNs now = runtime::monotonicNs();
        if (got || now >= until) break;
        sun_res_ev.wait(skey, until - now);
      }
      if (!got) health.sun_late.fetch_add(1, std::memory_order_relaxed);
    }

    auto r = vo.process(slot.frame);
    const TimeNs t_end = runtime::monotonicNs();
    const TimeNs trigger_mono = slot.meta.trigger_mono_ns;
    const TimeNs utc = slot.meta.trigger_utc_ns;
    pool->release(ticket.slot);
    if (!r) {
      health.estimator_errors.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    const TimeNs fe_end = t_start + static_cast<TimeNs>(r->times.frontend_ms * 1e6);
    const TimeNs ransac_end = fe_end + static_cast<TimeNs>(r->times.ransac_ms * 1e6);
    profiler.stamp(seq, runtime::Stamp::kFrontendEnd, std::min(fe_end, t_end));
    profiler.stamp(seq, runtime::Stamp::kRansacEnd, std::min(ransac_end, t_end));
    profiler.stamp(seq, runtime::Stamp::kWindowEnd, t_end);
    const double fr = r->times.frontend_ms + r->times.ransac_ms;
    front_ms_mean = have_prev ? 0.9 * front_ms_mean + 0.1 * fr : fr;

    const vo::TrackingStatus status = r->vo.status;
    if (status == vo::TrackingStatus::kLost) {
      health.lost_frames.fetch_add(1, std::memory_order_relaxed);
      if (last_status != vo::TrackingStatus::kLost) {
        health.tracking_losses.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (status == vo::TrackingStatus::kRecovered) {
      health.recoveries.fetch_add(1, std::memory_order_relaxed);
      ++reset_counter;
    }
    const sunfusion::GateCounters& gate = sun_term.counters();
    health.sun_accepted.store(gate.accepted, std::memory_order_relaxed);
    health.sun_rejected.store(gate.total() - gate.accepted, std::memory_order_relaxed);

    PoseRecord pose;
    pose.sequence = seq;
    pose.utc_ns = utc;
    pose.trigger_mono_ns = trigger_mono;
    const Isometry3& T_w_c = r->vo.T_w_c;
    const Eigen::Quaterniond q(T_w_c.linear());
    for (int i = 0; i < 3; ++i) pose.p_w[i] = T_w_c.translation()[i];
    pose.q_w_c[0] = q.x();
    pose.q_w_c[1] = q.y();
    pose.q_w_c[2] = q.z();
    pose.q_w_c[3] = q.w();
    const double dt = toSeconds(utc - t_prev_ns);
    const bool tracking_pair = status == vo::TrackingStatus::kTracking;
    if (have_prev && dt > 0.0 && tracking_pair) {
      const Eigen::Vector3d v = (T_w_c.translation() - T_w_prev.translation()) / dt;
      // omega in camera k: C_km1_k = C_k_km1^T = Exp(omega_c dt).
      const Eigen::Vector3d w = logSO3(r->vo.T_k_km1.linear().transpose()) / dt;
      for (int i = 0; i < 3; ++i) {
        pose.v_w[i] = v[i];
        pose.omega_c[i] = w[i];
      }
      pose.velocity_valid = v.allFinite() && w.allFinite();
    }
    pose.tracking = static_cast<int>(status);
    pose.ransac_inliers = r->vo.ransac_inliers;
    pose.reset_counter = reset_counter;
    poses_q.push(pose);  // drop-oldest: a stale pose is of no use
    poses_ev.notify();
    health.frames_processed.fetch_add(1, std::memory_order_relaxed);
    have_prev = true;
    T_w_prev = T_w_c;
    if (sun_provider) publishAttitude(q);
    t_prev_ns = utc;
    last_status = status;
    estimator_meter.frameDone();
  }
  estimator_done.store(true, std::memory_order_release);
  poses_ev.notify();
}

void RoverApp::Impl::sunLoop() {
  sun::SpaOptions spa;
  spa.latitude_deg = world.origin.lat_deg;
  spa.longitude_deg = world.origin.lon_deg;
  spa.elevation_m = world.origin.alt_m;
  for (;;) {
    const std::uint32_t key = sun_req_ev.prepare();
    SunRequest req;
    if (!sun_req_q.pop(&req)) {
      if (stop.load(std::memory_order_acquire) || estimator_done.load(std::memory_order_acquire)) {
        break;
      }
      sun_req_ev.wait(key, 100'000'000);
      continue;
    }
    profiler.stamp(req.sequence, runtime::Stamp::kSunStart, runtime::monotonicNs());
    SunResult res;
    res.sequence = req.sequence;
    res.utc_ns = req.utc_ns;
    auto sp = sun::computeSolarPosition(req.utc_ns, spa);
    SunQuery query;
    query.sequence = req.sequence;
    query.source_index = req.source_index;
    query.utc_ns = req.utc_ns;
    if (req.image_slot != kNoImage) query.images = &sun_pool->slot(req.image_slot).frame;
    Eigen::Quaterniond q_w_c_now;
    if (sp && latestAttitude(&q_w_c_now)) {
      // Prior in the camera: sun_c = R_c_w sun_w, up_c = R_c_w (0, 0, 1) with ENU world (z up).
      // The attitude is the last published pose's, one or a few frames before this one.
      const Eigen::Matrix3d R_c_w = q_w_c_now.toRotationMatrix().transpose();
      sunfusion::SunPrior prior;
      prior.sun_c = (R_c_w * sp->sun_enu).normalized();
      prior.up_c = R_c_w * Eigen::Vector3d::UnitZ();
      query.prior = prior;
    }
    auto m = sun_provider->measure(query);
    if (req.image_slot != kNoImage) sun_pool->release(req.image_slot);
    if (!sp || !m) {
      health.sun_errors.fetch_add(1, std::memory_order_relaxed);
    } else if (m->has_value()) {
      const sunfusion::SunMeasurement& meas = **m;
      res.has_measurement = meas.sun_c.allFinite();
      res.azimuth_only = meas.kind == sunfusion::SunMeasurementKind::kAzimuthOnly;
      res.sigma = meas.sigma;
      for (int i = 0; i < 3; ++i) {
        res.sun_c[i] = meas.sun_c[i];
        res.sun_w[i] = sp->sun_enu[i];
      }
      if (res.has_measurement) health.sun_measurements.fetch_add(1, std::memory_order_relaxed);
    }
    sun_res_q.push(res);
    sun_res_ev.notify();
    profiler.stamp(req.sequence, runtime::Stamp::kSunEnd, runtime::monotonicNs());
    sun_meter.frameDone();
  }
  sun_done.store(true, std::memory_order_release);
}

void RoverApp::Impl::publishAttitude(const Eigen::Quaterniond& q) {
  const std::uint64_t s0 = attitude_seq.load(std::memory_order_relaxed);
  attitude_seq.store(s0 + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  q_w_c[0].store(q.w(), std::memory_order_relaxed);
  q_w_c[1].store(q.x(), std::memory_order_relaxed);
  q_w_c[2].store(q.y(), std::memory_order_relaxed);
  q_w_c[3].store(q.z(), std::memory_order_relaxed);
  attitude_seq.store(s0 + 2, std::memory_order_release);
}

bool RoverApp::Impl::latestAttitude(Eigen::Quaterniond* q) const {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t s0 = attitude_seq.load(std::memory_order_acquire);
    if (s0 == 0) return false;  // no pose yet
    if (s0 & 1U) continue;      // being written
    const double w = q_w_c[0].load(std::memory_order_relaxed);
    const double x = q_w_c[1].load(std::memory_order_relaxed);
    const double y = q_w_c[2].load(std::memory_order_relaxed);
    const double z = q_w_c[3].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (attitude_seq.load(std::memory_order_relaxed) != s0) continue;
    *q = Eigen::Quaterniond(w, x, y, z);
    return std::isfinite(q->norm()) && q->norm() > 0.5;
  }
  return false;
}

void RoverApp::Impl::telemetryLoop() {
  const auto hb_period_ns = static_cast<TimeNs>(1e9 / config.telemetry.heartbeat_hz);
  const auto deadline_ns = static_cast<TimeNs>(config.estimator.deadline_ms * 1e6);
  TimeNs next_hb = runtime::monotonicNs();
  bool pending = false;  // a pose whose last byte has not left yet
  std::uint64_t pending_seq = 0;
  TimeNs pending_trigger = 0;
  TimeNs drain_until = 0;  // after the estimator finished: flush for at most this long
  auto complete = [&](TimeNs last_byte) {
    profiler.stamp(pending_seq, runtime::Stamp::kLastByte, last_byte);
    if (last_byte - pending_trigger > deadline_ns) {
      health.deadline_misses.fetch_add(1, std::memory_order_relaxed);
    }
    health.poses_published.fetch_add(1, std::memory_order_relaxed);
    pending = false;
    telemetry_meter.frameDone();
  };
  for (;;) {
    const std::uint32_t key = poses_ev.prepare();
    PoseRecord pose;
    while (poses_q.pop(&pose)) {
      const TimeNs now = runtime::monotonicNs();
      profiler.stamp(pose.sequence, runtime::Stamp::kPublishStart, now);
      if (pending) complete(link ? link->lastByteWrittenNs() : now);  // superseded while pending
      pending = true;
      pending_seq = pose.sequence;
      pending_trigger = pose.trigger_mono_ns;
      if (link && !link->sendPose(pose, now).isOk()) {
        health.link_errors.fetch_add(1, std::memory_order_relaxed);
      }
      if (!link) complete(runtime::monotonicNs());
    }
    const TimeNs now = runtime::monotonicNs();
    if (link) {
      if (!link->service(now).isOk()) health.link_errors.fetch_add(1, std::memory_order_relaxed);
      if (pending && link->drained()) complete(link->lastByteWrittenNs());
      if (now >= next_hb) {
        if (!link->sendHeartbeat(now).isOk()) {
          health.link_errors.fetch_add(1, std::memory_order_relaxed);
        }
        health.heartbeats.fetch_add(1, std::memory_order_relaxed);
        next_hb += hb_period_ns;
        if (next_hb < now) next_hb = now + hb_period_ns;
      }
    }
    const bool upstream_done = estimator_done.load(std::memory_order_acquire);
    if (upstream_done && poses_q.size() == 0) {
      if (drain_until == 0) drain_until = now + 200'000'000;  // 200 ms to flush the port
      if (!pending || now >= drain_until) break;
    }
    TimeNs sleep_ns = std::max<TimeNs>(next_hb - now, 0);
    if (pending) sleep_ns = std::min<TimeNs>(sleep_ns, 1'000'000);  // poll the port each ms
    sleep_ns = std::clamp<TimeNs>(sleep_ns, 100'000, 100'000'000);
    poses_ev.wait(key, sleep_ns);
  }
  telemetry_done.store(true, std::memory_order_release);
}

RoverDevices productionDevices() {
  return RoverDevices{&sysio::linuxSysIo(), &gpio::libgpiodApi()};
}

Expected<std::unique_ptr<RoverApp>> RoverApp::create(const RoverConfig& config,
                                                     std::unique_ptr<PoseLink> link,
                                                     const RoverDevices& devices) {
  SUNVO_RETURN_IF_ERROR(config.validate());
  auto impl = std::make_unique<Impl>(config);
  impl->period_ns = static_cast<TimeNs>(1e9 / config.trigger.rate_hz);
  impl->link = std::move(link);

  // Source and trigger.
  const bool needs_images = sunProviderNeedsImages(config.sun.provider);
  const KittiReplaySource* kitti_source = nullptr;
  if (config.source.type == SourceType::kKitti) {
    auto src = KittiReplaySource::open(config.source.kitti, needs_images);
    if (!src) return Status(src.status().code(), "source.kitti: " + src.status().message());
    const KittiSourceConfig& k = config.source.kitti;
    impl->schedule =
        std::make_shared<ReplaySchedule>((*src)->rangeTimes(), k.first_frame, k.end, k.total_frames,
                                         impl->period_ns, config.trigger.follow_recording);
    (*src)->setSchedule(impl->schedule);
    kitti_source = src->get();
    impl->source = std::move(*src);
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
    impl->source = std::move(*src);
  }
  if (config.trigger.type == TriggerType::kGpio) {
    if (devices.gpio == nullptr) return invalidArgument("trigger.type: gpio needs a GpioApi");
    const auto wait_ns =
        static_cast<TimeNs>(config.trigger.timeout_factor * static_cast<double>(impl->period_ns));
    auto trig = StrobeTrigger::open(config.trigger, wait_ns, *devices.gpio, utc_minus_mono_ns);
    if (!trig) return trig.status();
    impl->trigger = std::move(*trig);
  }
  if (config.trigger.type == TriggerType::kSimulated) {
    if (!impl->schedule) return invalidArgument("trigger.type: simulated needs a replay source");
    impl->trigger = std::make_unique<SimulatedTrigger>(impl->schedule);
  }
  if (!impl->source || !impl->trigger) {
    return invalidArgument("source.type / trigger.type: no such source in this build");
  }
  impl->camera = impl->source->camera();
  if (impl->camera.width != config.frames.width || impl->camera.height != config.frames.height) {
    return invalidArgument(
        config.path + ": frames.width/height " + std::to_string(config.frames.width) + "x" +
        std::to_string(config.frames.height) + " differ from the camera's " +
        std::to_string(impl->camera.width) + "x" + std::to_string(impl->camera.height));
  }
  auto world = setUpWorld(config, kitti_source);
  if (!world) return world.status();
  impl->world = *world;

  runtime::FramePoolOptions frame_options = config.frames;
  frame_options.color = needs_images;  // the capture thread copies left_color for the provider
  auto pool = runtime::FramePool::create(frame_options);
  if (!pool) return pool.status();
  impl->pool = std::move(*pool);

  auto provider = makeSunProvider(config.sun, impl->camera);
  if (!provider) return provider.status();
  impl->sun_provider = std::move(*provider);
  if (impl->sun_provider && impl->sun_provider->needsImages()) {
    runtime::FramePoolOptions so = config.frames;
    so.depth = config.queues.sun_requests + 2;
    so.color = true;
    auto sp = runtime::FramePool::create(so);
    if (!sp) return sp.status();
    impl->sun_pool = std::move(*sp);
  }

  pipeline::PipelineOptions popt;
  popt.frontend.max_features = config.estimator.max_features;
  popt.frontend.max_width = std::max(popt.frontend.max_width, config.frames.width);
  popt.frontend.max_height = std::max(popt.frontend.max_height, config.frames.height);
  popt.vo.window.window_size = config.estimator.window_size;
  popt.vo.window.max_num_iterations = config.estimator.max_iterations;
  popt.vo.window.max_solver_time_in_seconds = config.estimator.max_solver_time_ms * 1e-3;
  const Status ps = popt.validate();
  if (!ps.isOk()) return Status(ps.code(), config.path + ": estimator: " + ps.message());
  SUNVO_RETURN_IF_ERROR(impl->vo.init(popt, impl->camera, impl->world.T_w_c0));
  if (impl->sun_provider) {
    sunfusion::SunFusionOptions fusion;
    fusion.world_up = Eigen::Vector3d::UnitZ();  // ENU
    fusion.estimate_base_attitude = config.sun.estimate_base_attitude;
    fusion.gate.max_cosine_distance = config.sun.max_cosine_distance;
    fusion.initial_attitude_sigma_deg = config.sun.initial_attitude_sigma_deg;
    fusion.max_drift_deg_per_frame = config.sun.max_drift_deg_per_frame;
    SUNVO_RETURN_IF_ERROR(impl->sun_term.init(fusion));
    impl->sun_term.attach(impl->vo.odometry().window());
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
  auto launch = [&](int i, const char* name, const runtime::ThreadPolicy& p, void (Impl::*fn)()) {
    s.threads.emplace_back([&s, i, name, p, fn] {
      s.setThreadPolicy(name, p, &s.thread_warnings[static_cast<std::size_t>(i)]);
      s.threads_ready.fetch_add(1, std::memory_order_release);
      (s.*fn)();
    });
  };
  launch(0, "telemetry", s.config.rt.telemetry, &Impl::telemetryLoop);
  launch(1, "estimator", s.config.rt.estimator, &Impl::estimatorLoop);
  if (s.sun_provider) {
    launch(2, "sun", s.config.rt.sun, &Impl::sunLoop);
  } else {
    s.threads_ready.fetch_add(1);
    s.sun_done.store(true);
  }
  launch(3, "capture", s.config.rt.capture, &Impl::captureLoop);
  while (s.threads_ready.load(std::memory_order_acquire) < 4) std::this_thread::yield();
  for (const std::string& w : s.thread_warnings) {
    if (!w.empty()) warnings.push_back(w);
  }
  return warnings;
}

void RoverApp::requestStop() {
  impl_->stop.store(true, std::memory_order_release);
  impl_->frames_ev.notify();
  impl_->sun_req_ev.notify();
  impl_->sun_res_ev.notify();
  impl_->poses_ev.notify();
}

bool RoverApp::finished() const {
  const Impl& s = *impl_;
  if (s.config.source.type == SourceType::kKitti && s.config.source.kitti.end == EndAction::kHold &&
      !s.stop.load()) {
    return false;
  }
  return s.telemetry_done.load(std::memory_order_acquire);
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

std::uint64_t RoverApp::framesProcessed() const {
  return impl_->health.frames_processed.load(std::memory_order_relaxed);
}

std::string RoverApp::summary() const {
  const Impl& s = *impl_;
  const Health& h = s.health;
  auto g = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  std::string o;
  const TimeNs end = s.end_mono_ns != 0 ? s.end_mono_ns : runtime::monotonicNs();
  appendf(&o, "summary (%.1f s):\n", static_cast<double>(end - s.start_mono_ns) * 1e-9);
  appendf(&o,
          "  triggers %" PRIu64 " (timeouts %" PRIu64 ", missed %" PRIu64 ", duplicate %" PRIu64
          "), frames grabbed %" PRIu64 " (grab errors %" PRIu64 ", pool exhausted %" PRIu64 ")\n",
          g(h.triggers), g(h.trigger_timeouts), g(h.triggers_missed), g(h.triggers_duplicate),
          g(h.frames_grabbed), g(h.grab_errors), g(h.pool_exhausted));
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
  queue("frames", s.frames_q.counters());
  queue("sun_requests", s.sun_req_q.counters());
  queue("sun_results", s.sun_res_q.counters());
  queue("poses", s.poses_q.counters());
  appendf(&o,
          "  poses published %" PRIu64 ", deadline misses (trigger -> last byte > %.0f ms) %" PRIu64
          ", heartbeats %" PRIu64 ", link errors %" PRIu64 "\n",
          g(h.poses_published), s.config.estimator.deadline_ms, g(h.deadline_misses),
          g(h.heartbeats), g(h.link_errors));
  appendf(&o, "  tracking: losses %" PRIu64 ", recoveries %" PRIu64 ", lost frames %" PRIu64 "\n",
          g(h.tracking_losses), g(h.recoveries), g(h.lost_frames));
  appendf(&o,
          "  sun (%s): requests %" PRIu64 ", measurements %" PRIu64 ", errors %" PRIu64
          ", late %" PRIu64 ", accepted %" PRIu64 ", rejected %" PRIu64 "\n",
          s.sun_provider ? s.sun_provider->name() : "none", g(h.sun_requests),
          g(h.sun_measurements), g(h.sun_errors), g(h.sun_late), g(h.sun_accepted),
          g(h.sun_rejected));
  if (s.link) o += "  serial: " + s.link->countersText() + "\n";
  if (runtime::allocationProbeInstalled()) {
    auto meter = [&](const char* name, const runtime::AllocationMeter& m) {
      appendf(&o,
              "  allocations after warm-up, %-9s %" PRIu64 " in %" PRIu64
              " frames (%.2f per frame)\n",
              name, m.allocationsAfterWarmup(), m.framesMeasured(), m.perFrame());
    };
    meter("capture", s.capture_meter);
    meter("estimator", s.estimator_meter);
    meter("sun", s.sun_meter);
    meter("telemetry", s.telemetry_meter);
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
