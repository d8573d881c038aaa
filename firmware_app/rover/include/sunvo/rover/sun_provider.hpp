#pragma once
// Where the sun thread gets a sun measurement for a frame. The thread itself predicts the sun in
// the world (NREL SPA at the configured position and the frame's UTC time) and gates nothing:
// the estimator's SunWindowTerm gates against the current pose.
//
// Providers: "none" (no measurements: pure VO), "csv" (a per-frame file of sun vectors in the
// camera, e.g. a renderer's gt/sun_cam0.csv or kitti_odometry/*_sun_cam.csv) and, through
// ImageSunProvider, any sunfusion::ImageSunEstimator (Lalonde, Lalonde-VO, Sun-CNN): adding one
// is one line in makeSunProvider().

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/files/sun_csv.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::rover {

struct SunQuery {
  std::uint64_t sequence = 0;
  std::int64_t source_index = 0;  // frame index in the recording (csv rows)
  TimeNs utc_ns = 0;
  const StereoFrame* images = nullptr;  // set when the provider needsImages()
  std::optional<sunfusion::SunPrior> prior;
};

class SunProvider {
 public:
  virtual ~SunProvider() = default;
  virtual const char* name() const = 0;
  // True when measure() looks at the images (the capture thread then copies sun frames for it).
  virtual bool needsImages() const { return false; }
  // nullopt: no measurement for this frame (not an error).
  virtual Expected<std::optional<sunfusion::SunMeasurement>> measure(const SunQuery& query) = 0;
};

class CsvSunProvider final : public SunProvider {
 public:
  CsvSunProvider(files::SunCsv csv, double sigma) : csv_(std::move(csv)), sigma_(sigma) {}
  const char* name() const override { return "csv"; }
  Expected<std::optional<sunfusion::SunMeasurement>> measure(const SunQuery& query) override;

 private:
  files::SunCsv csv_;
  double sigma_;
};

// Adapts an image estimator: camera-0 colour image in, measurement out when it is valid.
class ImageSunProvider final : public SunProvider {
 public:
  ImageSunProvider(std::unique_ptr<sunfusion::ImageSunEstimator> estimator,
                   const StereoCamera& camera)
      : estimator_(std::move(estimator)), camera_(camera) {}
  const char* name() const override { return estimator_->name(); }
  bool needsImages() const override { return true; }
  Expected<std::optional<sunfusion::SunMeasurement>> measure(const SunQuery& query) override;

 private:
  std::unique_ptr<sunfusion::ImageSunEstimator> estimator_;
  StereoCamera camera_;
};

// True for the providers that look at the images.
inline bool sunProviderNeedsImages(SunProviderType type) {
  return type == SunProviderType::kLalonde || type == SunProviderType::kLalondeVo ||
         type == SunProviderType::kSunCnn;
}

// nullptr for provider none.
Expected<std::unique_ptr<SunProvider>> makeSunProvider(const SunConfig& config,
                                                       const StereoCamera& camera);

}  // namespace sunvo::rover
