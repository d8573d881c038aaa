#pragma once
// Synthetic stereo images for the front-end tests: a random blob texture, shifted crops of it, and
// the camera they are seen through.

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/core/camera.hpp"

namespace sunvo {

inline constexpr int kW = 640;  // synthetic image size, px
inline constexpr int kH = 240;

// A random texture with blobs of a few pixels: uniform noise at 1/3 resolution, upsampled by
// bicubic interpolation; float, (kW + 200) x (kH + 100) so that shifted crops stay inside.
inline cv::Mat makeTexture(std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse((kH + 100) / 3 + 2, (kW + 200) / 3 + 2, CV_32F);
  rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat fine;
  cv::resize(coarse, fine, cv::Size(coarse.cols * 3, coarse.rows * 3), 0, 0, cv::INTER_CUBIC);
  return fine;
}

// out(x, y) = texture(x + ox, y + oy) as CV_8UC1 of kW x kH (bicubic for fractional offsets).
inline cv::Mat crop(const cv::Mat& texture, double ox, double oy) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1.0, 0.0, ox + 50.0, 0.0, 1.0, oy + 30.0);
  cv::Mat f;
  cv::warpAffine(texture, f, m, cv::Size(kW, kH), cv::INTER_CUBIC | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REFLECT);
  cv::Mat out;
  f.convertTo(out, CV_8U);
  return out;
}

inline StereoCamera syntheticCamera() {
  StereoCamera cam;
  cam.fu = 500.0;
  cam.fv = 500.0;
  cam.cu = kW / 2.0;
  cam.cv = kH / 2.0;
  cam.baseline_m = 0.5;
  cam.width = kW;
  cam.height = kH;
  return cam;
}

}  // namespace sunvo
