// Each Lalonde cue alone (hil/tools/sun_eval/src/lalonde_cues.hpp), on a real KITTI 00 frame.

#include "lalonde_cues.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "datasets.hpp"
#include "metrics.hpp"

namespace {
using sunvo::suneval::axialErrorDeg;
const std::string kFrames = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";

TEST(SunEvalLalondeCues, AxialErrorFoldsTheTwoShadowDirections) {
  EXPECT_DOUBLE_EQ(axialErrorDeg(10.0), 10.0);
  EXPECT_DOUBLE_EQ(axialErrorDeg(170.0), 10.0);
  EXPECT_DOUBLE_EQ(axialErrorDeg(-100.0), 80.0);
  EXPECT_DOUBLE_EQ(axialErrorDeg(370.0), 10.0);
  EXPECT_DOUBLE_EQ(axialErrorDeg(90.0), 90.0);
  EXPECT_DOUBLE_EQ(axialErrorDeg(-180.0), 0.0);
}

class CuesOnARealFrame : public ::testing::Test {
 protected:
  void run(const sunvo::sunvision::LalondeOptions& options) {
    sunvo::suneval::EvalSetOptions o;
    o.max_frames = 1;
    auto ds = sunvo::suneval::loadEvalDataset(kFrames, o);
    ASSERT_TRUE(ds) << ds.status().toString();
    estimator_ = sunvo::sunvision::LalondeEstimator(options);
    ASSERT_TRUE(estimator_.init());
    sunvo::sunfusion::ImageSunInput in;
    in.color = cv::imread(ds->frames[0].image_path, cv::IMREAD_UNCHANGED);
    in.camera = ds->camera;
    in.prior = sunvo::sunfusion::SunPrior{ds->frames[0].true_sun_c, ds->frames[0].true_up_c};
    ASSERT_TRUE(estimator_.estimate(in));
  }
  sunvo::sunvision::LalondeEstimator estimator_;
};

TEST_F(CuesOnARealFrame, TheSaturatedSkyIsNotInformative) {
  // The sky of the KITTI frames is saturated but for a rim: with the relative sky threshold
  // (0.9 x the 99th percentile gray, 255 here) too few unsaturated pixels remain to fit.
  run({});
  EXPECT_FALSE(estimator_.lastCues().sky_informative);
}

TEST_F(CuesOnARealFrame, ASunAtTheSkyCuesBestCellHasNoSkyError) {
  // The bookkeeping needs an informative sky cue: the absolute threshold alone gives one here.
  sunvo::sunvision::LalondeOptions o;
  o.sky_min_relative_gray = 0.0;
  run(o);
  const sunvo::sunvision::LalondeCues& cues = estimator_.lastCues();
  ASSERT_TRUE(cues.sky_informative);
  cv::Point best;
  cv::minMaxLoc(cues.sky_loglik, nullptr, nullptr, nullptr, &best);
  const double az = estimator_.azimuthOfColRad(best.x);
  const double zen = estimator_.zenithOfRowRad(best.y);
  const sunvo::suneval::CueErrors at =
      sunvo::suneval::lalondeCueErrors(estimator_, cues.horizon.direction(az, zen));
  EXPECT_NEAR(at.sky_deg, 0.0, 1e-6);
  // The sun half a turn away: the sky cue is 180 deg off, the shadow cue (an axis) unchanged.
  const sunvo::suneval::CueErrors opposite =
      sunvo::suneval::lalondeCueErrors(estimator_, cues.horizon.direction(az + M_PI, zen));
  EXPECT_NEAR(std::abs(opposite.sky_deg), 180.0, 1e-6);
  if (cues.shadow_informative) {
    EXPECT_GE(at.shadow_deg, 0.0);
    EXPECT_LE(at.shadow_deg, 90.0);
    EXPECT_NEAR(opposite.shadow_deg, at.shadow_deg, 1e-6);
  }
}

TEST_F(CuesOnARealFrame, ACueThatIsOffHasNoError) {
  sunvo::sunvision::LalondeOptions o;
  o.use_sky = false;
  o.use_shadows = false;
  run(o);
  const sunvo::suneval::CueErrors e =
      sunvo::suneval::lalondeCueErrors(estimator_, Eigen::Vector3d(0.3, -0.5, 0.8).normalized());
  EXPECT_TRUE(std::isnan(e.sky_deg));
  EXPECT_TRUE(std::isnan(e.shadow_deg));
}

}  // namespace
