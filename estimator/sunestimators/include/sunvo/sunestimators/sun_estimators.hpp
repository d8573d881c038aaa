#pragma once
// The one factory of image sun estimators by name, each ready to use (initialised): the rover's
// sun thread (sun.provider), sunvo_replay --estimators and sunvo_sun_eval all make theirs here.

#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::sunestimators {

// Names known to makeSunEstimator, in the default evaluation order.
std::vector<std::string> knownSunEstimators();

// True for the estimators that need the left colour image (the others also run on gray).
bool needsColour(const std::string& name);

// One estimator by name ("lalonde", "lalonde_vo", "sun_cnn"); sun_cnn loads the ONNX model at
// model_path with the options of the JSON beside it (name.onnx -> name.json, see
// suncnn::loadSunCnnOptions; without one, SunCnnOptions' defaults, which are the shipped colour
// model's). Not-found error for an unknown name; the model's errors name the file.
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> makeSunEstimator(
    const std::string& name, const std::string& model_path);

// All of `names`, in order; fails on the first unknown or failing one.
Expected<std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>>> makeSunEstimators(
    const std::vector<std::string>& names, const std::string& model_path);

}  // namespace sunvo::sunestimators
