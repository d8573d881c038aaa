#pragma once
// A sun direction measured in a camera frame, by an image estimator, a sun sensor or a file.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "sunvo/core/time.hpp"

namespace sunvo::sunfusion {

enum class SunMeasurementKind {
  kFull3d,       // a full unit vector sun_c (Lalonde, Lalonde-VO, sun sensor)
  kAzimuthOnly,  // only the direction in the camera x-z plane is known (Sun-CNN)
};

struct SunMeasurement {
  TimeNs time_ns = 0;
  std::uint64_t sequence = 0;  // frame the measurement belongs to
  SunMeasurementKind kind = SunMeasurementKind::kFull3d;
  Eigen::Vector3d sun_c = Eigen::Vector3d::UnitZ();  // unit vector toward the sun, camera frame
                                                     // (for kAzimuthOnly, sun_c.y() is ignored)
  double sigma = 0.1;  // 1-sigma error of each vector component (3-D) or of the x-z chord
                       // (unitless, ~ angle in rad for small errors); sets R_s = sigma^2 I
  // Optional, kFull3d only: a direction measured better one way than the other (the vertical
  // cue fixes a level camera's roll better than its pitch). When 0 < sigma_strong < sigma and
  // strong_axis_c is nonzero, the error along strong_axis_c (made normal to sun_c) has
  // std sigma_strong and R_s = sigma^2 (I - a a^T) + sigma_strong^2 a a^T; 0 = sigma everywhere.
  double sigma_strong = 0.0;
  Eigen::Vector3d strong_axis_c = Eigen::Vector3d::Zero();
};

// The square-root information W (W^T W = R_s^-1) of a full 3-D measurement: I / sigma, or with a
// strong axis a (the unit part of strong_axis_c normal to sun_c), I / sigma + (1 / sigma_strong -
// 1 / sigma) a a^T. An unusable strong axis (not finite, along sun_c, sigma_strong outside
// (0, sigma)) falls back to I / sigma.
inline Eigen::Matrix3d directionSqrtInformation(const Eigen::Vector3d& sun_c, double sigma,
                                                double sigma_strong,
                                                const Eigen::Vector3d& strong_axis_c) {
  Eigen::Matrix3d W = Eigen::Matrix3d::Identity() / sigma;
  if (!(sigma_strong > 0.0 && sigma_strong < sigma) || !strong_axis_c.allFinite() ||
      !sun_c.allFinite()) {
    return W;
  }
  const Eigen::Vector3d a = strong_axis_c - strong_axis_c.dot(sun_c) * sun_c;
  const double n = a.norm();
  if (!(n > 1e-6 * strong_axis_c.norm())) return W;  // also a zero axis (n = 0)
  const Eigen::Vector3d u = a / n;
  W += (1.0 / sigma_strong - 1.0 / sigma) * u * u.transpose();
  return W;
}

}  // namespace sunvo::sunfusion
