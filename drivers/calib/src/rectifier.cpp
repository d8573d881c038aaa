#include "sunvo/calib/rectifier.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace sunvo::calib {
namespace {

// Bilinear remap with cv::initUndistortRectifyMap's fixed-point maps (map1 CV_16SC2: the integer
// source pixel (x, y); map2 CV_16UC1: the fraction as fy * 32 + fx in 1/32 px), black outside the
// source. cv::remap computes the same (its 8-bit tables differ in rounding by at most one grey
// level) but allocates block buffers on every call (RemapInvoker; 28 allocations for one 1242x375
// image with OpenCV 4.6, tests/calib/rectifier_test.cpp), so a frame could not be allocation-free
// through it.
// With weights w = (32 - f) or f per axis, out = (sum of w_x w_y * pixel + 512) >> 10.
template <int kChannels>
void remapBilinear(const cv::Mat& src, const cv::Mat& map1, const cv::Mat& map2, cv::Mat& dst) {
  constexpr int kBits = cv::INTER_BITS;  // 5
  constexpr int kTab = 1 << kBits;       // 32
  // Locals, not Mat fields: the byte stores below may alias anything, and would make the
  // compiler reload src's fields for every pixel.
  const int w = src.cols;
  const int h = src.rows;
  const std::uint8_t* const data = src.data;
  const std::size_t step = src.step[0];
  const int cols = dst.cols;
  const auto pixel = [&](int x, int y, int c) -> int {
    return (x >= 0 && y >= 0 && x < w && y < h) ? data[static_cast<std::size_t>(y) * step +
                                                       static_cast<std::size_t>(x * kChannels + c)]
                                                : 0;
  };
  for (int v = 0; v < dst.rows; ++v) {
    const auto* xy = map1.ptr<std::int16_t>(v);
    const auto* frac = map2.ptr<std::uint16_t>(v);
    std::uint8_t* out = dst.ptr<std::uint8_t>(v);
    for (int u = 0; u < cols; ++u, out += kChannels) {
      const int x = xy[2 * u];
      const int y = xy[2 * u + 1];
      const int fx = frac[u] & (kTab - 1);
      const int fy = frac[u] >> kBits;
      const int w00 = (kTab - fx) * (kTab - fy);
      const int w01 = fx * (kTab - fy);
      const int w10 = (kTab - fx) * fy;
      const int w11 = fx * fy;
      if (x >= 0 && y >= 0 && x + 1 < w && y + 1 < h) {
        const std::uint8_t* p0 = data + static_cast<std::size_t>(y) * step + x * kChannels;
        const std::uint8_t* p1 = p0 + step;
        for (int c = 0; c < kChannels; ++c) {
          const int sum =
              p0[c] * w00 + p0[kChannels + c] * w01 + p1[c] * w10 + p1[kChannels + c] * w11;
          out[c] = static_cast<std::uint8_t>((sum + 512) >> 10);
        }
      } else {
        for (int c = 0; c < kChannels; ++c) {
          const int sum = pixel(x, y, c) * w00 + pixel(x + 1, y, c) * w01 +
                          pixel(x, y + 1, c) * w10 + pixel(x + 1, y + 1, c) * w11;
          out[c] = static_cast<std::uint8_t>((sum + 512) >> 10);
        }
      }
    }
  }
}

}  // namespace

Status RectifyOptions::validate() const {
  if (!(alpha >= 0.0 && alpha <= 1.0)) {
    return invalidArgument("alpha: " + std::to_string(alpha) + " is outside [0, 1]");
  }
  return Status::ok();
}

