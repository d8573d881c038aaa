#pragma once
// The statistics sunvo_sun_eval reports for one estimator on one image set.
//
// Azimuth: the camera-frame azimuth atan2(x, z) (x right, z forward, y down), so a positive
// azimuth is a sun to the right of the optical axis. Azimuth error = estimate minus truth, wrapped
// to (-180, 180] deg: a positive signed median (bias) means the estimates lie clockwise of the true
// sun seen from above (to its right). Gross: |azimuth error| > kGrossAzimuthDeg.
//
// Quantiles interpolate linearly between the sorted values at position q (n - 1) (so the median
// of an even count is the mean of the two middle values); NaN for no values.

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::suneval {

inline constexpr double kGrossAzimuthDeg = 45.0;  // deg: an error above this is gross
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One estimator's output on one frame, as the statistics need it.
struct FrameResult {
  bool valid = false;  // the estimator called its estimate usable
  // Azimuth error, deg, (-180, 180]; also for an invalid estimate (for the share of gross errors
  // flagged invalid). NaN when the estimator gave no direction.
  double azimuth_error_deg = kNaN;
  double zenith_error_deg = kNaN;   // deg, estimate minus truth; NaN for azimuth-only estimates
  double azimuth_sigma_deg = kNaN;  // the estimate's 1-sigma azimuth, deg (azimuthSigmaDeg)
  bool kept_by_gate = false;        // accepted by the sun gate against the true-pose prediction
  double cpu_ms = 0.0;              // process CPU time of the call, ms
  double wall_ms = 0.0;             // wall time of the call, ms (as the estimator measured it)
};

struct EstimatorSummary {
  int frames = 0;
  int valid = 0;
  double valid_share = kNaN;  // valid / frames
  // Over the valid frames with a finite azimuth error:
  double azimuth_median_deg = kNaN;  // median |error|
  double azimuth_p90_deg = kNaN;     // 90th percentile of |error|
  double azimuth_bias_deg = kNaN;    // median of the signed error (sign convention above)
  double zenith_median_deg = kNaN;   // median |zenith error| (full 3-D estimates only)
  double zenith_p90_deg = kNaN;
  int gross = 0;                // valid frames with a gross error
  double gross_share = kNaN;    // gross / valid
  int gross_any = 0;            // all frames (valid or not) whose estimate is gross
  int gross_invalid = 0;        // of those, the ones flagged invalid
  double gross_flagged = kNaN;  // gross_invalid / gross_any: how well "valid" catches failures
  int sigma_checked = 0;        // valid frames with a finite error and sigma
  int within_2sigma = 0;        // of those, |azimuth error| < 2 azimuth sigma
  double within_2sigma_share = kNaN;  // within_2sigma / sigma_checked (95 % when calibrated)
  int kept = 0;
  double kept_share = kNaN;  // kept / frames
  double cpu_ms_median = kNaN, cpu_ms_p90 = kNaN, wall_ms_median = kNaN, wall_ms_p90 = kNaN;
};

// One cue of Lalonde's alone: its error on every frame, NaN where the cue was not informative.
struct CueSummary {
  int frames = 0;
  int informative = 0;
  double informative_share = kNaN;  // informative / frames
  double median_deg = kNaN;         // median |error| over the informative frames
  double p90_deg = kNaN;
  int gross = 0;              // informative frames with |error| > kGrossAzimuthDeg
  double gross_share = kNaN;  // gross / informative
};

// The q-quantile, q in [0, 1], of the finite values (see above); NaN when there are none.
double quantile(std::vector<double> values, double q);

// a wrapped to (-180, 180] deg.
double wrapDeg(double a_deg);

// Camera-frame azimuth atan2(x, z) of v, deg, (-180, 180].
double azimuthDeg(const Eigen::Vector3d& v_c);

// The 1-sigma azimuth of a measurement, deg. sigma is the 1-sigma error of each tangent component
// (sun_measurement.hpp), about an angle in rad: for an azimuth-only estimate it is the azimuth's
// sigma; for a full 3-D one the azimuth component spans sigma / rho, rho = the true sun's length
// in the camera x-z plane (clamped to >= 0.1: a sun near the camera's y axis has no azimuth).
double azimuthSigmaDeg(sunfusion::SunMeasurementKind kind, double sigma,
                       const Eigen::Vector3d& true_sun_c);

EstimatorSummary summarize(const std::vector<FrameResult>& frames);

// errors_deg: one per frame, NaN where the cue was not informative.
CueSummary summarizeCue(const std::vector<double>& errors_deg);

}  // namespace sunvo::suneval
