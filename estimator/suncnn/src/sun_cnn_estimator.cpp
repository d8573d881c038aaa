#include "sunvo/suncnn/sun_cnn_estimator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace sunvo::suncnn {
namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

Status range(const char* key, const char* r) {
  return invalidArgument(std::string("suncnn.") + key + " out of range " + r);
}

constexpr double kMaxElevationRad = 85.0 * std::numbers::pi / 180.0;

// tan^2 of the sun's elevation above the plane normal to up_c, the elevation capped at 85 deg;
// 0 for a sun on or below the horizon or a degenerate prior.
double elevationTan2(const sunfusion::SunPrior& prior) {
  const double n = prior.sun_c.norm() * prior.up_c.norm();
  if (!(n > 1e-12) || !std::isfinite(n)) return 0.0;
  const double elevation = std::asin(std::clamp(prior.sun_c.dot(prior.up_c) / n, -1.0, 1.0));
  if (!(elevation > 0.0)) return 0.0;
  const double t = std::tan(std::min(elevation, kMaxElevationRad));
  return t * t;
}

// Square of the circular standard deviation of a mean resultant length R in (0, 1]: -2 ln R.
double circularStdSquared(double r) {
  return -2.0 * std::log(std::clamp(r, 1e-6, 1.0));
}
}  // namespace

Status SunCnnOptions::validate() const {
  if (!(input_width >= 16 && input_width <= 2048)) return range("input_width", "[16, 2048]");
  if (!(input_height >= 16 && input_height <= 2048)) return range("input_height", "[16, 2048]");
  if (!(pixel_mean >= 0.0 && pixel_mean <= 1.0)) return range("pixel_mean", "[0, 1]");
  if (!(pixel_std > 0.0 && pixel_std <= 10.0)) return range("pixel_std", "(0, 10]");
  if (input_channels != 1 && input_channels != 3) return range("input_channels", "{1, 3}");
  if (!(ensemble_members >= 1 && ensemble_members <= 16))
    return range("ensemble_members", "[1, 16]");
  if (!(mask_rows >= 2 && mask_rows <= 1024)) return range("mask_rows", "[2, 1024]");
  if (!(mask1_size >= 1 && mask1_size <= 1000000)) return range("mask1_size", "[1, 1e6]");
  if (!(mask2_size >= 1 && mask2_size <= 1000000)) return range("mask2_size", "[1, 1e6]");
  if (!(dropout_p >= 0.0 && dropout_p <= 0.9)) return range("dropout_p", "[0, 0.9]");
  if (!(mc_samples >= 0 && mc_samples <= mask_rows - 1))
    return range("mc_samples", "[0, mask_rows - 1]");
  if (!(sigma_scale > 0.0 && sigma_scale <= 100.0)) return range("sigma_scale", "(0, 100]");
  if (!(sigma_min_rad >= 0.0 && sigma_min_rad <= 1.0)) return range("sigma_min_rad", "[0, 1]");
  if (!(sigma_max_rad >= sigma_min_rad && sigma_max_rad <= 10.0))
    return range("sigma_max_rad", "[sigma_min_rad, 10]");
  if (!(max_valid_sigma_rad > 0.0 && max_valid_sigma_rad <= 10.0))
    return range("max_valid_sigma_rad", "(0, 10]");
  if (!(gray_sigma_scale > 0.0 && gray_sigma_scale <= 100.0))
    return range("gray_sigma_scale", "(0, 100]");
  if (!(gray_max_valid_sigma_rad > 0.0 && gray_max_valid_sigma_rad <= 10.0))
    return range("gray_max_valid_sigma_rad", "(0, 10]");
  if (!(elevation_gain >= 0.0 && elevation_gain <= 100.0))
    return range("elevation_gain", "[0, 100]");
  if (!(gray_elevation_gain >= 0.0 && gray_elevation_gain <= 100.0))
    return range("gray_elevation_gain", "[0, 100]");
  if (!(feature_gain >= 0.0 && feature_gain <= 100.0)) return range("feature_gain", "[0, 100]");
  if (!(gray_feature_gain >= 0.0 && gray_feature_gain <= 100.0))
    return range("gray_feature_gain", "[0, 100]");
  SUNVO_RETURN_IF_ERROR(
      feature_prior.validate(ensemble_members, mask1_size, "suncnn.feature_prior"));
  SUNVO_RETURN_IF_ERROR(
      gray_feature_prior.validate(ensemble_members, mask1_size, "suncnn.gray_feature_prior"));
  if (!(max_up_tilt_deg >= 0.0 && max_up_tilt_deg <= 90.0))
    return range("max_up_tilt_deg", "[0, 90]");
  return Status::ok();
}

