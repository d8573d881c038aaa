#pragma once
// Gating of sun measurements before they enter the window, using the current pose estimate.
//
// A measurement is compared with the sun predicted from the current pose, s_hat_k = C_k_w s_w:
//  - cosine distance 1 - s_hat . s (full 3-D, or both projected and normalised in the camera x-z
//    plane) above max_cosine_distance -> rejected (the paper used 0.3);
//  - vertical error |s_hat_y - s_y| (camera y, i.e. mostly zenith) above max_vertical_error ->
//    rejected, which cuts the skewed tail of Lalonde-type zenith errors (full 3-D only);
//  - sun below the horizon (s_w.up <= min_sun_elevation) -> no measurement is used at all;
//  - a non-finite or non-unit measurement -> rejected as invalid.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string_view>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::sunfusion {

enum class GatePlane { kFull3d, kXZ };
inline std::span<const std::string_view> enumNames(GatePlane) {
  static constexpr std::string_view kNames[] = {"full_3d", "xz"};
  return kNames;
}

struct SunGateOptions {
  double max_cosine_distance = 0.3;      // reject above, [0, 2]; 2 disables
  GatePlane plane = GatePlane::kFull3d;  // where the cosine distance is measured
  double max_vertical_error = 0.3;       // reject |s_hat_y - s_y| above, [0, 2]; 2 disables
  double min_sun_elevation_deg = 0.0;    // ignore measurements while the sun is lower, [-5, 60] deg

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("max_cosine_distance", s.max_cosine_distance);
    v("plane", s.plane);
    v("max_vertical_error", s.max_vertical_error);
    v("min_sun_elevation_deg", s.min_sun_elevation_deg);
  }
};

enum class GateResult {
  kAccepted,
  kRejectedCosine,
  kRejectedVertical,
  kRejectedSunDown,
  kRejectedInvalid,
  kRejectedInnovation,  // by the fusion's innovation gate (sun_window_term.hpp), not by this gate
  kRejectedCorrection,  // would turn the attitude more than the fusion's max_correction_deg
};

const char* toString(GateResult r);

struct GateCounters {
  std::uint64_t accepted = 0;
  std::uint64_t rejected_cosine = 0;
  std::uint64_t rejected_vertical = 0;
  std::uint64_t rejected_sun_down = 0;
  std::uint64_t rejected_invalid = 0;
  std::uint64_t rejected_innovation = 0;
  std::uint64_t rejected_correction = 0;
  void count(GateResult r);
  std::uint64_t total() const {
    return accepted + rejected_cosine + rejected_vertical + rejected_sun_down + rejected_invalid +
           rejected_innovation + rejected_correction;
  }
};

// predicted_sun_c: the sun in camera k predicted from the current pose; sun_up: the world sun's
// up component (sin of its elevation).
GateResult gateSunMeasurement(const SunGateOptions& options, const Eigen::Vector3d& predicted_sun_c,
                              double sun_up, const SunMeasurement& measurement);

// Unit vector of v's x and z components; zero when both are ~0.
Eigen::Vector2d xzDirection(const Eigen::Vector3d& v);

}  // namespace sunvo::sunfusion
