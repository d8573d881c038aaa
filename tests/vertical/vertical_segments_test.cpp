#include "sunvo/vertical/vertical_segments.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "../support/kitti_first_frames.hpp"
#include "sunvo/vertical/vertical_estimator.hpp"
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::vertical {
namespace {

constexpr int kW = 1241, kH = 376;

// An antialiased line from (x0, y0) to (x1, y1), pixel centres at integers (cv::line, shift 4).
void drawLine(cv::Mat& img, double x0, double y0, double x1, double y1, int value) {
  const auto p = [](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(16.0 * x)),
                     static_cast<int>(std::lround(16.0 * y)));
  };
  cv::line(img, p(x0, y0), p(x1, y1), cv::Scalar(value), 3, cv::LINE_AA, 4);
}

// x of a segment's line at row y.
double xAt(const cv::Vec4d& s, double y) {
  return s[0] + (s[2] - s[0]) * (y - s[1]) / (s[3] - s[1]);
}

TEST(VerticalSegmentDetector, FindsVerticalAndLeaningEdgesWhereTheyAre) {
  cv::Mat img(kH, kW, CV_8UC1, cv::Scalar(70));
  drawLine(img, 300.3, 40.0, 300.3, 330.0, 200);   // vertical bar, centre column 300.3
  drawLine(img, 700.0, 60.0, 760.0, 320.0, 200);   // leaning 13 deg from the columns
  drawLine(img, 350.0, 200.0, 650.0, 210.0, 200);  // nearly horizontal: not wanted
  VerticalSegmentDetector det;
  ASSERT_TRUE(det.init(kW, kH, 640, 5.0, 256).isOk());
  EXPECT_EQ(det.factor(), 2);
  std::vector<cv::Vec4f> segs;
  ASSERT_TRUE(det.detect(img, 20.0, &segs).isOk());
  ASSERT_FALSE(segs.empty());
  // A bar has two edges, one each side of its centre (the antialiased 3-px line covers about
  // 5 px): their mean is the centre column to a tenth of a pixel, all along the bar.
  std::vector<double> bar;
  for (const cv::Vec4d s : segs) {
    if (std::abs(xAt(s, 150.0) - 300.3) < 4.0) {
      bar.push_back(xAt(s, 150.0));
      EXPECT_NEAR(xAt(s, 60.0), xAt(s, 310.0), 0.1);
      EXPECT_LT(s[1], 45.0);
      EXPECT_GT(s[3], 325.0);
    }
  }
  ASSERT_EQ(bar.size(), 2u);
  EXPECT_NEAR(0.5 * (bar[0] + bar[1]), 300.3, 0.1);
  EXPECT_GT(std::abs(bar[0] - bar[1]), 3.0);
  // Both edges of the leaning bar, their direction within 0.3 deg of the bar's.
  const double lean = std::atan2(60.0, 260.0);
  int leaning = 0;
  for (const cv::Vec4d s : segs) {
    const double a = std::atan2(s[2] - s[0], s[3] - s[1]);
    if (std::abs(xAt(s, 190.0) - 730.0) < 3.0) {
      ++leaning;
      EXPECT_NEAR(a, lean, 0.3 * std::numbers::pi / 180.0);
      EXPECT_GT(s[3] - s[1], 200.0);
    }
  }
  EXPECT_EQ(leaning, 2);
  // Nothing along the horizontal line.
  for (const cv::Vec4d s : segs) {
    EXPECT_GT(std::abs(s[3] - s[1]), 20.0 * std::cos(45.0 * std::numbers::pi / 180.0));
  }
  EXPECT_EQ(det.stats().segments, static_cast<int>(segs.size()));
}

TEST(VerticalSegmentDetector, ACornerIsTwoSegmentsNotOneBentOne) {
  cv::Mat img(kH, kW, CV_8UC1, cv::Scalar(60));
  // A bent pole: vertical from row 30 to 190, then leaning 25 deg down to row 350.
  const double bend_x = 500.0 + 160.0 * std::tan(25.0 * std::numbers::pi / 180.0);
  drawLine(img, 500.0, 30.0, 500.0, 190.0, 210);
  drawLine(img, 500.0, 190.0, bend_x, 350.0, 210);
  VerticalSegmentDetector det;
  ASSERT_TRUE(det.init(kW, kH, 640, 5.0, 256).isOk());
  std::vector<cv::Vec4f> segs;
  ASSERT_TRUE(det.detect(img, 20.0, &segs).isOk());
  int upper = 0, lower = 0;
  for (const cv::Vec4d s : segs) {
    const double a = std::atan2(s[2] - s[0], s[3] - s[1]) / (std::numbers::pi / 180.0);
    if (std::abs(a) < 1.0 && s[3] < 200.0) ++upper;
    if (std::abs(a - 25.0) < 1.0 && s[1] > 180.0) ++lower;
    EXPECT_TRUE(std::abs(a) < 1.0 || std::abs(a - 25.0) < 1.0) << "bent segment, " << a << " deg";
  }
  EXPECT_EQ(upper, 2);  // the pole's two edges
  EXPECT_EQ(lower, 2);
}

