#pragma once
// StereoRectifier: raw stereo images in, the rectified pair of StereoCamera out.
//
// Computed once from a RawStereoCalibration: cv::stereoRectify (CALIB_ZERO_DISPARITY, free
// scaling `alpha`) or, for the equidistant model, cv::fisheye::stereoRectify (balance = alpha),
// then cv::initUndistortRectifyMap into fixed-point maps (CV_16SC2 + CV_16UC1). Per frame, a
// bilinear remap with those maps (the arithmetic of cv::remap's INTER_LINEAR, black outside the
// raw image; cv::remap itself allocates block buffers on every call) writes into the caller's
// Mats, which are allocated by the first frame and reused after: a frame allocates nothing
// (tests/calib/rectifier_test.cpp counts it) and runs on the calling thread.
//
// Frames: l = raw left camera, r = raw right, c = the rectified left camera (the estimator's
// camera frame). stereoRectify's R1 is C_c_l (p_c = C_c_l p_l); both rectified cameras share the
// orientation of c, the right one at +baseline along c's x axis. The rectified left camera's
// optical centre is the raw left camera's.

#include <Eigen/Core>
#include <memory>

#include "sunvo/calib/stereo_calibration.hpp"
#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"

namespace sunvo::calib {

struct RectifyOptions {
  // [0, 1]: stereoRectify's free scaling. 0 = the rectified images show only valid pixels
  // (zoomed in, no black border); 1 = every raw pixel is kept (black corners). For the
  // equidistant model it is cv::fisheye::stereoRectify's balance.
  double alpha = 0.0;
  Status validate() const;  // names the key ("alpha: 2 is outside [0, 1]")
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("alpha", s.alpha);
  }
};

class StereoRectifier {
 public:
  static Expected<std::unique_ptr<StereoRectifier>> create(const RawStereoCalibration& calib,
                                                           const RectifyOptions& options = {});

  // The rectified pair: fu = fv, (cu, cv) shared by both eyes, baseline |t|, the raw image size.
  const StereoCamera& camera() const { return camera_; }
  // p_c = C_c_l p_l: the rectified left camera from the raw left camera (stereoRectify's R1).
  const Eigen::Matrix3d& C_c_l() const { return C_c_l_; }
  // The raw image size the maps expect (the calibration's).
  cv::Size rawSize() const { return raw_size_; }

  // raw.left / raw.right (CV_8UC1, raw size) -> out.left / out.right, and raw.left_color ->
  // out.left_color when raw has one (CV_8UC3). out's Mats are (re)allocated only when their size
  // or type differs. Times and sequence are copied. Fails (naming the eye) on a wrong size or
  // type; never allocates on success once warm.
  Status rectify(const StereoFrame& raw, StereoFrame& out) const;
  // One image of one eye (right = false: left), CV_8UC1 or CV_8UC3.
  Status rectifyEye(const cv::Mat& raw, bool right, cv::Mat& out) const;

  // The maps (for tests and tools): map1 CV_16SC2, map2 CV_16UC1 of the rectified size.
  const cv::Mat& map1(bool right) const { return right ? map1_right_ : map1_left_; }
  const cv::Mat& map2(bool right) const { return right ? map2_right_ : map2_left_; }

 private:
  StereoRectifier() = default;
  StereoCamera camera_;
  Eigen::Matrix3d C_c_l_ = Eigen::Matrix3d::Identity();
  cv::Size raw_size_;
  cv::Mat map1_left_, map2_left_, map1_right_, map2_right_;
};

}  // namespace sunvo::calib
