#include "sunvo/sun_estimators/sun_estimators.hpp"

#include "sunvo/suncnn/sun_cnn_estimator.hpp"
#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::suneval {
namespace {
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> lalonde(sunvision::LalondePrior prior) {
  sunvision::LalondeOptions options;
  options.prior = prior;
  auto e = std::make_unique<sunvision::LalondeEstimator>(options);
  SUNVO_RETURN_IF_ERROR(e->init());
  return std::unique_ptr<sunfusion::ImageSunEstimator>(std::move(e));
}

// The shipped model (config/sun_cnn.onnx) with its default options.
Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> sunCnn() {
  auto e = std::make_unique<suncnn::SunCnnEstimator>();
  SUNVO_RETURN_IF_ERROR(e->init(suncnn::SunCnnOptions{}, SUNVO_DEFAULT_SUN_CNN_MODEL));
  return std::unique_ptr<sunfusion::ImageSunEstimator>(std::move(e));
}
}  // namespace

std::vector<std::string> knownSunEstimators() {
  return {"lalonde", "lalonde_vo", "sun_cnn"};
}

Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> makeSunEstimator(const std::string& name) {
  if (name == "lalonde") return lalonde(sunvision::LalondePrior::kZenith);
  if (name == "lalonde_vo") return lalonde(sunvision::LalondePrior::kVisualOdometry);
  if (name == "sun_cnn") return sunCnn();
  return notFound("unknown sun estimator '" + name + "'");
}

Expected<std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>>> makeSunEstimators(
    const std::vector<std::string>& names) {
  std::vector<std::unique_ptr<sunfusion::ImageSunEstimator>> out;
  for (const std::string& n : names) {
    Expected<std::unique_ptr<sunfusion::ImageSunEstimator>> e = makeSunEstimator(n);
    if (!e) return e.status();
    out.push_back(std::move(*e));
  }
  return out;
}

}  // namespace sunvo::suneval
