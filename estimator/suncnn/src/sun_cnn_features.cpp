#include "sunvo/suncnn/sun_cnn_features.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace sunvo::suncnn {

Status SunCnnFeaturePrior::validate(int members, int features_expected, const char* key) const {
  const std::string k = key;
  if (empty()) return Status::ok();
  if (features != features_expected)
    return invalidArgument(k + ".features is " + std::to_string(features) +
                           ", the model's trunk has " + std::to_string(features_expected));
  if (components < 1 || components > features)
    return invalidArgument(k + ".components out of range [1, features]");
  const std::size_t m = static_cast<std::size_t>(members), f = static_cast<std::size_t>(features),
                    p = static_cast<std::size_t>(components);
  if (mean.size() != m * f || axes.size() != m * p * f || variances.size() != m * p)
    return invalidArgument(k + ": " + std::to_string(mean.size() / std::max<std::size_t>(f, 1)) +
                           " members' numbers, the model has " + std::to_string(members) +
                           " (each needs mean [features], axes [components x features], "
                           "variances [components])");
  const auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (!finite(mean) || !finite(axes)) return invalidArgument(k + ": a number is not finite");
  if (!std::all_of(variances.begin(), variances.end(),
                   [](double v) { return std::isfinite(v) && v > 0.0; }))
    return invalidArgument(k + ".variances must be finite and > 0");
  return Status::ok();
}

double SunCnnFeaturePrior::memberDistance(int member, const float* x) const {
  const std::size_t f = static_cast<std::size_t>(features),
                    p = static_cast<std::size_t>(components);
  const double* mu = mean.data() + static_cast<std::size_t>(member) * f;
  const double* a = axes.data() + static_cast<std::size_t>(member) * p * f;
  const double* s = variances.data() + static_cast<std::size_t>(member) * p;
  double sum = 0.0;
  for (std::size_t i = 0; i < p; ++i) {
    double z = 0.0;
    for (std::size_t j = 0; j < f; ++j) z += (static_cast<double>(x[j]) - mu[j]) * a[i * f + j];
    sum += z * z / s[i];
  }
  return sum / static_cast<double>(p);
}

double featureWeakness(double distance) {
  if (!std::isfinite(distance)) return 0.0;  // a non-finite d says nothing about weakness
  return std::max(0.0, -std::log(std::max(distance, 1e-12)));
}

}  // namespace sunvo::suncnn
