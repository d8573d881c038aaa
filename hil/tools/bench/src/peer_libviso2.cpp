// sunvo_bench_vo's libviso2 peer: VisualOdometryStereo (A. Geiger's libviso2, GPL, built outside
// this tree and linked from SUNVO_LIBVISO2_DIR) with the parameters of its KITTI demo: calibration
// f, cu, cv, base from the same calib.txt sunvo reads, everything else libviso2's defaults (quad
// matching, half-resolution + multi-stage, bucketing 2 per 50x50 px, 200 RANSAC iterations,
// 2 px inlier threshold, reweighting). Frames are handed over as the same 8-bit grey buffers
// sunvo reads (no copy: dims = width, height, bytes per line); libviso2 copies them into its own
// aligned buffers inside process(), which is part of its timed work.

#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/bench/peer.hpp"
#include "viso_stereo.h"

namespace sunvo::bench {

Expected<PeerRun> runLibviso2(const KittiFrames& data, const BenchConfig& config) {
  const std::size_t n = data.frames.size();
  if (n < 2) return Status(StatusCode::kInvalidArgument, "libviso2 peer: needs >= 2 frames");
  // libviso2 reads 8-bit single-channel images; sunvo's KITTI frames already are, but convert
  // (outside the timed calls) should a colour sequence be given.
  std::vector<cv::Mat> left(n), right(n);
  for (std::size_t k = 0; k < n; ++k) {
    const cv::Mat& l = data.frames[k].left;
    const cv::Mat& r = data.frames[k].right;
    if (l.size() != r.size() || l.empty()) {
      return Status(StatusCode::kInvalidArgument,
                    "libviso2 peer: frame " + std::to_string(k) + " has unequal or empty images");
    }
    if (l.type() == CV_8UC1) {
      left[k] = l;
      right[k] = r;
    } else {
      cv::cvtColor(l, left[k], cv::COLOR_BGR2GRAY);
      cv::cvtColor(r, right[k], cv::COLOR_BGR2GRAY);
    }
  }

  VisualOdometryStereo::parameters param;
  param.calib.f = data.camera.fu;
  param.calib.cu = data.camera.cu;
  param.calib.cv = data.camera.cv;
  param.base = data.camera.baseline_m;
  VisualOdometryStereo viso(param);

  PeerRun run;
  run.name = "libviso2";
  auto feed = [&](std::size_t index) {
    const std::size_t k = pingPong(index, n);
    int32_t dims[3] = {left[k].cols, left[k].rows, static_cast<int32_t>(left[k].step[0])};
    return viso.process(left[k].data, right[k].data, dims);
  };
  std::size_t i = 0;
  for (int w = 0; w < config.warmup; ++w, ++i) (void)feed(i);
  for (int f = 0; f < config.frames; ++f, ++i) {
    const double cpu0 = threadCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = feed(i);
    const auto t1 = std::chrono::steady_clock::now();
    const double cpu1 = threadCpuMs();
    run.wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    run.cpu_ms.push_back(cpu1 - cpu0);
    run.matches.push_back(viso.getNumberOfMatches());
    run.inliers.push_back(viso.getNumberOfInliers());
    if (!ok) {
      ++run.failures;
      continue;
    }
    const Matrix T = viso.getMotion();
    run.translation_m.push_back(std::sqrt(T.val[0][3] * T.val[0][3] + T.val[1][3] * T.val[1][3] +
                                          T.val[2][3] * T.val[2][3]));
  }
  return run;
}

}  // namespace sunvo::bench