Status SunCnnEstimator::init(const SunCnnOptions& options, const std::string& model_path) {
  ready_ = false;
  SUNVO_RETURN_IF_ERROR(options.validate());
  options_ = options;
  try {
    net_ = cv::dnn::readNetFromONNX(model_path);
  } catch (const cv::Exception& e) {
    return invalidArgument("suncnn: cannot read ONNX model " + model_path + ": " + e.msg);
  }
  if (net_.empty()) return invalidArgument("suncnn: empty ONNX model " + model_path);
  return finishInit();
}

Status SunCnnEstimator::init(const SunCnnOptions& options,
                             const std::vector<unsigned char>& model_bytes) {
  ready_ = false;
  SUNVO_RETURN_IF_ERROR(options.validate());
  options_ = options;
  if (model_bytes.empty()) return invalidArgument("suncnn: empty model bytes");
  try {
    net_ = cv::dnn::readNetFromONNX(model_bytes);
  } catch (const cv::Exception& e) {
    return invalidArgument(std::string("suncnn: cannot parse ONNX model bytes: ") + e.msg);
  }
  if (net_.empty()) return invalidArgument("suncnn: empty ONNX model (bytes)");
  return finishInit();
}

Status SunCnnEstimator::finishInit() {
  const SunCnnOptions& o = options_;
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  rng_.seed(o.seed);
  small3_.create(o.input_height, o.input_width, CV_8UC3);
  small1_.create(o.input_height, o.input_width, CV_8UC1);
  const int blob_shape[] = {1, o.input_channels, o.input_height, o.input_width};
  blob_.create(4, blob_shape, CV_32F);
  blob_.setTo(cv::Scalar(0.0));
  mask1_.create(o.mask_rows, o.mask1_size, CV_32F);
  mask2_.create(o.mask_rows, o.mask2_size, CV_32F);
  mask1_.setTo(cv::Scalar(1.0));
  mask2_.setTo(cv::Scalar(1.0));
  // With a feature prior, each member's trunk output is read too: the graph's Flatten nodes
  // (one per member, in member order: "onnx_node!/Flatten", "..._1", ...).
  out_names_.assign(1, "azimuth_cs");
  if (!o.feature_prior.empty() || !o.gray_feature_prior.empty()) {
    std::vector<cv::String> trunks;
    for (const cv::String& n : net_.getLayerNames()) {
      const std::string s = n;
      if (s.rfind("onnx_node!/Flatten", 0) == 0 && s.find("/flatten") == std::string::npos)
        trunks.push_back(n);
    }
    std::sort(trunks.begin(), trunks.end(), [](const cv::String& a, const cv::String& b) {
      return a.size() != b.size() ? a.size() < b.size() : a < b;
    });
    if (static_cast<int>(trunks.size()) != o.ensemble_members)
      return invalidArgument("suncnn: the model has " + std::to_string(trunks.size()) +
                             " trunk outputs (Flatten nodes), suncnn.feature_prior needs one per "
                             "member (" +
                             std::to_string(o.ensemble_members) + ")");
    out_names_.insert(out_names_.end(), trunks.begin(), trunks.end());
  }
  // One forward pass checks the model against the shapes the options promise.
  try {
    net_.setInput(blob_, "image");
    net_.setInput(mask1_, "mask1");
    net_.setInput(mask2_, "mask2");
    net_.forward(outs_, out_names_);
    out_ = outs_[0];
    for (std::size_t i = 1; i < outs_.size(); ++i)
      if (outs_[i].total() != static_cast<std::size_t>(o.mask1_size))
        return invalidArgument("suncnn: trunk output " + std::string(out_names_[i]) + " has " +
                               std::to_string(outs_[i].total()) + " values, suncnn.mask1_size is " +
                               std::to_string(o.mask1_size));
  } catch (const cv::Exception& e) {
    return invalidArgument(
        "suncnn: the model does not run with the shapes of suncnn.input_width/input_height/"
        "input_channels/mask_rows/mask1_size/mask2_size: " +
        e.msg);
  }
  const std::size_t expected = static_cast<std::size_t>(o.ensemble_members * o.mask_rows) * 2;
  if (out_.total() != expected)
    return invalidArgument(
        "suncnn: model output has " + std::to_string(out_.total()) +
        " values, expected suncnn.ensemble_members x mask_rows x 2 = " + std::to_string(expected));
  ready_ = true;
  return Status::ok();
}

