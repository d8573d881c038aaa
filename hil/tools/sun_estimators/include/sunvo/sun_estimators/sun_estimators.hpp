#pragma once
// The image sun estimators by name (for sunvo_sun_eval and sunvo_replay), each ready to use
// (initialised). sun_cnn loads the shipped model config/sun_cnn.onnx.

#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::suneval {

// Names known to makeSunEstimator, in the default evaluation order.
std::vector<std::string> knownSunEstimators();

// One estimator by name ("lalonde", "lalonde_vo", "sun_cnn"); not-found error for an unknown name.
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> makeSunEstimator(const std::string& name);

// All of `names`, in order; fails on the first unknown or failing one.
Expected<std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>>> makeSunEstimators(
    const std::vector<std::string>& names);

}  // namespace sunvo::suneval
