#include "sunvo/rover/sun_provider.hpp"

#include "sunvo/suncnn/sun_cnn_estimator.hpp"
#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::rover {

Expected<std::optional<sunfusion::SunMeasurement>> CsvSunProvider::measure(const SunQuery& q) {
  if (q.source_index < 0 || static_cast<std::size_t>(q.source_index) >= csv_.sun_c.size()) {
    return std::optional<sunfusion::SunMeasurement>();
  }
  sunfusion::SunMeasurement m;
  m.time_ns = q.utc_ns;
  m.sequence = q.sequence;
  m.kind = sunfusion::SunMeasurementKind::kFull3d;
  m.sun_c = csv_.sun_c[static_cast<std::size_t>(q.source_index)];
  m.sigma = sigma_;
  return std::optional<sunfusion::SunMeasurement>(m);
}

Expected<std::optional<sunfusion::SunMeasurement>> ImageSunProvider::measure(const SunQuery& q) {
  // The colour image when the source delivers one; else the gray left image, for an estimator
  // that accepts it (a monochrome V4L2 camera).
  const bool colour = q.images != nullptr && !q.images->left_color.empty();
  const bool gray = q.images != nullptr && !q.images->left.empty() && estimator_->acceptsGray();
  if (!colour && !gray) {
    return failedPrecondition(std::string(name()) + ": no " +
                              (estimator_->acceptsGray() ? "image" : "colour image") +
                              " for frame " + std::to_string(q.sequence));
  }
  sunfusion::ImageSunInput in{colour ? q.images->left_color : q.images->left, camera_, q.prior};
  auto e = estimator_->estimate(in);
  if (!e) return e.status();
  if (!e->valid) return std::optional<sunfusion::SunMeasurement>();
  sunfusion::SunMeasurement m = e->measurement;
  m.sequence = q.sequence;
  m.time_ns = q.utc_ns;
  return std::optional<sunfusion::SunMeasurement>(m);
}

namespace {
Expected<std::unique_ptr<SunProvider>> lalonde(sunvision::LalondePrior prior,
                                               const StereoCamera& camera) {
  sunvision::LalondeOptions options;
  options.prior = prior;
  auto e = std::make_unique<sunvision::LalondeEstimator>(options);
  const Status s = e->init();
  if (!s.isOk()) return Status(s.code(), "sun.provider: " + s.message());
  return std::unique_ptr<SunProvider>(new ImageSunProvider(std::move(e), camera));
}
}  // namespace

Expected<std::unique_ptr<SunProvider>> makeSunProvider(const SunConfig& config,
                                                       const StereoCamera& camera) {
  switch (config.provider) {
    case SunProviderType::kNone:
      return std::unique_ptr<SunProvider>();
    case SunProviderType::kCsv: {
      auto csv = files::readSunCsv(config.csv);
      if (!csv) return Status(csv.status().code(), "sun.csv: " + csv.status().message());
      return std::unique_ptr<SunProvider>(new CsvSunProvider(std::move(*csv), config.sigma));
    }
    case SunProviderType::kLalonde:
      return lalonde(sunvision::LalondePrior::kZenith, camera);
    case SunProviderType::kLalondeVo:
      return lalonde(sunvision::LalondePrior::kVisualOdometry, camera);
    case SunProviderType::kSunCnn: {
      auto e = std::make_unique<suncnn::SunCnnEstimator>();
      const Status s = e->init(suncnn::SunCnnOptions{}, config.model);
      if (!s.isOk()) return Status(s.code(), "sun.model: " + s.message());
      return std::unique_ptr<SunProvider>(new ImageSunProvider(std::move(e), camera));
    }
  }
  return invalidArgument("sun.provider: unknown");
}

}  // namespace sunvo::rover
