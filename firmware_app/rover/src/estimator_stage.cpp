#include <algorithm>

#include "stages.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/runtime/clock.hpp"
#include "sunvo/runtime/deadline.hpp"

namespace sunvo::rover {

Status EstimatorStage::init(const StereoCamera& camera, const Isometry3& T_w_c0, bool use_sun) {
  const RoverConfig& c = ctx_.config;
  pipeline::SunAidedOptions options = c.estimator;
  options.use_sun = use_sun;
  options.fusion.world_up = Eigen::Vector3d::UnitZ();  // ENU
  // The vertical cue runs in the sun thread (SunStage): it allocates, this loop must not. Its
  // answers come back with the sun results (takeSunResults).
  options.vertical.measure_here = false;
  // The frames the estimator accepts are the configured ones.
  options.pipeline.frontend.max_width =
      std::max(options.pipeline.frontend.max_width, c.frames.width);
  options.pipeline.frontend.max_height =
      std::max(options.pipeline.frontend.max_height, c.frames.height);
  const Status s = odometry_.init(options, camera, T_w_c0);
  if (!s.isOk()) return Status(s.code(), c.path + ": estimator." + s.message());
  meter_.setWarmup(static_cast<std::uint64_t>(c.realtime.warmup_frames));
  return Status::ok();
}

void EstimatorStage::takeSunResults(std::uint64_t waiting_for, bool* got) {
  SunResult r;
  while (ctx_.channels.sun_results.pop(&r)) {
    if (r.sequence == waiting_for) *got = true;
    if (r.has_up) {
      sunfusion::SunObservation up;
      up.measurement.time_ns = r.utc_ns;
      up.measurement.sequence = r.sequence;
      up.measurement.kind = sunfusion::SunMeasurementKind::kFull3d;
      up.measurement.sun_c = Eigen::Vector3d(r.up_c[0], r.up_c[1], r.up_c[2]);
      up.measurement.sigma = r.up_sigma;
      up.measurement.sigma_strong = r.up_sigma_strong;
      up.measurement.strong_axis_c =
          Eigen::Vector3d(r.up_strong_axis_c[0], r.up_strong_axis_c[1], r.up_strong_axis_c[2]);
      up.sun_w = Eigen::Vector3d::UnitZ();  // ENU
      odometry_.addVertical(up);
    }
    if (!r.has_measurement) continue;
    sunfusion::SunObservation obs;
    obs.measurement.time_ns = r.utc_ns;
    obs.measurement.sequence = r.sequence;
    obs.measurement.kind = r.azimuth_only ? sunfusion::SunMeasurementKind::kAzimuthOnly
                                          : sunfusion::SunMeasurementKind::kFull3d;
    obs.measurement.sun_c = Eigen::Vector3d(r.sun_c[0], r.sun_c[1], r.sun_c[2]);
    obs.measurement.sigma = r.sigma;
    obs.sun_w = Eigen::Vector3d(r.sun_w[0], r.sun_w[1], r.sun_w[2]);
    odometry_.addSun(obs);
  }
}

PoseRecord EstimatorStage::poseOf(const pipeline::FrameResult& r, const runtime::FrameSlot& slot) {
  PoseRecord pose;
  pose.sequence = slot.meta.sequence;
  pose.utc_ns = slot.meta.trigger_utc_ns;
  pose.trigger_mono_ns = slot.meta.trigger_mono_ns;
  const Isometry3& T_w_c = r.vo.T_w_c;
  const Eigen::Quaterniond q(T_w_c.linear());
  for (int i = 0; i < 3; ++i) pose.p_w[i] = T_w_c.translation()[i];
  pose.q_w_c[0] = q.x();
  pose.q_w_c[1] = q.y();
  pose.q_w_c[2] = q.z();
  pose.q_w_c[3] = q.w();
  const double dt = toSeconds(pose.utc_ns - t_prev_ns_);
  if (have_prev_ && dt > 0.0 && r.vo.status == vo::TrackingStatus::kTracking) {
    const Eigen::Vector3d v = (T_w_c.translation() - T_w_prev_.translation()) / dt;
    // omega in camera k: C_km1_k = C_k_km1^T = Exp(omega_c dt).
    const Eigen::Vector3d w = logSO3(r.vo.T_k_km1.linear().transpose()) / dt;
    for (int i = 0; i < 3; ++i) {
      pose.v_w[i] = v[i];
      pose.omega_c[i] = w[i];
    }
    pose.velocity_valid = v.allFinite() && w.allFinite();
  }
  pose.tracking = static_cast<int>(r.vo.status);
  pose.ransac_inliers = r.vo.ransac_inliers;
  pose.reset_counter = reset_counter_;
  if (odometry_.options().use_sun) {
    const Eigen::Matrix3d P_w = odometry_.attitudeCovariance();
    const double upper[6] = {P_w(0, 0), P_w(0, 1), P_w(0, 2), P_w(1, 1), P_w(1, 2), P_w(2, 2)};
    for (int i = 0; i < 6; ++i) pose.cov_theta_w[i] = upper[i];
    pose.cov_theta_valid = P_w.allFinite();
  }
  have_prev_ = true;
  T_w_prev_ = T_w_c;
  t_prev_ns_ = pose.utc_ns;
  return pose;
}

void EstimatorStage::run() {
  const RealtimeConfig& rt = ctx_.config.realtime;
  const double max_budget_ms =
      ctx_.config.estimator.pipeline.vo.window.max_solver_time_in_seconds * 1e3;
  Channels& ch = ctx_.channels;
  Health& health = ctx_.health;
  const auto sun_wait_ns = static_cast<TimeNs>(rt.sun_wait_ms * 1e6);
  double front_ms_mean = 0.0;  // running mean of front end + RANSAC, ms
  bool have_mean = false;
  vo::TrackingStatus last_status = vo::TrackingStatus::kInitializing;
  const bool cue = odometry_.options().vertical.enabled;
  for (;;) {
    const std::uint32_t key = ch.frames_ev.prepare();
    FrameTicket ticket;
    if (!ch.frames.pop(&ticket)) {
      if (ch.stop.load(std::memory_order_acquire) ||
          ch.capture_done.load(std::memory_order_acquire)) {
        if (ch.frames.size() == 0) break;
        continue;
      }
      ch.frames_ev.wait(key, 50'000'000);
      continue;
    }
    if (ch.stop.load(std::memory_order_acquire)) {  // shutting down: queued frames are dropped
      ctx_.pool.release(ticket.slot);
      health.frames_dropped_at_stop.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    runtime::FrameSlot& slot = ctx_.pool.slot(ticket.slot);
    const std::uint64_t seq = slot.meta.sequence;
    const TimeNs t_start = runtime::monotonicNs();
    ctx_.profiler.stamp(seq, runtime::Stamp::kEstimatorStart, t_start);

    // Solver budget from the frame's age.
    const TimeNs age = t_start - slot.meta.trigger_mono_ns;
    if (age > ctx_.period_ns) health.late_frames.fetch_add(1, std::memory_order_relaxed);
    const double budget_ms =
        runtime::solverBudgetMs(rt.deadline_ms, static_cast<double>(age) * 1e-6, front_ms_mean,
                                rt.publish_margin_ms, rt.min_solver_time_ms, max_budget_ms);
    if (budget_ms < max_budget_ms) health.shrunk_budgets.fetch_add(1, std::memory_order_relaxed);
    odometry_.setSolverTimeBudget(budget_ms * 1e-3);
    ctx_.profiler.setSolverBudget(seq, budget_ms);

    // Sun results; a sun frame (or a frame of the vertical cue) waits a bounded time for its own
    // (the window, size 2, keeps the frame's rotation free only while it is the newest).
    bool got = false;
    takeSunResults(seq, &got);
    if (odometry_.isAidFrame(seq) && !got) {
      const TimeNs until = runtime::monotonicNs() + sun_wait_ns;
      for (;;) {
        const std::uint32_t skey = ch.sun_results_ev.prepare();
        takeSunResults(seq, &got);
        const TimeNs now = runtime::monotonicNs();
        if (got || now >= until) break;
        ch.sun_results_ev.wait(skey, until - now);
      }
      if (!got) health.sun_late.fetch_add(1, std::memory_order_relaxed);
    }

    auto r = odometry_.process(slot.frame);
    const TimeNs t_end = runtime::monotonicNs();
    if (!r) {
      ctx_.pool.release(ticket.slot);
      health.estimator_errors.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    const TimeNs fe_end = t_start + static_cast<TimeNs>(r->times.frontend_ms * 1e6);
    const TimeNs ransac_end = fe_end + static_cast<TimeNs>(r->times.ransac_ms * 1e6);
    ctx_.profiler.stamp(seq, runtime::Stamp::kFrontendEnd, std::min(fe_end, t_end));
    ctx_.profiler.stamp(seq, runtime::Stamp::kRansacEnd, std::min(ransac_end, t_end));
    ctx_.profiler.stamp(seq, runtime::Stamp::kWindowEnd, t_end);
    const double fr = r->times.frontend_ms + r->times.ransac_ms;
    front_ms_mean = have_mean ? 0.9 * front_ms_mean + 0.1 * fr : fr;
    have_mean = true;

    const vo::TrackingStatus status = r->vo.status;
    if (status == vo::TrackingStatus::kLost) {
      health.lost_frames.fetch_add(1, std::memory_order_relaxed);
      if (last_status != vo::TrackingStatus::kLost) {
        health.tracking_losses.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (status == vo::TrackingStatus::kRecovered) {
      health.recoveries.fetch_add(1, std::memory_order_relaxed);
      ++reset_counter_;
    }
    if (odometry_.options().pipeline.self_calibration.enabled) {
      const selfcal::SelfCalibrationReport& sc = r->self_calibration;
      health.self_cal_pitch_urad.store(std::llround(1e3 * sc.pitch_mrad),
                                       std::memory_order_relaxed);
      health.self_cal_roll_urad.store(std::llround(1e3 * sc.roll_mrad), std::memory_order_relaxed);
      health.self_cal_resets.store(sc.resets, std::memory_order_relaxed);
    }
    const sunfusion::GateCounters& gate = odometry_.sunCounters();
    health.sun_accepted.store(gate.accepted, std::memory_order_relaxed);
    health.sun_rejected.store(gate.total() - gate.accepted, std::memory_order_relaxed);
    const sunfusion::GateCounters& vgate = odometry_.verticalCounters();
    health.vertical_accepted.store(vgate.accepted, std::memory_order_relaxed);
    health.vertical_rejected.store(vgate.total() - vgate.accepted, std::memory_order_relaxed);
    if (odometry_.sunTerm().startTiltJudged() && health.start_tilt_answers.load() == 0) {
      const sunfusion::WorldUpAlignment& level = odometry_.sunTerm().worldUpAlignment();
      health.start_tilt_mdeg.store(std::llround(1e3 * level.tiltDeg()), std::memory_order_relaxed);
      health.start_tilt_removed.store(odometry_.sunTerm().startLevelled(),
                                      std::memory_order_relaxed);
      // Release: a reader that sees the answers sees the tilt and the decision.
      health.start_tilt_answers.store(static_cast<std::uint64_t>(level.used()),
                                      std::memory_order_release);
    }

    const PoseRecord pose = poseOf(*r, slot);
    ctx_.pool.release(ticket.slot);
    ch.poses.push(pose);  // drop-oldest: a stale pose is of no use
    ch.poses_ev.notify();
    health.frames_processed.fetch_add(1, std::memory_order_relaxed);
    if (odometry_.options().use_sun || cue) {
      attitude_.publish(Eigen::Quaterniond(r->vo.T_w_c.linear()));
    }
    last_status = status;
    meter_.frameDone();
  }
  ch.estimator_done.store(true, std::memory_order_release);
  ch.poses_ev.notify();
}

}  // namespace sunvo::rover
