// Tests of correct_edge_columns (frontend_rows.cpp): the row-offset plane fitted to the measured
// right rows, and the columns of edge matches moved along their edges, on synthetic pairs whose
// right rows are off by a known plane (a rig turned in pitch and roll).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/frontend/stereo_frontend.hpp"
#include "synthetic_pair.hpp"

namespace sunvo {
namespace {

// The blob texture with slanted stripes over it (edges at 35-70 deg from level, whose windows
// are edges for measureRightRow), float, the size of makeTexture's.
cv::Mat makeEdgyTexture(std::uint64_t seed) {
  cv::Mat t = makeTexture(seed) * 0.3;
  cv::RNG rng(seed + 100);
  for (int k = 0; k < 220; ++k) {
    const double angle = rng.uniform(35.0, 70.0) * (rng.uniform(0, 2) == 0 ? 1.0 : -1.0);
    const double len = rng.uniform(20.0, 60.0);
    const cv::Point2d c(rng.uniform(0.0, static_cast<double>(t.cols)),
                        rng.uniform(0.0, static_cast<double>(t.rows)));
    const cv::Point2d dir(std::cos(angle * CV_PI / 180.0), -std::sin(angle * CV_PI / 180.0));
    cv::line(t, c - dir * len, c + dir * len, cv::Scalar(rng.uniform(160.0, 250.0)), 5,
             cv::LINE_AA);
  }
  cv::GaussianBlur(t, t, cv::Size(0, 0), 1.0);
  return t;
}

// The right image: texture seen d px further left, its rows off by
// dv(x, y) = a + b (x - cu) / fu + c (y - cv) / fv px (a point of row Y on the left lies on row
// Y + dv on the right).
cv::Mat rightWithRowPlane(const cv::Mat& texture, double d, double a, double b, double c) {
  const StereoCamera cam = syntheticCamera();
  cv::Mat map_x(kH, kW, CV_32F);
  cv::Mat map_y(kH, kW, CV_32F);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const double dv = a + b * (x - cam.cu) / cam.fu + c * (y - cam.cv) / cam.fv;
      map_x.at<float>(y, x) = static_cast<float>(x + d + 50.0);
      map_y.at<float>(y, x) = static_cast<float>(y - dv + 30.0);
    }
  }
  cv::Mat f;
  cv::remap(texture, f, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  cv::Mat out;
  f.convertTo(out, CV_8U);
  return out;
}

// The options under test: right rows measured, edge columns moved when `correct`.
FrontendOptions rowOptions(bool correct) {
  FrontendOptions opt;
  opt.measure_v_right = true;
  opt.correct_edge_columns = correct;
  return opt;
}

struct EdgeErrors {
  double edge_mean = 0.0;  // signed mean disparity error of the unmeasured matches, px
  double edge_abs = 0.0;   // their mean |error|, px
  int edges = 0;
  FrontendStats stats;
};

// Three frames of the same pair (the plane's memory fills) and the errors of the last.
EdgeErrors run(bool correct, double a, double b, double c) {
  const cv::Mat texture = makeEdgyTexture(5);
  const double d = 15.0;
  StereoFrontend fe;
  EXPECT_TRUE(fe.init(rowOptions(correct), syntheticCamera()).isOk());
  const cv::Mat left = crop(texture, 0, 0);
  const cv::Mat right = rightWithRowPlane(texture, d, a, b, c);
  FrameFeatures out;
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(fe.process(left, right, k, k, out).isOk());
  EdgeErrors e;
  for (const auto& o : out.observations) {
    if (o.v_right_measured) continue;
    e.edge_mean += o.disparity() - d;
    e.edge_abs += std::abs(o.disparity() - d);
    ++e.edges;
  }
  e.edge_mean /= std::max(e.edges, 1);
  e.edge_abs /= std::max(e.edges, 1);
  e.stats = fe.lastStats();
  return e;
}

// Rows off by a pitch-like 0.6 px and a roll-like slope (0.8 px over half the image width): the
// plane comes back within 0.05 px, and the edge matches' disparity error falls to under half.
TEST(FrontendRows, EdgeColumnsFollowTheRowPlane) {
  const double a = 0.6;
  const double b = 0.8 * syntheticCamera().fu / (kW / 2.0);
  const EdgeErrors off = run(false, a, b, 0.0);
  const EdgeErrors on = run(true, a, b, 0.0);
  std::printf(
      "edges %d / %d, disparity error mean %+.3f / %+.3f px, mean |.| %.3f -> %.3f px; "
      "plane a %+.3f b %+.3f c %+.3f px (truth %+.3f %+.3f 0), %d moved\n",
      off.edges, on.edges, off.edge_mean, on.edge_mean, off.edge_abs, on.edge_abs,
      on.stats.row_offset_a_px, on.stats.row_offset_b_px, on.stats.row_offset_c_px, a, b,
      on.stats.edge_columns_moved);
  ASSERT_GE(on.edges, 40);
  EXPECT_EQ(off.stats.edge_columns_moved, 0);
  EXPECT_GE(on.stats.edge_columns_moved, on.edges / 2);
  EXPECT_NEAR(on.stats.row_offset_a_px, a, 0.05);
  EXPECT_NEAR(on.stats.row_offset_b_px * kW / 2.0 / syntheticCamera().fu, 0.8, 0.05);
  EXPECT_NEAR(on.stats.row_offset_c_px, 0.0, 0.1);
  EXPECT_LT(on.edge_abs, 0.5 * off.edge_abs);
}

// A rectified pair: the plane stays within 0.02 px of 0 and the edges' error does not grow.
TEST(FrontendRows, RectifiedPairIsLeftAlone) {
  const EdgeErrors off = run(false, 0.0, 0.0, 0.0);
  const EdgeErrors on = run(true, 0.0, 0.0, 0.0);
  std::printf("rectified: mean |error| %.3f -> %.3f px, plane a %+.3f b %+.3f c %+.3f\n",
              off.edge_abs, on.edge_abs, on.stats.row_offset_a_px, on.stats.row_offset_b_px,
              on.stats.row_offset_c_px);
  EXPECT_NEAR(on.stats.row_offset_a_px, 0.0, 0.02);
  EXPECT_LE(on.edge_abs, off.edge_abs + 0.01);
}

// A knock: five frames with the rows 0.6 px off, then the rows 0.8 px off the other way. Most of
// the new frame's rows miss the plane, so it restarts from that frame alone (flagged), and the
// plane is at the new offset at once (within 0.08 px: the one-step row measurement reads 0.55 for
// 0.6 on this synthetic texture); without a knock nothing restarts.
TEST(FrontendRows, AKnockRestartsThePlane) {
  const cv::Mat texture = makeEdgyTexture(6);
  const double d = 15.0;
  StereoFrontend fe;
  ASSERT_TRUE(fe.init(rowOptions(true), syntheticCamera()).isOk());
  const cv::Mat left = crop(texture, 0, 0);
  FrameFeatures out;
  const cv::Mat before = rightWithRowPlane(texture, d, 0.6, 0.0, 0.0);
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(fe.process(left, before, k, k, out).isOk());
    EXPECT_FALSE(fe.lastStats().row_offset_restarted) << k;
  }
  EXPECT_NEAR(fe.lastStats().row_offset_a_px, 0.6, 0.08);
  ASSERT_TRUE(fe.process(left, rightWithRowPlane(texture, d, -0.8, 0.0, 0.0), 5, 5, out).isOk());
  std::printf("after the knock: restarted %d, plane a %+.3f px from %d rows\n",
              fe.lastStats().row_offset_restarted ? 1 : 0, fe.lastStats().row_offset_a_px,
              fe.lastStats().row_offset_rows_used);
  EXPECT_TRUE(fe.lastStats().row_offset_restarted);
  EXPECT_NEAR(fe.lastStats().row_offset_a_px, -0.8, 0.08);
  EXPECT_GE(fe.lastStats().row_offset_rows_used, 30);
}

}  // namespace
}  // namespace sunvo
