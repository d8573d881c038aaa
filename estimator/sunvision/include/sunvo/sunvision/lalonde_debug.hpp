#pragma once
// Debug images of a Lalonde estimate in the style of Clement et al.'s Fig. 1: the probability map
// of each cue and of their combination over (azimuth across, zenith down: 0 deg at the top row),
// the camera's horizontal field of view as two black lines, the best cell as a yellow circle and
// the true sun (when given) as a green cross; and a virtual sundial, a vertical 1.5 m stick 8 m
// ahead (red) with the shadow the estimated sun casts (black; the true sun's in green).
// Writes nothing itself: the caller saves the images.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <optional>

#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::sunvision {

struct LalondeDebugImages {
  cv::Mat sky, shadow, prior, posterior;  // CV_8UC3 maps, 4 px per grid cell
  cv::Mat sundial;                        // CV_8UC3 copy of the input with the sundial drawn
  cv::Mat panel;                          // the four maps (2 x 2) above the sundial image
};

// estimator: the one that produced `estimate` from `input` (its lastCues()).
Expected<LalondeDebugImages> renderLalondeDebug(const LalondeEstimator& estimator,
                                                const sunfusion::ImageSunInput& input,
                                                const sunfusion::ImageSunEstimate& estimate,
                                                const std::optional<Eigen::Vector3d>& true_sun_c);

}  // namespace sunvo::sunvision
