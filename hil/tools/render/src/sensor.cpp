#include "sunvo/render/sensor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace sunvo::render {
namespace {
Status range(const char* key, const char* r) {
  return invalidArgument(std::string("sensor.") + key + " out of range " + r);
}
}  // namespace

Status SensorOptions::validate() const {
  if (!(full_well_e == 0.0 || (full_well_e >= 100 && full_well_e <= 1e6)))
    return range("full_well_e", "0 or [100, 1e6]");
  if (!(read_noise_e >= 0 && read_noise_e <= 1000)) return range("read_noise_e", "[0, 1000]");
  if (!(vignetting >= 0 && vignetting <= 1)) return range("vignetting", "[0, 1]");
  if (!(exposure_sigma >= 0 && exposure_sigma <= 0.5)) return range("exposure_sigma", "[0, 0.5]");
  if (!(exposure_target > 0 && exposure_target <= 1)) return range("exposure_target", "(0, 1]");
  if (!(motion_blur_px >= 0 && motion_blur_px <= 20)) return range("motion_blur_px", "[0, 20]");
  if (!(defocus_sigma_px >= 0 && defocus_sigma_px <= 5)) return range("defocus_sigma_px", "[0, 5]");
  if (!(white_balance_r >= 0.5 && white_balance_r <= 2))
    return range("white_balance_r", "[0.5, 2]");
  if (!(white_balance_b >= 0.5 && white_balance_b <= 2))
    return range("white_balance_b", "[0.5, 2]");
  if (response != "srgb" && response != "gamma" && response != "scurve" && response != "filmic")
    return invalidArgument("sensor.response: '" + response +
                           "' is not one of srgb, gamma, scurve, filmic");
  if (!(gamma >= 1 && gamma <= 3.5)) return range("gamma", "[1, 3.5]");
  if (!(contrast >= 0 && contrast <= 1)) return range("contrast", "[0, 1]");
  return Status::ok();
}

double srgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double linearToSrgb(double l) {
  l = std::clamp(l, 0.0, 1.0);
  return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

double responseCurve(const SensorOptions& o, double s) {
  s = std::clamp(s, 0.0, 1.0);
  if (o.response == "gamma") return std::pow(s, 1.0 / o.gamma);
  if (o.response == "filmic") {
    constexpr double kWhite = 2.0;  // linear value mapped to 1 (s in [0, 1] stays below it)
    const double t = (1.0 + 1.0 / (kWhite * kWhite)) * s / (1.0 + s);
    return std::pow(std::clamp(t, 0.0, 1.0), 1.0 / o.gamma);
  }
  const double y = linearToSrgb(s);
  if (o.response == "scurve") return y + o.contrast * (y * y * (3.0 - 2.0 * y) - y);
  return y;
}

cv::Mat applySensor(const cv::Mat& bgr8, const SensorOptions& o, double gain, double fu, double cu,
                    double cv_px, std::uint64_t noise_seed) {
  cv::Mat lin(bgr8.size(), CV_32FC3);
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = static_cast<float>(srgbToLinear(i / 255.0));
  for (int y = 0; y < bgr8.rows; ++y)
    for (int x = 0; x < bgr8.cols; ++x) {
      const cv::Vec3b p = bgr8.at<cv::Vec3b>(y, x);
      lin.at<cv::Vec3f>(y, x) = cv::Vec3f(lut[p[0]], lut[p[1]], lut[p[2]]);
    }
  if (o.motion_blur_px >= 1.0) {
    const int k = static_cast<int>(std::lround(o.motion_blur_px));
    cv::blur(lin, lin, cv::Size(k, 1));
  }
  if (o.defocus_sigma_px > 0.0) cv::GaussianBlur(lin, lin, cv::Size(0, 0), o.defocus_sigma_px);
  // Response curve as a table over the normalised signal (4096 steps: finer than 8 bits).
  constexpr int kSteps = 4096;
  std::array<unsigned char, kSteps + 1> curve{};
  for (int i = 0; i <= kSteps; ++i)
    curve[static_cast<std::size_t>(i)] =
        static_cast<unsigned char>(std::lround(255.0 * responseCurve(o, double(i) / kSteps)));
  const bool classic = o.response == "srgb";
  const double wb[3] = {o.white_balance_b, 1.0, o.white_balance_r};  // B, G, R
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<float> N01(0.0f, 1.0f);
  cv::Mat out(bgr8.size(), CV_8UC3);
  const double fw = o.full_well_e > 0 ? o.full_well_e : 8000.0;
  for (int y = 0; y < bgr8.rows; ++y)
    for (int x = 0; x < bgr8.cols; ++x) {
      // Natural vignetting cos^4(angle off axis), applied with strength o.vignetting.
      const double r2 = ((x - cu) * (x - cu) + (y - cv_px) * (y - cv_px)) / (fu * fu);
      const double c4 = 1.0 / ((1.0 + r2) * (1.0 + r2));
      const double v = gain * (1.0 - o.vignetting * (1.0 - c4));
      cv::Vec3b& q = out.at<cv::Vec3b>(y, x);
      const cv::Vec3f p = lin.at<cv::Vec3f>(y, x);
      for (int c = 0; c < 3; ++c) {
        // Electrons e = fw * signal; shot noise sqrt(e), read noise sigma_r (Gaussian approx.).
        const double e = fw * std::min(static_cast<double>(p[c]) * v * wb[c], 1.2);
        const double sigma =
            std::sqrt((o.full_well_e > 0 ? e : 0.0) + o.read_noise_e * o.read_noise_e);
        const double s = (e + sigma * static_cast<double>(N01(rng))) / fw;
        // The sRGB curve is evaluated exactly (the classic look's images stay bit-identical).
        q[c] = classic
                   ? static_cast<unsigned char>(std::lround(255.0 * linearToSrgb(s)))
                   : curve[static_cast<std::size_t>(std::lround(std::clamp(s, 0.0, 1.0) * kSteps))];
      }
    }
  return out;
}

}  // namespace sunvo::render