void SunCnnEstimator::fillMasks() {
  // Inverted dropout, as torch.nn.Dropout in training: keep with probability 1 - p, scaled by
  // 1 / (1 - p). Row 0 stays all ones (dropout off); rows beyond mc_samples are not read.
  const float keep = static_cast<float>(1.0 / (1.0 - options_.dropout_p));
  std::bernoulli_distribution dropped(options_.dropout_p);
  for (cv::Mat* m : {&mask1_, &mask2_}) {
    m->row(0).setTo(cv::Scalar(1.0));
    for (int r = 1; r <= options_.mc_samples; ++r) {
      float* p = m->ptr<float>(r);
      for (int j = 0; j < m->cols; ++j) p[j] = dropped(rng_) ? 0.0f : keep;
    }
  }
}

Expected<cv::Mat> SunCnnEstimator::forwardRaw(const cv::Mat& blob, const cv::Mat& mask1,
                                              const cv::Mat& mask2) {
  if (!ready_) return failedPrecondition("suncnn: estimator not initialised");
  try {
    net_.setInput(blob, "image");
    net_.setInput(mask1, "mask1");
    net_.setInput(mask2, "mask2");
    return net_.forward("azimuth_cs").clone();
  } catch (const cv::Exception& e) {
    return invalidArgument(std::string("suncnn: forward failed: ") + e.msg);
  }
}

