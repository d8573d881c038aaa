#pragma once
// The image sun estimators sunvo_sun_eval knows, by name, each ready to use (initialised).

#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::suneval {

// Names known to makeSunEstimator, in the default evaluation order.
std::vector<std::string> knownSunEstimators();

// One estimator by name ("lalonde", "lalonde_vo"); not-found error for an unknown name.
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> makeSunEstimator(const std::string& name);

// All of `names`, in order; fails on the first unknown or failing one.
Expected<std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>>> makeSunEstimators(
    const std::vector<std::string>& names);

}  // namespace sunvo::suneval
