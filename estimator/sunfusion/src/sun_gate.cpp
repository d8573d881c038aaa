#include "sunvo/sunfusion/sun_gate.hpp"

#include <algorithm>
#include <cmath>

namespace sunvo::sunfusion {

Status SunGateOptions::validate() const {
  if (!(max_cosine_distance >= 0.0 && max_cosine_distance <= 2.0)) {
    return invalidArgument("sun_gate.max_cosine_distance out of range [0, 2]");
  }
  if (!(max_vertical_error >= 0.0 && max_vertical_error <= 2.0)) {
    return invalidArgument("sun_gate.max_vertical_error out of range [0, 2]");
  }
  if (!(min_sun_elevation_deg >= -5.0 && min_sun_elevation_deg <= 60.0)) {
    return invalidArgument("sun_gate.min_sun_elevation_deg out of range [-5, 60]");
  }
  return Status::ok();
}

const char* toString(GateResult r) {
  switch (r) {
    case GateResult::kAccepted:
      return "accepted";
    case GateResult::kRejectedCosine:
      return "rejected: cosine distance";
    case GateResult::kRejectedVertical:
      return "rejected: vertical error";
    case GateResult::kRejectedSunDown:
      return "rejected: sun below limit";
    case GateResult::kRejectedInvalid:
      return "rejected: invalid measurement";
    case GateResult::kRejectedInnovation:
      return "rejected: innovation";
    case GateResult::kRejectedCorrection:
      return "rejected: correction too large";
  }
  return "unknown";
}

void GateCounters::count(GateResult r) {
  switch (r) {
    case GateResult::kAccepted:
      ++accepted;
      break;
    case GateResult::kRejectedCosine:
      ++rejected_cosine;
      break;
    case GateResult::kRejectedVertical:
      ++rejected_vertical;
      break;
    case GateResult::kRejectedSunDown:
      ++rejected_sun_down;
      break;
    case GateResult::kRejectedInvalid:
      ++rejected_invalid;
      break;
    case GateResult::kRejectedInnovation:
      ++rejected_innovation;
      break;
    case GateResult::kRejectedCorrection:
      ++rejected_correction;
      break;
  }
}

Eigen::Vector2d xzDirection(const Eigen::Vector3d& v) {
  const Eigen::Vector2d xz(v.x(), v.z());
  const double n = xz.norm();
  return n > 1e-9 ? Eigen::Vector2d(xz / n) : Eigen::Vector2d::Zero();
}

GateResult gateSunMeasurement(const SunGateOptions& options, const Eigen::Vector3d& predicted_sun_c,
                              double sun_up, const SunMeasurement& m) {
  if (std::asin(std::clamp(sun_up, -1.0, 1.0)) * 180.0 / M_PI < options.min_sun_elevation_deg) {
    return GateResult::kRejectedSunDown;
  }
  if (!m.sun_c.allFinite() || !(m.sigma > 0.0) || !std::isfinite(m.sigma) ||
      !std::isfinite(m.sigma_strong) || m.sigma_strong < 0.0 || !m.strong_axis_c.allFinite()) {
    return GateResult::kRejectedInvalid;
  }
  const bool azimuth_only = m.kind == SunMeasurementKind::kAzimuthOnly;
  if (!azimuth_only && std::abs(m.sun_c.norm() - 1.0) > 1e-3) return GateResult::kRejectedInvalid;
  const Eigen::Vector2d m_xz = xzDirection(m.sun_c);
  const Eigen::Vector2d p_xz = xzDirection(predicted_sun_c);
  if (azimuth_only && (m_xz.isZero() || p_xz.isZero())) return GateResult::kRejectedInvalid;

  const bool in_plane = azimuth_only || options.plane == GatePlane::kXZ;
  const double cosine = in_plane ? m_xz.dot(p_xz) : m.sun_c.dot(predicted_sun_c.normalized());
  if (1.0 - cosine > options.max_cosine_distance) return GateResult::kRejectedCosine;
  if (!azimuth_only &&
      std::abs(predicted_sun_c.normalized().y() - m.sun_c.y()) > options.max_vertical_error) {
    return GateResult::kRejectedVertical;
  }
  return GateResult::kAccepted;
}

}  // namespace sunvo::sunfusion
