#include "sunvo/sunfusion/simulated_sun_source.hpp"

#include <algorithm>
#include <cmath>

#include "sunvo/core/geometry.hpp"

namespace sunvo::sunfusion {
namespace {
constexpr double kDeg = M_PI / 180.0;

bool inUnit(double v) {
  return v >= 0.0 && v <= 1.0;
}
}  // namespace

Status SunErrorModel::validate() const {
  if (!(azimuth_sigma_deg >= 0.0 && azimuth_sigma_deg <= 180.0)) {
    return invalidArgument("sun_error.azimuth_sigma_deg out of range [0, 180]");
  }
  if (!(zenith_sigma_deg >= 0.0 && zenith_sigma_deg <= 90.0)) {
    return invalidArgument("sun_error.zenith_sigma_deg out of range [0, 90]");
  }
  if (!(zenith_bias_deg >= -45.0 && zenith_bias_deg <= 45.0)) {
    return invalidArgument("sun_error.zenith_bias_deg out of range [-45, 45]");
  }
  if (!inUnit(outlier_share)) return invalidArgument("sun_error.outlier_share out of range [0, 1]");
  if (!inUnit(flip_share)) return invalidArgument("sun_error.flip_share out of range [0, 1]");
  if (!inUnit(dropout_share)) return invalidArgument("sun_error.dropout_share out of range [0, 1]");
  if (!(reported_sigma > 0.0 && reported_sigma <= 2.0)) {
    return invalidArgument("sun_error.reported_sigma out of range (0, 2]");
  }
  if (!(azimuth_bias_deg >= 0.0 && azimuth_bias_deg <= 90.0)) {
    return invalidArgument("sun_error.azimuth_bias_deg out of range [0, 90]");
  }
  if (!(azimuth_bias_length >= 1.0 && azimuth_bias_length <= 1e6)) {
    return invalidArgument("sun_error.azimuth_bias_length out of range [1, 1e6]");
  }
  if (!(azimuth_offset_deg >= -180.0 && azimuth_offset_deg <= 180.0)) {
    return invalidArgument("sun_error.azimuth_offset_deg out of range [-180, 180]");
  }
  return Status::ok();
}

Status VerticalErrorModel::validate() const {
  if (!(sigma_deg >= 0.0 && sigma_deg <= 30.0)) {
    return invalidArgument("vertical_error.sigma_deg out of range [0, 30]");
  }
  if (!(std::abs(pitch_bias_deg) <= 10.0) || !(std::abs(roll_bias_deg) <= 10.0)) {
    return invalidArgument("vertical_error.pitch_bias_deg / roll_bias_deg out of range [-10, 10]");
  }
  if (!inUnit(outlier_share)) {
    return invalidArgument("vertical_error.outlier_share out of range [0, 1]");
  }
  if (!(outlier_deg >= 0.0 && outlier_deg <= 90.0)) {
    return invalidArgument("vertical_error.outlier_deg out of range [0, 90]");
  }
  if (!inUnit(dropout_share)) {
    return invalidArgument("vertical_error.dropout_share out of range [0, 1]");
  }
  if (!(reported_sigma_deg > 0.0 && reported_sigma_deg <= 30.0)) {
    return invalidArgument("vertical_error.reported_sigma_deg out of range (0, 30]");
  }
  return Status::ok();
}

std::optional<SunMeasurement> SimulatedVerticalSource::measure(std::uint64_t sequence,
                                                               TimeNs time_ns,
                                                               const Eigen::Vector3d& true_up_c) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double u_drop = unit(rng_), u_out = unit(rng_);
  const Eigen::Vector3d n(normal(rng_), normal(rng_), normal(rng_));
  const Eigen::Vector3d axis(normal(rng_), normal(rng_), normal(rng_));
  if (u_drop < model_.dropout_share) return std::nullopt;
  Eigen::Vector3d rot;
  const Eigen::Vector3d t = true_up_c.normalized();
  const Eigen::Vector3d across = axis - axis.dot(t) * t;  // turns t by the full angle
  if (u_out < model_.outlier_share && across.norm() > 0.0) {
    rot = across.normalized() * model_.outlier_deg * kDeg;
  } else {
    rot = Eigen::Vector3d(model_.pitch_bias_deg, 0.0, model_.roll_bias_deg) * kDeg +
          n * model_.sigma_deg * kDeg;
  }
  SunMeasurement m;
  m.time_ns = time_ns;
  m.sequence = sequence;
  m.kind = SunMeasurementKind::kFull3d;
  m.sigma = model_.reported_sigma_deg * kDeg;
  m.sun_c = (expSO3(rot) * t).normalized();
  return m;
}

Eigen::Vector3d sunFromAzimuthZenith(double azimuth_rad, double zenith_rad) {
  const double s = std::sin(zenith_rad);
  return {s * std::sin(azimuth_rad), -std::cos(zenith_rad), s * std::cos(azimuth_rad)};
}

void azimuthZenithFromSun(const Eigen::Vector3d& sun_c, double& azimuth_rad, double& zenith_rad) {
  const Eigen::Vector3d u = sun_c.normalized();
  azimuth_rad = std::atan2(u.x(), u.z());
  zenith_rad = std::atan2(std::hypot(u.x(), u.z()), -u.y());
}

std::optional<SunMeasurement> SimulatedSunSource::measure(std::uint64_t sequence, TimeNs time_ns,
                                                          const Eigen::Vector3d& true_sun_c) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  // Draw every variate each call so that the sequence does not depend on earlier outcomes.
  const double u_drop = unit(rng_), u_out = unit(rng_), u_flip = unit(rng_);
  const double out_az = unit(rng_), out_zen = unit(rng_);
  const double n_az = normal(rng_), n_zen = normal(rng_);
  if (model_.azimuth_bias_deg > 0.0) {
    // The stationary start, then one Gauss-Markov step per call (see the header).
    const double sigma_b = model_.azimuth_bias_deg * kDeg;
    const double n_b = normal(bias_rng_);
    const double phi = std::exp(-1.0 / model_.azimuth_bias_length);
    bias_ =
        bias_started_ ? phi * bias_ + std::sqrt(1.0 - phi * phi) * sigma_b * n_b : sigma_b * n_b;
    bias_started_ = true;
  }
  if (u_drop < model_.dropout_share) return std::nullopt;

  double az = 0.0, zen = 0.0;
  azimuthZenithFromSun(true_sun_c, az, zen);
  if (u_out < model_.outlier_share) {
    az = (2.0 * out_az - 1.0) * M_PI;
    zen = std::acos(out_zen);  // uniform over the upper hemisphere's solid angle
  } else {
    if (u_flip < model_.flip_share) az += M_PI;
    az += (n_az * model_.azimuth_sigma_deg + model_.azimuth_offset_deg) * kDeg + bias_;
    zen += (model_.zenith_bias_deg + n_zen * model_.zenith_sigma_deg) * kDeg;
    zen = std::clamp(zen, 0.0, M_PI);
  }
  SunMeasurement m;
  m.time_ns = time_ns;
  m.sequence = sequence;
  m.sigma = model_.reported_sigma;
  m.kind = model_.azimuth_only ? SunMeasurementKind::kAzimuthOnly : SunMeasurementKind::kFull3d;
  m.sun_c =
      model_.azimuth_only ? sunFromAzimuthZenith(az, M_PI / 2.0) : sunFromAzimuthZenith(az, zen);
  return m;
}

}  // namespace sunvo::sunfusion
