#include "sunvo/sunestimators/sun_estimators.hpp"

#include "sunvo/suncnn/sun_cnn_estimator.hpp"
#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::sunestimators {
namespace {
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> lalonde(sunvision::LalondePrior prior) {
  sunvision::LalondeOptions options;
  options.prior = prior;
  auto e = std::make_unique<sunvision::LalondeEstimator>(options);
  SUNVO_RETURN_IF_ERROR(e->init());
  return std::unique_ptr<sunfusion::ImageSunEstimator>(std::move(e));
}

Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> sunCnn(const std::string& model_path) {
  // The model's JSON (written with it by the training script) says its channels, ensemble and
  // calibration; without one, the defaults (the shipped colour model's) apply.
  auto options = suncnn::optionsForModel(model_path);
  if (!options) return options.status();
  auto e = std::make_unique<suncnn::SunCnnEstimator>();
  SUNVO_RETURN_IF_ERROR(e->init(*options, model_path));
  return std::unique_ptr<sunfusion::ImageSunEstimator>(std::move(e));
}
}  // namespace

std::vector<std::string> knownSunEstimators() {
  return {"lalonde", "lalonde_vo", "sun_cnn"};
}

bool needsColour(const std::string& /*name*/) {
  return false;  // Sun-CNN takes grey images too (its grey model, or (Y, Y, Y) for colour)
}

Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> makeSunEstimator(
    const std::string& name, const std::string& model_path) {
  if (name == "lalonde") return lalonde(sunvision::LalondePrior::kZenith);
  if (name == "lalonde_vo") return lalonde(sunvision::LalondePrior::kVisualOdometry);
  if (name == "sun_cnn") return sunCnn(model_path);
  return notFound("unknown sun estimator '" + name + "' (known: lalonde, lalonde_vo, sun_cnn)");
}

Expected<std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>>> makeSunEstimators(
    const std::vector<std::string>& names, const std::string& model_path) {
  std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>> out;
  for (const std::string& n : names) {
    Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> e = makeSunEstimator(n, model_path);
    if (!e) return e.status();
    out.push_back(std::move(*e));
  }
  return out;
}

}  // namespace sunvo::sunestimators
