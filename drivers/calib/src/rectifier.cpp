#include "sunvo/calib/rectifier.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace sunvo::calib {
namespace {

// Pixels per remap call: OpenCV's remap asks parallel_for_ for total / 2^16 stripes, and one
// stripe runs inline on the calling thread (no job object, no worker wake-up).
constexpr int kBandPixels = 1 << 16;

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
  const int band_rows = std::max(1, kBandPixels / std::max(1, out.cols));
  for (int r0 = 0; r0 < out.rows; r0 += band_rows) {
    const cv::Range rows(r0, std::min(out.rows, r0 + band_rows));
    cv::Mat dst = out.rowRange(rows);
    cv::remap(raw, dst, m1.rowRange(rows), m2.rowRange(rows), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar::all(0));
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
