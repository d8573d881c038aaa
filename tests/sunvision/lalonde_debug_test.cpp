#include "sunvo/sunvision/lalonde_debug.hpp"

#include <gtest/gtest.h>

#include "synthetic_scene.hpp"

namespace sunvo::sunvision {
namespace {

TEST(LalondeDebug, DrawsMapsAndSundial) {
  LalondeEstimator est;
  ASSERT_TRUE(est.init().isOk());
  const StereoCamera cam = testing::kittiCamera();
  const Eigen::Vector3d sun_c = testing::sunInLevelCamera(30.0, 45.0);
  const sunfusion::ImageSunInput in{testing::renderScene(cam, sun_c, true, true), cam,
                                    sunfusion::SunPrior{}};
  Expected<sunfusion::ImageSunEstimate> e = est.estimate(in);
  ASSERT_TRUE(e);
  Expected<LalondeDebugImages> d = renderLalondeDebug(est, in, *e, sun_c);
  ASSERT_TRUE(d) << d.status().toString();
  for (const cv::Mat* m : {&d->sky, &d->shadow, &d->prior, &d->posterior}) {
    EXPECT_EQ(m->type(), CV_8UC3);
    EXPECT_EQ(m->cols, est.azimuthBins() * 4);
    EXPECT_EQ(m->rows, est.zenithBins() * 4);
  }
  ASSERT_EQ(d->sundial.size(), in.color.size());
  // The stick is drawn in red where the input had no red.
  cv::Mat diff;
  cv::absdiff(d->sundial, in.color, diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
  EXPECT_EQ(d->panel.cols, 2 * d->sky.cols);
  // The input is not drawn into.
  EXPECT_EQ(cv::countNonZero(in.color.reshape(1) !=
                             testing::renderScene(cam, sun_c, true, true).reshape(1)),
            0);
}

TEST(LalondeDebug, NeedsAnEstimate) {
  LalondeEstimator est;
  ASSERT_TRUE(est.init().isOk());
  const StereoCamera cam = testing::kittiCamera();
  EXPECT_FALSE(renderLalondeDebug(est, {cv::Mat(), cam, std::nullopt}, {}, std::nullopt));
}

}  // namespace
}  // namespace sunvo::sunvision
