// The wall cue of LalondeEstimator (see lalonde_estimator.hpp for the model).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::sunvision {
namespace {
// sRGB 8-bit -> linear [0, 1] (IEC 61966-2-1); only the ratio's sign must survive another curve.
double linearOf(unsigned char v8) {
  const double v = v8 / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

double median(std::vector<float>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}
}  // namespace

void LalondeEstimator::wallCue(const cv::Mat& work_gray, double scale) {
  cues_.wall_loglik.setTo(0.0);
  cues_.wall_informative = false;
  cues_.wall_log_ratio = 0.0;
  const int w = work_gray.cols, h = work_gray.rows;
  const int side_w = std::max(1, static_cast<int>(options_.wall_side_fraction * w));
  const double min_up = std::sin(options_.wall_min_elevation_deg * std::numbers::pi / 180.0);
  wall_left_.clear();
  wall_right_.clear();
  int side_pixels = 0;  // pixels above the horizon in one side band (sky or not)
  for (int y = 0; y < h; ++y) {
    const unsigned char* g = work_gray.ptr<unsigned char>(y);
    const unsigned char* sky = cues_.sky_mask.ptr<unsigned char>(y);
    for (int x = 0; x < w; ++x) {
      if (x >= side_w && x < w - side_w) continue;
      if (rayAt((x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5).dot(cues_.horizon.up_c) <
          min_up) {
        continue;
      }
      if (x < side_w) ++side_pixels;
      if (sky[x] != 0) continue;
      (x < side_w ? wall_left_ : wall_right_).push_back(static_cast<float>(linearOf(g[x])));
    }
  }
  const double needed = std::max(1.0, options_.wall_min_share * side_pixels);
  if (static_cast<double>(wall_left_.size()) < needed ||
      static_cast<double>(wall_right_.size()) < needed) {
    return;
  }
  const double left = median(wall_left_), right = median(wall_right_);
  constexpr double kDark = 1e-3;  // linear level below which a side is black (no information)
  if (left < kDark && right < kDark) return;
  cues_.wall_log_ratio = std::log(std::max(left, kDark) / std::max(right, kDark));
  cues_.wall_informative = true;
  const double q = 1.0 / (1.0 + std::exp(-cues_.wall_log_ratio / options_.wall_log_ratio_scale));
  const double weight = options_.wall_max_weight * (2.0 * q - 1.0);
  // g = sin phi sin theta / wall_side_band clamped to [-1, 1]: flat over most of each side, so
  // the cue picks a side without pulling the estimate toward phi = +-90 deg.
  for (int r = 0; r < n_zen_; ++r) {
    double* out = cues_.wall_loglik.ptr<double>(r);
    const double st = std::sin(zenithOfRowRad(r));
    for (int c = 0; c < n_az_; ++c) {
      const double g =
          std::clamp(std::sin(azimuthOfColRad(c)) * st / options_.wall_side_band, -1.0, 1.0);
      out[c] = std::log1p(weight * g);
    }
  }
}

}  // namespace sunvo::sunvision
