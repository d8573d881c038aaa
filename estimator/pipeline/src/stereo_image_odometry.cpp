#include "sunvo/pipeline/stereo_image_odometry.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <string>

namespace sunvo::pipeline {
namespace {

Status badKey(const char* key, const std::string& what) {
  return invalidArgument(std::string(key) + ": " + what);
}

double msBetween(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double nsToMs(std::int64_t ns) {
  return static_cast<double>(ns) * 1e-6;
}

// CPU time of the calling thread, ms; 0 if the clock is unavailable.
double threadCpuMs() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace

Status PipelineOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(frontend.validate());
  SUNVO_RETURN_IF_ERROR(vo.validate());
  if (frontend.max_features > vo.max_observations) {
    return badKey("frontend.max_features", "must be <= max_observations (" +
                                               std::to_string(vo.max_observations) + "), is " +
                                               std::to_string(frontend.max_features));
  }
  if (!(max_hint_px >= 0.0 && max_hint_px <= 1000.0)) {
    return badKey("max_hint_px", "must be in [0, 1000] px");
  }
  SUNVO_RETURN_IF_ERROR(self_calibration.validate());
  if (self_calibration.enabled && !frontend.measure_v_right) {
    return badKey("self_calibration.enabled",
                  "needs frontend.measure_v_right: true (the right rows it learns from)");
  }
  return Status::ok();
}

Status StereoImageOdometry::init(const PipelineOptions& options, const StereoCamera& camera,
                                 const Isometry3& T_w_c0) {
  initialized_ = false;
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  SUNVO_RETURN_IF_ERROR(frontend_.init(options.frontend, camera));
  SUNVO_RETURN_IF_ERROR(odometry_.init(options.vo, camera, T_w_c0));
  options_ = options;
  camera_ = camera;
  frontend_.reserveOutput(features_);
  frontend_.reserveOutput(corrected_);
  SUNVO_RETURN_IF_ERROR(self_calibration_.init(options.self_calibration, camera));
  have_motion_ = false;
  last_motion_ = Isometry3::Identity();
  initialized_ = true;
  return Status::ok();
}

// The hint for frame k+1 under constant velocity, T_{k+1}_k ~ T_k_km1 = [R | t]. A point at
// infinity in direction d (frame k) appears in frame k+1 in direction R d; the translation does
// not move it. For the optical axis d = (0, 0, 1), R d = third column r_.2, which projects to
//   u = cu + fu r02 / r22,   v = cv + fv r12 / r22,
// so the image content near the centre shifts by (fu r02 / r22, fv r12 / r22). Near points also
// move with the translation (depth-dependent); the front end's per-feature constant image velocity
// prediction covers those once a feature has a history.
bool StereoImageOdometry::rotationShift(const Isometry3& T_k_km1, float* du, float* dv) const {
  const Eigen::Matrix3d R = T_k_km1.linear();
  const double r22 = R(2, 2);
  if (!(r22 > 1e-3)) return false;
  const double su = camera_.fu * R(0, 2) / r22;
  const double sv = camera_.fv * R(1, 2) / r22;
  if (!std::isfinite(su) || !std::isfinite(sv)) return false;
  if (std::abs(su) > options_.max_hint_px || std::abs(sv) > options_.max_hint_px) return false;
  *du = static_cast<float>(su);
  *dv = static_cast<float>(sv);
  return true;
}

Expected<FrameResult> StereoImageOdometry::process(const StereoFrame& frame) {
  if (!initialized_) return failedPrecondition("StereoImageOdometry::process before init");
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const double cpu0 = threadCpuMs();
  FrameResult r;
  if (options_.rotation_hint && have_motion_) {
    float du = 0.0F;
    float dv = 0.0F;
    if (rotationShift(last_motion_, &du, &dv)) {
      frontend_.setPixelShiftHint(du, dv);
      r.hint_du_px = du;
      r.hint_dv_px = dv;
    }
  }

  const std::uint64_t c0 = counter_ != nullptr ? counter_() : 0;
  SUNVO_RETURN_IF_ERROR(
      frontend_.process(frame.left, frame.right, frame.trigger_time_ns, frame.sequence, features_));
  const std::uint64_t c1 = counter_ != nullptr ? counter_() : 0;
  const auto t1 = Clock::now();
  const double cpu1 = threadCpuMs();
  // The self-calibration learns the right camera's turn from this frame's rows and corrects
  // the right observations before the back end sees them.
  const FrameFeatures* to_odometry = &features_;
  if (self_calibration_.active()) {
    r.self_calibration = self_calibration_.process(features_, &corrected_);
    to_odometry = &corrected_;
  }
  Expected<vo::VoResult> vr = odometry_.process(*to_odometry);
  const std::uint64_t c2 = counter_ != nullptr ? counter_() : 0;
  const auto t2 = Clock::now();
  const double cpu2 = threadCpuMs();
  if (!vr) return vr.status();

  r.vo = *vr;
  r.frontend = frontend_.lastStats();
  r.num_features = static_cast<int>(features_.observations.size());
  r.frontend_counter_delta = c1 - c0;
  r.odometry_counter_delta = c2 - c1;

  // A motion is a measurement only when this frame was tracked against its predecessor.
  const bool tracked = (r.vo.status == vo::TrackingStatus::kTracking ||
                        r.vo.status == vo::TrackingStatus::kRecovered) &&
                       r.vo.reference_gap == 1;
  have_motion_ = tracked;
  if (tracked) last_motion_ = r.vo.T_k_km1;

  r.times.detect_ms = nsToMs(r.frontend.detect_ns);
  r.times.temporal_ms = nsToMs(r.frontend.temporal_ns);
  r.times.stereo_ms = nsToMs(r.frontend.stereo_ns);
  r.times.frontend_ms = msBetween(t0, t1);
  r.times.ransac_ms = r.vo.ransac_ms;
  r.times.window_ms = r.vo.window_ms;
  r.times.odometry_ms = msBetween(t1, t2);
  r.times.detect_cpu_ms = nsToMs(r.frontend.detect_cpu_ns);
  r.times.match_cpu_ms = nsToMs(r.frontend.temporal_cpu_ns + r.frontend.stereo_cpu_ns);
  r.times.frontend_cpu_ms = cpu1 - cpu0;
  r.times.odometry_cpu_ms = cpu2 - cpu1;
  r.times.total_cpu_ms = threadCpuMs() - cpu0;
  r.times.total_ms = msBetween(t0, Clock::now());
  return r;
}

}  // namespace sunvo::pipeline