Expected<std::unique_ptr<StereoRectifier>> StereoRectifier::create(
    const RawStereoCalibration& calib, const RectifyOptions& options) {
  SUNVO_RETURN_IF_ERROR(calib.validate());
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<StereoRectifier> r(new StereoRectifier());
  r->raw_size_ = calib.size;
  cv::Mat R1, R2, P1, P2, Q;
  const cv::Mat K1(calib.K_left), K2(calib.K_right), R(calib.C_r_l), T(calib.t_r_l);
  try {
    if (calib.model == DistortionModel::kEquidistant) {
      cv::fisheye::stereoRectify(K1, calib.D_left, K2, calib.D_right, calib.size, R, T, R1, R2, P1,
                                 P2, Q, cv::CALIB_ZERO_DISPARITY, calib.size, options.alpha);
      cv::fisheye::initUndistortRectifyMap(K1, calib.D_left, R1, P1, calib.size, CV_16SC2,
                                           r->map1_left_, r->map2_left_);
      cv::fisheye::initUndistortRectifyMap(K2, calib.D_right, R2, P2, calib.size, CV_16SC2,
                                           r->map1_right_, r->map2_right_);
    } else {
      cv::stereoRectify(K1, calib.D_left, K2, calib.D_right, calib.size, R, T, R1, R2, P1, P2, Q,
                        cv::CALIB_ZERO_DISPARITY, options.alpha, calib.size);
      cv::initUndistortRectifyMap(K1, calib.D_left, R1, P1, calib.size, CV_16SC2, r->map1_left_,
                                  r->map2_left_);
      cv::initUndistortRectifyMap(K2, calib.D_right, R2, P2, calib.size, CV_16SC2, r->map1_right_,
                                  r->map2_right_);
    }
  } catch (const cv::Exception& e) {
    return invalidArgument(calib.file + ": rectification failed: " + e.msg);
  }
  // P1 = [f 0 cu 0; 0 f cv 0; 0 0 1 0], P2 = [f 0 cu -f b; 0 f cv 0; 0 0 1 0] for a horizontal
  // pair whose right camera sits at +b along the rectified x axis.
  const double f = P1.at<double>(0, 0);
  const double tx = P2.at<double>(0, 3);
  const double ty = P2.at<double>(1, 3);
  if (std::abs(ty) > std::abs(tx)) {
    return invalidArgument(calib.file + ": T: the cameras are stacked vertically; sunvo needs a " +
                           "horizontal pair");
  }
  if (tx >= 0.0) {
    return invalidArgument(calib.file + ": T: the second camera is left of the first; swap the " +
                           "cameras (the first is the left one)");
  }
  if (!(f > 0.0) || !cv::checkRange(P1) || !cv::checkRange(P2)) {
    return invalidArgument(calib.file + ": rectification gave a degenerate projection");
  }
  StereoCamera& c = r->camera_;
  c.fu = f;
  c.fv = P1.at<double>(1, 1);
  c.cu = P1.at<double>(0, 2);
  c.cv = P1.at<double>(1, 2);
  c.baseline_m = -tx / f;
  c.width = calib.size.width;
  c.height = calib.size.height;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r->C_c_l_(i, j) = R1.at<double>(i, j);
  }
  SUNVO_RETURN_IF_ERROR(c.validate());
  return r;
}

Status StereoRectifier::rectifyEye(const cv::Mat& raw, bool right, cv::Mat& out) const {
  if (raw.size() != raw_size_) {
    return invalidArgument(std::string(right ? "right" : "left") +
                           " image: " + std::to_string(raw.cols) + "x" + std::to_string(raw.rows) +
                           " differs from the calibration's " + std::to_string(raw_size_.width) +
                           "x" + std::to_string(raw_size_.height));
  }
  if (raw.data == out.data) return invalidArgument("rectifyEye: in place is not possible");
  const cv::Mat& m1 = map1(right);
  const cv::Mat& m2 = map2(right);
  out.create(m1.size(), raw.type());  // no-op when warm
  switch (raw.type()) {
    case CV_8UC1:
      remapBilinear<1>(raw, m1, m2, out);
      break;
    case CV_8UC3:
      remapBilinear<3>(raw, m1, m2, out);
      break;
    default:
      return invalidArgument(std::string(right ? "right" : "left") +
                             " image: only CV_8UC1 and CV_8UC3 are rectified");
  }
  return Status::ok();
}

Status StereoRectifier::rectify(const StereoFrame& raw, StereoFrame& out) const {
  if (raw.left.type() != CV_8UC1 || raw.right.type() != CV_8UC1) {
    return invalidArgument("rectify: the grey images must be CV_8UC1");
  }
  SUNVO_RETURN_IF_ERROR(rectifyEye(raw.left, false, out.left));
  SUNVO_RETURN_IF_ERROR(rectifyEye(raw.right, true, out.right));
  if (!raw.left_color.empty())
    SUNVO_RETURN_IF_ERROR(rectifyEye(raw.left_color, false, out.left_color));
  if (!raw.right_color.empty()) {
    SUNVO_RETURN_IF_ERROR(rectifyEye(raw.right_color, true, out.right_color));
  }
  out.trigger_time_ns = raw.trigger_time_ns;
  out.sequence = raw.sequence;
  return Status::ok();
}

}  // namespace sunvo::calib