Expected<sunfusion::ImageSunEstimate> SunCnnEstimator::estimate(
    const sunfusion::ImageSunInput& input) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!ready_) return failedPrecondition("suncnn: estimator not initialised (call init)");
  const cv::Mat& img = input.color;
  const SunCnnOptions& o = options_;
  if (img.empty()) return invalidArgument("suncnn: empty image");
  if (img.type() != CV_8UC3 && img.type() != CV_8UC1)
    return invalidArgument("suncnn: image must be CV_8UC3 (BGR) or CV_8UC1 (grey)");
  if (input.camera.width > 0 && input.camera.height > 0 &&
      (img.cols != input.camera.width || img.rows != input.camera.height))
    return invalidArgument("suncnn: image " + std::to_string(img.cols) + "x" +
                           std::to_string(img.rows) + " differs from the camera's " +
                           std::to_string(input.camera.width) + "x" +
                           std::to_string(input.camera.height));
  if (img.cols < o.input_width || img.rows < o.input_height)
    return invalidArgument("suncnn: image smaller than the network input " +
                           std::to_string(o.input_width) + "x" + std::to_string(o.input_height));

  // Pre-processing exactly as in training: INTER_AREA resize, then the model's planes (BGR, or
  // BT.601 luma 0.114 B + 0.587 G + 0.299 R), (v/255 - mean)/std.
  const bool grey_in = img.type() == CV_8UC1;
  cv::Mat& small = grey_in ? small1_ : small3_;
  cv::resize(img, small, small.size(), 0.0, 0.0, cv::INTER_AREA);
  const float a = static_cast<float>(1.0 / (255.0 * o.pixel_std));
  const float b = static_cast<float>(-o.pixel_mean / o.pixel_std);
  const int plane = o.input_width * o.input_height;
  float* dst = blob_.ptr<float>();
  for (int y = 0; y < o.input_height; ++y) {
    const unsigned char* src = small.ptr<unsigned char>(y);
    for (int x = 0; x < o.input_width; ++x) {
      const int at = y * o.input_width + x;
      if (grey_in) {
        const float v = static_cast<float>(src[x]) * a + b;
        for (int c = 0; c < o.input_channels; ++c) dst[c * plane + at] = v;
      } else if (o.input_channels == 3) {
        for (int c = 0; c < 3; ++c)
          dst[c * plane + at] = static_cast<float>(src[3 * x + c]) * a + b;
      } else {
        const float luma = 0.114f * src[3 * x] + 0.587f * src[3 * x + 1] + 0.299f * src[3 * x + 2];
        dst[at] = luma * a + b;
      }
    }
  }
  fillMasks();
  try {
    net_.setInput(blob_, "image");
    net_.setInput(mask1_, "mask1");
    net_.setInput(mask2_, "mask2");
    net_.forward(outs_, out_names_);
  } catch (const cv::Exception& e) {
    return invalidArgument(std::string("suncnn: forward failed: ") + e.msg);
  }
  const int M = o.ensemble_members, K = o.mask_rows;
  if (outs_.size() != out_names_.size() || outs_[0].total() != static_cast<std::size_t>(M * K) * 2)
    return invalidArgument("suncnn: unexpected model output size");
  const float* out = outs_[0].ptr<float>();

  SunCnnRaw raw;
  double sum_c = 0.0, sum_s = 0.0;
  for (int m = 0; m < M; ++m) {
    const float* member = out + 2 * m * K;
    raw.c += static_cast<double>(member[0]) / M;
    raw.s += static_cast<double>(member[1]) / M;
    for (int r = 1; r <= o.mc_samples; ++r) {
      const double c = static_cast<double>(member[2 * r]);
      const double s = static_cast<double>(member[2 * r + 1]);
      const double n = std::hypot(c, s);
      if (n > 1e-9 && std::isfinite(n)) {
        sum_c += c / n;
        sum_s += s / n;
      }  // a zero or non-finite sample adds no direction: it lowers R_mc
    }
  }
  raw.r_mc = o.mc_samples > 0 ? std::hypot(sum_c, sum_s) / (M * o.mc_samples) : 1.0;
  const bool finite = std::isfinite(raw.c) && std::isfinite(raw.s);
  if (!finite) raw.c = raw.s = 0.0;  // no direction; sigma goes to its cap below
  raw.r_al = std::min(std::hypot(raw.c, raw.s), 1.0);
  raw.gray_calibration = grey_in && o.input_channels == 3;
  const double scale = raw.gray_calibration ? o.gray_sigma_scale : o.sigma_scale;
  const double max_valid =
      raw.gray_calibration ? o.gray_max_valid_sigma_rad : o.max_valid_sigma_rad;
  const double gain = raw.gray_calibration ? o.gray_elevation_gain : o.elevation_gain;
  raw.elevation_tan2 = input.prior ? elevationTan2(*input.prior) : 0.0;
  const SunCnnFeaturePrior& fp = raw.gray_calibration ? o.gray_feature_prior : o.feature_prior;
  const double f_gain = raw.gray_calibration ? o.gray_feature_gain : o.feature_gain;
  if (!fp.empty()) {  // then out_names_ holds the M trunks, and outs_ matched it above
    double d = 0.0;
    for (int m = 0; m < M; ++m) d += fp.memberDistance(m, outs_[1 + m].ptr<float>()) / M;
    raw.feature_distance = d;
    raw.feature_weakness = featureWeakness(d);
  }
  raw.sigma_rad =
      std::clamp(scale * std::sqrt(circularStdSquared(raw.r_mc) + circularStdSquared(raw.r_al) +
                                   gain * raw.elevation_tan2 + f_gain * raw.feature_weakness),
                 o.sigma_min_rad, o.sigma_max_rad);
  raw_ = raw;

  sunfusion::ImageSunEstimate e;
  const double az = raw.r_al > 0.0 ? std::atan2(raw.s, raw.c) : 0.0;
  e.azimuth_deg = az * kRadToDeg;
  if (e.azimuth_deg <= -180.0) e.azimuth_deg += 360.0;
  e.zenith_deg = 90.0;
  e.confidence = std::clamp(raw.r_mc * raw.r_al, 0.0, 1.0);
  e.measurement.kind = sunfusion::SunMeasurementKind::kAzimuthOnly;
  e.measurement.sun_c = Eigen::Vector3d(std::sin(az), 0.0, std::cos(az));
  e.measurement.sigma = raw.sigma_rad;
  bool upright = true;
  if (input.prior) {
    const Eigen::Vector3d& up_c = input.prior->up_c;
    const double n = up_c.norm();
    upright = n > 1e-9 && std::isfinite(n) &&
              std::acos(std::clamp(-up_c.y() / n, -1.0, 1.0)) * kRadToDeg <= o.max_up_tilt_deg;
  }
  e.valid = finite && upright && raw.sigma_rad <= max_valid;
  e.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return e;
}

}  // namespace sunvo::suncnn
