#pragma once
// The four thread stages of sunvo_rover (app.hpp draws how they connect). Each is one class with
// one run() loop; RoverApp creates them, starts one thread per stage and joins them. A stage owns
// what only its thread touches (the estimator, the sun provider, the pose link) and shares the
// rest through StageContext.

#include <memory>

#include "rover_state.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/pose_link.hpp"
#include "sunvo/rover/pose_log.hpp"
#include "sunvo/rover/sources.hpp"
#include "sunvo/rover/sun_provider.hpp"
#include "sunvo/runtime/allocation_meter.hpp"
#include "sunvo/runtime/frame_pool.hpp"
#include "sunvo/runtime/latency_profiler.hpp"
#include "sunvo/sun/spa.hpp"
#include "sunvo/vertical/vertical_estimator.hpp"

namespace sunvo::rover {

// What every stage shares; owned by RoverApp, outlives the stages.
struct StageContext {
  const RoverConfig& config;
  TimeNs period_ns = 0;  // trigger period
  Channels& channels;
  Health& health;
  runtime::LatencyProfiler& profiler;
  runtime::FramePool& pool;      // stereo frames, capture -> estimator
  runtime::FramePool* sun_pool;  // copies of sun frames for an image provider, or null
};

// Waits for each trigger, grabs its stereo pair into a free pool slot and queues it; for a sun
// frame (and a frame of the vertical cue) also queues a sun request, with a copy of the left
// image when the provider or the cue needs it.
class CaptureStage {
 public:
  CaptureStage(StageContext& ctx, TriggerSource& trigger, FrameSource& source,
               const pipeline::SunAidedOdometry& schedule)
      : ctx_(ctx), trigger_(trigger), source_(source), schedule_(schedule) {}
  void run();
  runtime::AllocationMeter& meter() { return meter_; }

 private:
  void requestSun(const runtime::FrameSlot& slot, std::uint64_t sequence, TimeNs utc_ns);

  StageContext& ctx_;
  TriggerSource& trigger_;
  FrameSource& source_;
  // Only its immutable every-n schedule is read here (isAidFrame is safe across threads).
  const pipeline::SunAidedOdometry& schedule_;
  runtime::AllocationMeter meter_;
};

// The sun-aided estimator on each queued frame; before a sun frame it waits a bounded time for
// that frame's sun result. The solver's time budget shrinks when the frame is late:
//   budget = clamp(deadline - age - (front end + RANSAC, running mean) - margin,
//                  min_solver_time, max_solver_time),  age = dequeue - trigger.
class EstimatorStage {
 public:
  EstimatorStage(StageContext& ctx, AttitudeMailbox& attitude) : ctx_(ctx), attitude_(attitude) {}
  // Sizes the estimator from the config (before the threads start).
  Status init(const StereoCamera& camera, const Isometry3& T_w_c0, bool use_sun);
  void run();
  const pipeline::SunAidedOdometry& odometry() const { return odometry_; }
  runtime::AllocationMeter& meter() { return meter_; }

 private:
  // Hands the sun results that arrived to the estimator; *got when `waiting_for`'s is among them.
  void takeSunResults(std::uint64_t waiting_for, bool* got);
  PoseRecord poseOf(const pipeline::FrameResult& r, const runtime::FrameSlot& slot);

  StageContext& ctx_;
  AttitudeMailbox& attitude_;
  pipeline::SunAidedOdometry odometry_;
  runtime::AllocationMeter meter_;
  // Velocity from consecutive tracked poses; reset counter for the autopilot.
  bool have_prev_ = false;
  Isometry3 T_w_prev_ = Isometry3::Identity();
  TimeNs t_prev_ns_ = 0;
  std::uint8_t reset_counter_ = 0;
};

// The sun in the world (NREL SPA at the origin and the frame's UTC) and the provider's
// measurement in the camera, for each sun request; off the critical path (low priority). With
// estimator.vertical.enabled it also measures the camera's "up" on the request's image (the
// vertical cue allocates, so it runs here and not in the estimator's fixed-memory loop); the
// provider may then be null (sun.provider: none).
class SunStage {
 public:
  SunStage(StageContext& ctx, const AttitudeMailbox& attitude,
           std::unique_ptr<SunProvider> provider, const geodesy::GeodeticPoint& origin)
      : ctx_(ctx), attitude_(attitude), provider_(std::move(provider)), origin_(origin) {}
  // Turns the vertical cue on (before the threads start).
  Status initVerticalCue(const vertical::VerticalOptions& options, const StereoCamera& camera);
  void run();
  const SunProvider* provider() const { return provider_.get(); }
  runtime::AllocationMeter& meter() { return meter_; }

 private:
  // The provider's sun (with the prior from the last published attitude and the ephemeris at
  // the origin, `spa`).
  void measureSun(const sun::SpaOptions& spa, SunQuery& query, SunResult& res);
  // The cue on the request's left image, with the last published attitude as its prior.
  void measureUp(const SunQuery& query, SunResult& res);

  StageContext& ctx_;
  const AttitudeMailbox& attitude_;
  std::unique_ptr<SunProvider> provider_;
  geodesy::GeodeticPoint origin_;
  bool cue_ = false;
  vertical::VerticalEstimator vertical_;
  runtime::AllocationMeter meter_;
};

// Each pose -> the link (MAVLink ODOMETRY), HEARTBEAT at heartbeat_hz; the time the frame's last
// byte left is its publish stamp; trigger -> last byte above the deadline is a miss. With a pose
// log (telemetry.pose_log), each pose also goes there, flushed about once a second and at the end.
class TelemetryStage {
 public:
  TelemetryStage(StageContext& ctx, std::unique_ptr<PoseLink> link,
                 std::unique_ptr<TumPoseLog> pose_log = nullptr)
      : ctx_(ctx), link_(std::move(link)), pose_log_(std::move(pose_log)) {}
  void run();
  const PoseLink* link() const { return link_.get(); }
  const TumPoseLog* poseLog() const { return pose_log_.get(); }
  runtime::AllocationMeter& meter() { return meter_; }

 private:
  StageContext& ctx_;
  std::unique_ptr<PoseLink> link_;
  std::unique_ptr<TumPoseLog> pose_log_;
  runtime::AllocationMeter meter_;
};

}  // namespace sunvo::rover
