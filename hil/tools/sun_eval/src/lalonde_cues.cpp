#include "lalonde_cues.hpp"

#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>

#include "metrics.hpp"

namespace sunvo::suneval {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

// Horizon-frame azimuth (deg) of the best cell of a cue's log-likelihood grid.
double bestAzimuthDeg(const sunvision::LalondeEstimator& estimator, const cv::Mat& loglik) {
  cv::Point best;
  cv::minMaxLoc(loglik, nullptr, nullptr, nullptr, &best);
  return estimator.azimuthOfColRad(best.x) / kDeg;
}
}  // namespace

double axialErrorDeg(double error_deg) {
  const double e = std::abs(wrapDeg(error_deg));
  return std::min(e, 180.0 - e);
}

CueErrors lalondeCueErrors(const sunvision::LalondeEstimator& estimator,
                           const Eigen::Vector3d& true_sun_c) {
  const sunvision::LalondeCues& cues = estimator.lastCues();
  const double true_az_deg = cues.horizon.azimuthRad(true_sun_c) / kDeg;
  CueErrors e{kNaN, kNaN};
  if (cues.sky_informative) {
    e.sky_deg = wrapDeg(bestAzimuthDeg(estimator, cues.sky_loglik) - true_az_deg);
  }
  if (cues.shadow_informative) {
    e.shadow_deg = axialErrorDeg(bestAzimuthDeg(estimator, cues.shadow_loglik) - true_az_deg);
  }
  return e;
}

}  // namespace sunvo::suneval