// Windows of a facade seen in perspective: short dark parallelograms whose sides are vertical
// and whose top and bottom slope toward the vanishing point, as above the horizon. The ends of a
// side's edge are pulled toward the sloping edges it meets, one way at the top and another at the
// bottom; the end points are left out of the fit, so every side is found vertical.
TEST(VerticalSegmentDetector, AShortEdgeBetweenSlopingCornersIsFoundVertical) {
  cv::Mat img(kH, kW, CV_8UC1, cv::Scalar(190));
  const double slope = std::tan(20.0 * std::numbers::pi / 180.0);
  for (int i = 0; i < 8; ++i) {
    const double x0 = 100.0 + 130.0 * i, x1 = x0 + 40.0, y0 = 60.0 + 7.0 * i, h = 46.0;
    const auto p = [](double x, double y) {
      return cv::Point(static_cast<int>(std::lround(16.0 * x)),
                       static_cast<int>(std::lround(16.0 * y)));
    };
    const cv::Point quad[4] = {p(x0, y0), p(x1, y0 - 40.0 * slope), p(x1, y0 - 40.0 * slope + h),
                               p(x0, y0 + h)};
    cv::fillConvexPoly(img, quad, 4, cv::Scalar(60), cv::LINE_AA, 4);
  }
  VerticalSegmentDetector det;
  ASSERT_TRUE(det.init(kW, kH, 640, 5.0, 256).isOk());
  std::vector<cv::Vec4f> segs;
  ASSERT_TRUE(det.detect(img, 30.0, &segs).isOk());
  int sides = 0;
  double sum = 0.0;
  for (const cv::Vec4d s : segs) {
    const double a = std::atan2(s[2] - s[0], s[3] - s[1]) / (std::numbers::pi / 180.0);
    if (std::abs(a) > 5.0) continue;
    ++sides;
    sum += a;
    EXPECT_LT(std::abs(a), 0.5) << "side at column " << s[0];
  }
  EXPECT_EQ(sides, 16);
  // Measured: 0.038 deg mean; 0.196 deg with the end points in the fit.
  EXPECT_LT(std::abs(sum / std::max(sides, 1)), 0.1);
}

TEST(VerticalSegmentDetector, BadInputIsAnErrorAndTheOutputIsBounded) {
  VerticalSegmentDetector det;
  std::vector<cv::Vec4f> segs;
  EXPECT_FALSE(det.detect(cv::Mat(kH, kW, CV_8UC1), 20.0, &segs).isOk());  // before init
  EXPECT_FALSE(det.init(4, 4, 640, 5.0, 10).isOk());
  EXPECT_FALSE(det.init(kW, kH, 640, 0.0, 10).isOk());
  ASSERT_TRUE(det.init(kW, kH, 640, 5.0, 3).isOk());
  const Status wrong = det.detect(cv::Mat(kH, kW - 1, CV_8UC1, cv::Scalar(0)), 20.0, &segs);
  EXPECT_FALSE(wrong.isOk());
  EXPECT_NE(wrong.toString().find("1241x376"), std::string::npos) << wrong.toString();
  EXPECT_FALSE(det.detect(cv::Mat(kH, kW, CV_8UC3, cv::Scalar::all(0)), 20.0, &segs).isOk());
  // Ten bars, room for three segments: three kept, the rest counted.
  cv::Mat img(kH, kW, CV_8UC1, cv::Scalar(50));
  for (int i = 0; i < 10; ++i)
    drawLine(img, 100.0 + 100.0 * i, 30.0, 100.0 + 100.0 * i, 340.0, 220);
  ASSERT_TRUE(det.detect(img, 20.0, &segs).isOk());
  EXPECT_EQ(segs.size(), 3u);
  EXPECT_EQ(det.stats().dropped_full, 17);
}

// The cue on the real KITTI frames: the default detector makes no heap allocation per call.
TEST(VerticalSegmentDetector, TheCueAllocatesNothingPerCallOnRealFrames) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  auto sample = sunvo::testing::loadKittiFirstFrames();
  ASSERT_TRUE(sample) << sample.status().toString();
  ASSERT_TRUE(runtime::allocCounterActive());
  VerticalEstimator est;
  ASSERT_TRUE(est.init(VerticalOptions{}, sample->camera).isOk());
  const Eigen::Vector3d level(0.0, -1.0, 0.0);
  std::uint64_t total = 0;
  int valid = 0;
  for (const auto& frame : sample->frames) {
    runtime::AllocationScope scope;
    auto m = est.estimate(frame.left, level);
    total += scope.count();
    ASSERT_TRUE(m) << m.status().toString();
    valid += m->valid ? 1 : 0;
  }
  EXPECT_EQ(total, 0u);
  // The real frames give an answer: 8 of 11 since the segments' end points are left out of the
  // fit (10 before; their inlier counts sit at vertical.min_inliers, docs/vertical.md).
  EXPECT_GE(valid, 8);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::vertical
