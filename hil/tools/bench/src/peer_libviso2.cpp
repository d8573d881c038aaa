// sunvo_bench_vo's libviso2 peer: VisualOdometryStereo (A. Geiger's libviso2, GPL, built outside
// this tree and linked from SUNVO_LIBVISO2_DIR) with the parameters of its KITTI demo: calibration
// f, cu, cv, base from the same calib.txt sunvo reads, everything else libviso2's defaults (quad
// matching, half-resolution + multi-stage, bucketing 2 per 50x50 px, 200 RANSAC iterations,
// 2 px inlier threshold, reweighting). Frames are handed over as the same 8-bit grey buffers
// sunvo reads (no copy: dims = width, height, bytes per line); libviso2 copies them into its own
// aligned buffers inside process(), which is part of its timed work.

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "sunvo/bench/peer.hpp"
#include "viso_stereo.h"

namespace sunvo::bench {
namespace {

VisualOdometryStereo::parameters kittiDemoParameters(const StereoCamera& camera) {
  VisualOdometryStereo::parameters param;
  param.calib.f = camera.fu;
  param.calib.cu = camera.cu;
  param.calib.cv = camera.cv;
  param.base = camera.baseline_m;
  return param;
}

class Libviso2Odometry final : public PeerOdometry {
 public:
  explicit Libviso2Odometry(const StereoCamera& camera) : viso_(kittiDemoParameters(camera)) {}

  bool process(const cv::Mat& left, const cv::Mat& right) override {
    const cv::Mat* l = &left;
    const cv::Mat* r = &right;
    if (left.type() != CV_8UC1) {  // libviso2 reads 8-bit single-channel rows
      cv::cvtColor(left, grey_left_, cv::COLOR_BGR2GRAY);
      cv::cvtColor(right, grey_right_, cv::COLOR_BGR2GRAY);
      l = &grey_left_;
      r = &grey_right_;
    }
    if (l->size() != r->size() || l->step[0] != r->step[0] || l->empty()) return false;
    int32_t dims[3] = {l->cols, l->rows, static_cast<int32_t>(l->step[0])};
    return viso_.process(l->data, r->data, dims);
  }
  // libviso2's getters are not const.
  int matches() const override { return viso_.getNumberOfMatches(); }
  int inliers() const override { return viso_.getNumberOfInliers(); }
  double translationM() const override {
    const Matrix T = viso_.getMotion();
    return std::sqrt(T.val[0][3] * T.val[0][3] + T.val[1][3] * T.val[1][3] +
                     T.val[2][3] * T.val[2][3]);
  }

 private:
  mutable VisualOdometryStereo viso_;
  cv::Mat grey_left_, grey_right_;
};

}  // namespace

std::unique_ptr<PeerOdometry> makeLibviso2(const StereoCamera& camera) {
  return std::make_unique<Libviso2Odometry>(camera);
}

}  // namespace sunvo::bench
