#include "sunvo/rover/sun_provider.hpp"

#include "sunvo/sunestimators/sun_estimators.hpp"

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

Expected<std::unique_ptr<SunProvider>> makeSunProvider(const SunConfig& config,
                                                       const StereoCamera& camera) {
  switch (config.provider) {
    case SunProviderType::kNone:
      return std::unique_ptr<SunProvider>();
    case SunProviderType::kCsv: {
      auto csv = files::readSunCsv(config.csv);
      if (!csv) return Status(csv.status().code(), "sun.csv: " + csv.status().message());
      return std::unique_ptr<SunProvider>(new CsvSunProvider(std::move(*csv), config.csv_sigma));
    }
    case SunProviderType::kLalonde:
    case SunProviderType::kLalondeVo:
    case SunProviderType::kSunCnn: {
      // The image estimators: the one factory every program uses, by the provider's name.
      auto e =
          sunestimators::makeSunEstimator(std::string(enumName(config.provider)), config.model);
      if (!e) {
        const char* key =
            config.provider == SunProviderType::kSunCnn ? "sun.model: " : "sun.provider: ";
        return Status(e.status().code(), key + e.status().message());
      }
      return std::unique_ptr<SunProvider>(new ImageSunProvider(std::move(*e), camera));
    }
  }
  return invalidArgument("sun.provider: unknown");
}

}  // namespace sunvo::rover
