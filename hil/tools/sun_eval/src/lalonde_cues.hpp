#pragma once
// Each cue of a Lalonde estimator alone (issue 14: where each cue fails). After an estimate() call
// the estimator's lastCues() holds every cue's log likelihood on its (azimuth x zenith) grid; a
// cue's own estimate is its best cell. Azimuths here are in the estimator's horizon frame (built
// from the "up" it was given), where the shadow cue lives; the true sun is taken into that frame.
//  - sky: the best cell of the sky fit; error = its azimuth minus the true sun's, wrapped;
//  - shadow: a ground shadow line gives the sun's azimuth only up to 180 deg (its two-peaked
//    kernel), so its error is the axial one: the smaller of |e| and 180 - |e|, in [0, 90] deg.
// NaN for a cue that was not informative on the frame (too little sky, too few shadow lines).

#include <Eigen/Core>

#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::suneval {

struct CueErrors {
  double sky_deg;     // signed, (-180, 180]
  double shadow_deg;  // axial, [0, 90]
};

// The cue errors of the estimator's last estimate() call against the true sun (camera frame).
CueErrors lalondeCueErrors(const sunvision::LalondeEstimator& estimator,
                           const Eigen::Vector3d& true_sun_c);

// An azimuth error (deg) as the error of an axis: min(|e|, 180 - |e|) after wrapping.
double axialErrorDeg(double error_deg);

}  // namespace sunvo::suneval
