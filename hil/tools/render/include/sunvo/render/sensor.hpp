#pragma once
// The camera applied to POV-Ray's output: exposure gain, vignetting, blur, white balance, shot
// and read noise, and the camera's response curve (tone curve) back to 8 bits.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

#include "sunvo/core/status.hpp"

namespace sunvo::render {

struct SensorOptions {
  double full_well_e =
      8000.0;  // electrons at saturation (shot noise), [100, 1e6]; 0 = no shot noise
  double read_noise_e = 12.0;    // read noise std, electrons, [0, 1000]
  double vignetting = 0.3;       // 0 = none; fraction of the cos^4 fall-off applied, [0, 1]
  double exposure_sigma = 0.02;  // per-frame log-gain innovation (AR(1), 0.9), [0, 0.5]
  double exposure_target =
      0.3;  // linear value of an albedo-0.25 patch under E_sky + E_sun max(cos z_s, 0.5), (0, 1]
  double motion_blur_px = 0.0;    // horizontal box blur length, px, [0, 20]; 0 = off
  double defocus_sigma_px = 0.0;  // Gaussian blur (defocus, lens) std, px, [0, 5]; 0 = off
  double white_balance_r = 1.0;   // red gain in linear light (camera white balance), [0.5, 2]
  double white_balance_b = 1.0;   // blue gain in linear light, [0.5, 2]
  // Response (tone) curve from linear signal s in [0, 1] to the 8-bit code value:
  //   srgb   IEC 61966-2-1 sRGB encoding
  //   gamma  s^(1/gamma)
  //   scurve sRGB, then a smoothstep contrast curve y + contrast (y_s - y), y_s = 3y^2 - 2y^3
  //   filmic a saturating shoulder (1 + 1/w^2) s / (1 + s) (Reinhard, white point w = 2),
  //          then s^(1/gamma)
  std::string response = "srgb";  // srgb | gamma | scurve | filmic
  double gamma = 2.2;             // exponent of gamma and filmic, [1, 3.5]
  double contrast = 0.0;          // scurve strength, [0, 1]
  Status validate() const;        // names the key ("sensor.gamma ...")
};

// sRGB transfer function and its inverse (IEC 61966-2-1).
double srgbToLinear(double c);
double linearToSrgb(double l);

// The response curve of `o` at linear signal s (clamped to [0, 1]); returns [0, 1].
double responseCurve(const SensorOptions& o, double s);

// Applies exposure gain, vignetting, blur, white balance, noise and the response curve to a
// BGR8 image (sRGB-encoded, as POV-Ray writes it). Deterministic for noise_seed.
cv::Mat applySensor(const cv::Mat& bgr8, const SensorOptions& o, double gain, double fu, double cu,
                    double cv_px, std::uint64_t noise_seed);

}  // namespace sunvo::render
