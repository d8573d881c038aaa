#pragma once
// A sun direction measured in a camera frame, by an image estimator, a sun sensor or a file.

#include <Eigen/Core>
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
};

}  // namespace sunvo::sunfusion
