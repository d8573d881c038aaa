#include "stages.hpp"
#include "sunvo/runtime/clock.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::rover {

Status SunStage::initVerticalCue(const vertical::VerticalOptions& options,
                                 const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(vertical_.init(options, camera));
  cue_ = true;
  return Status::ok();
}

void SunStage::measureSun(const sun::SpaOptions& spa, SunQuery& query, SunResult& res) {
  Health& health = ctx_.health;
  auto sp = sun::computeSolarPosition(query.utc_ns, spa);
  Eigen::Quaterniond q_w_c_now;
  if (sp && attitude_.latest(&q_w_c_now)) {
    // Prior in the camera: sun_c = R_c_w sun_w, up_c = R_c_w (0, 0, 1) with ENU world (z up).
    // The attitude is the last published pose's, one or a few frames before this one.
    const Eigen::Matrix3d R_c_w = q_w_c_now.toRotationMatrix().transpose();
    sunfusion::SunPrior prior;
    prior.sun_c = (R_c_w * sp->sun_enu).normalized();
    prior.up_c = R_c_w * Eigen::Vector3d::UnitZ();
    query.prior = prior;
  }
  auto m = provider_->measure(query);
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
}

void SunStage::measureUp(const SunQuery& query, SunResult& res) {
  Eigen::Quaterniond q_w_c;
  // No prior before the first pose: the cue waits for one (its search is +-max_tilt_deg about it).
  if (query.images == nullptr || !attitude_.latest(&q_w_c)) return;
  Health& health = ctx_.health;
  // up_c = C_c_w up_w, ENU world (z up); the last published pose's, a frame or a few old.
  const Eigen::Vector3d prior_c = q_w_c.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
  health.vertical_calls.fetch_add(1, std::memory_order_relaxed);
  const Expected<vertical::VerticalMeasurement> m = vertical_.estimate(query.images->left, prior_c);
  if (!m) {
    health.vertical_errors.fetch_add(1, std::memory_order_relaxed);  // the image is refused
    return;
  }
  if (!m->valid || !m->up_c.allFinite() || !std::isfinite(m->sigma_rad)) return;
  health.vertical_valid.fetch_add(1, std::memory_order_relaxed);
  res.has_up = true;
  for (int i = 0; i < 3; ++i) {
    res.up_c[i] = m->up_c[i];
    res.up_strong_axis_c[i] = m->strong_axis_c[i];
  }
  res.up_sigma = m->sigma_rad;
  res.up_sigma_strong = m->sigma_strong_rad;
}

void SunStage::run() {
  Channels& ch = ctx_.channels;
  sun::SpaOptions spa;
  spa.latitude_deg = origin_.lat_deg;
  spa.longitude_deg = origin_.lon_deg;
  spa.elevation_m = origin_.alt_m;
  for (;;) {
    const std::uint32_t key = ch.sun_requests_ev.prepare();
    SunRequest req;
    if (!ch.sun_requests.pop(&req)) {
      if (ch.stop.load(std::memory_order_acquire) ||
          ch.estimator_done.load(std::memory_order_acquire)) {
        break;
      }
      ch.sun_requests_ev.wait(key, 100'000'000);
      continue;
    }
    ctx_.profiler.stamp(req.sequence, runtime::Stamp::kSunStart, runtime::monotonicNs());
    SunResult res;
    res.sequence = req.sequence;
    res.utc_ns = req.utc_ns;
    SunQuery query;
    query.sequence = req.sequence;
    query.source_index = req.source_index;
    query.utc_ns = req.utc_ns;
    if (req.image_slot != kNoImage) query.images = &ctx_.sun_pool->slot(req.image_slot).frame;
    if (provider_) measureSun(spa, query, res);
    if (cue_) measureUp(query, res);
    if (req.image_slot != kNoImage) ctx_.sun_pool->release(req.image_slot);
    ch.sun_results.push(res);
    ch.sun_results_ev.notify();
    ctx_.profiler.stamp(req.sequence, runtime::Stamp::kSunEnd, runtime::monotonicNs());
    meter_.frameDone();
  }
  ch.sun_done.store(true, std::memory_order_release);
}

}  // namespace sunvo::rover
