#pragma once
// The one interface behind which every image sun estimator sits (Lalonde, Lalonde-VO, Sun-CNN).
//
// An estimator looks at one rectified colour image of camera 0 and says where the sun is in that
// camera's frame (x right, y down, z forward). The caller runs it off the critical path (every
// fifth frame by default) and hands the result to SunWindowTerm as a SunMeasurement.
//
//   ImageSunInput in{frame.left_color, camera, prior};
//   Expected<ImageSunEstimate> e = estimator.estimate(in);
//   if (e && e->valid) sun_term.addObservation({e->measurement, sun_w});
//
// Implementations allocate their buffers in init() and must not allocate per call where they can
// avoid it; they never throw, never end the process and never return NaN.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <optional>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::sunfusion {

// Prior on the sun in the camera frame, from the current VO attitude and the ephemeris:
// sun_c = C_c_w * sun_w. Lalonde-VO centres its prior on it; other estimators may ignore it.
struct SunPrior {
  Eigen::Vector3d sun_c = Eigen::Vector3d::UnitZ();  // unit vector toward the sun, camera frame
  Eigen::Vector3d up_c = -Eigen::Vector3d::UnitY();  // unit "up" (away from gravity), camera frame
};

struct ImageSunInput {
  cv::Mat color;        // rectified camera-0 image, CV_8UC3 (BGR); CV_8UC1 where acceptsGray()
  StereoCamera camera;  // intrinsics of that image (only fu, fv, cu, cv, width, height)
  std::optional<SunPrior> prior;  // the camera's "up" and, when known, the predicted sun
};

struct ImageSunEstimate {
  bool valid = false;          // false: no usable estimate (night, no sky and no shadows, ...)
  SunMeasurement measurement;  // sun_c, kind (kFull3d or kAzimuthOnly) and sigma (sets R_s)
  double azimuth_deg = 0.0;    // camera-frame azimuth atan2(x, z), deg, (-180, 180]
  double zenith_deg = 0.0;     // angle from the camera's "up", deg, [0, 180]; NaN-free
  double confidence = 0.0;     // [0, 1], estimator-specific (peak probability mass, 1 - spread)
  double time_ms = 0.0;        // wall time of the call, ms
};

class ImageSunEstimator {
 public:
  virtual ~ImageSunEstimator() = default;
  virtual const char* name() const = 0;  // "lalonde", "lalonde_vo", "sun_cnn"
  // True if a gray (CV_8UC1) image is a valid input, e.g. from a monochrome V4L2 camera; the
  // estimator then skips its colour cues. False: colour only (give a gray frame as GRAY2BGR).
  virtual bool acceptsGray() const { return false; }
  // The image is not kept. Errors: wrong image type or size, estimator not initialised.
  virtual Expected<ImageSunEstimate> estimate(const ImageSunInput& input) = 0;
};

}  // namespace sunvo::sunfusion
