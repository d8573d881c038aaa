// sunvo_sun_eval's statistics (hil/tools/sun_eval/src/metrics.hpp) on small inputs whose results
// are worked out by hand in the comments.

#include "metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {
using sunvo::suneval::FrameResult;
using sunvo::suneval::kNaN;
constexpr double kDeg = std::numbers::pi / 180.0;

FrameResult frame(bool valid, double az_err, double zen_err, double sigma_az, double cpu_ms,
                  bool kept = false) {
  FrameResult f;
  f.valid = valid;
  f.azimuth_error_deg = az_err;
  f.zenith_error_deg = zen_err;
  f.azimuth_sigma_deg = sigma_az;
  f.cpu_ms = cpu_ms;
  f.wall_ms = 2.0 * cpu_ms;
  f.kept_by_gate = kept;
  return f;
}

TEST(SunEvalMetrics, QuantileInterpolatesAndSkipsNonFinite) {
  using sunvo::suneval::quantile;
  EXPECT_DOUBLE_EQ(quantile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 0.5), 2.5);  // mean of the middle two
  // 0.9 of [0, 10, 20]: position 1.8 -> 10 + 0.8 * 10.
  EXPECT_DOUBLE_EQ(quantile({20.0, 0.0, 10.0}, 0.9), 18.0);
  EXPECT_DOUBLE_EQ(quantile({kNaN, 5.0, INFINITY, 7.0}, 0.0), 5.0);
  EXPECT_TRUE(std::isnan(quantile({}, 0.5)));
  EXPECT_TRUE(std::isnan(quantile({kNaN}, 0.5)));
}

TEST(SunEvalMetrics, WrapsAndMeasuresAzimuth) {
  using sunvo::suneval::azimuthDeg;
  using sunvo::suneval::wrapDeg;
  EXPECT_DOUBLE_EQ(wrapDeg(190.0), -170.0);
  EXPECT_DOUBLE_EQ(wrapDeg(-180.0), 180.0);
  EXPECT_DOUBLE_EQ(wrapDeg(540.0), 180.0);
  EXPECT_DOUBLE_EQ(wrapDeg(-45.0), -45.0);
  // x right, z forward: a sun to the right is +90 deg, one behind is 180 deg.
  EXPECT_NEAR(azimuthDeg(Eigen::Vector3d(1.0, -0.3, 0.0)), 90.0, 1e-12);
  EXPECT_NEAR(azimuthDeg(Eigen::Vector3d(0.0, -0.3, -1.0)), 180.0, 1e-12);
  EXPECT_NEAR(azimuthDeg(Eigen::Vector3d(-1.0, 0.0, 1.0)), -45.0, 1e-12);
}

TEST(SunEvalMetrics, AzimuthSigmaOfEachMeasurementKind) {
  using sunvo::suneval::azimuthSigmaDeg;
  using Kind = sunvo::sunfusion::SunMeasurementKind;
  // Azimuth-only: sigma is the azimuth's, in rad.
  EXPECT_NEAR(azimuthSigmaDeg(Kind::kAzimuthOnly, 0.1, Eigen::Vector3d::UnitZ()), 0.1 / kDeg,
              1e-12);
  // Full 3-D, true sun (0, -0.8, 0.6): rho = 0.6, so the azimuth spans 0.1 / 0.6 rad.
  EXPECT_NEAR(azimuthSigmaDeg(Kind::kFull3d, 0.1, Eigen::Vector3d(0.0, -0.8, 0.6)),
              0.1 / 0.6 / kDeg, 1e-9);
  // A sun along the camera's y axis: rho clamped to 0.1.
  EXPECT_NEAR(azimuthSigmaDeg(Kind::kFull3d, 0.1, Eigen::Vector3d(0.0, -1.0, 0.0)), 1.0 / kDeg,
              1e-9);
  EXPECT_TRUE(std::isnan(azimuthSigmaDeg(Kind::kFull3d, kNaN, Eigen::Vector3d::UnitZ())));
}

TEST(SunEvalMetrics, SummarizesOneEstimatorOnOneSet) {
  // valid: 1, 2, 3, 6 (6 gave no direction); invalid: 4 (gross, so flagged) and 5.
  const std::vector<FrameResult> frames = {
      frame(true, 10.0, -2.0, 10.0, 1.0, true),  // |10| < 2 * 10: within
      frame(true, -30.0, kNaN, 10.0, 3.0),       // |-30| >= 20: outside
      frame(true, 60.0, kNaN, 40.0, 2.0),        // gross; |60| < 80: within
      frame(false, 100.0, kNaN, 5.0, 4.0),       // gross, flagged invalid
      frame(false, 5.0, kNaN, 5.0, 5.0),        frame(true, kNaN, kNaN, kNaN, 6.0),
  };
  const sunvo::suneval::EstimatorSummary s = sunvo::suneval::summarize(frames);
  EXPECT_EQ(s.frames, 6);
  EXPECT_EQ(s.valid, 4);
  EXPECT_DOUBLE_EQ(s.valid_share, 4.0 / 6.0);
  // |errors| of the valid frames: 10, 30, 60 -> median 30; p90 at position 1.8: 30 + 0.8 * 30.
  EXPECT_DOUBLE_EQ(s.azimuth_median_deg, 30.0);
  EXPECT_DOUBLE_EQ(s.azimuth_p90_deg, 54.0);
  // Signed: -30, 10, 60 -> median +10 (the estimates lie clockwise of the sun).
  EXPECT_DOUBLE_EQ(s.azimuth_bias_deg, 10.0);
  EXPECT_DOUBLE_EQ(s.zenith_median_deg, 2.0);
  EXPECT_EQ(s.gross, 1);
  EXPECT_DOUBLE_EQ(s.gross_share, 1.0 / 3.0);
  EXPECT_EQ(s.gross_any, 2);
  EXPECT_EQ(s.gross_invalid, 1);
  EXPECT_DOUBLE_EQ(s.gross_flagged, 0.5);
  EXPECT_EQ(s.sigma_checked, 3);
  EXPECT_EQ(s.within_2sigma, 2);
  EXPECT_DOUBLE_EQ(s.within_2sigma_share, 2.0 / 3.0);
  EXPECT_EQ(s.kept, 1);
  EXPECT_DOUBLE_EQ(s.kept_share, 1.0 / 6.0);
  // CPU 1..6 ms: median 3.5, p90 at position 4.5 -> 5.5; wall is twice that.
  EXPECT_DOUBLE_EQ(s.cpu_ms_median, 3.5);
  EXPECT_DOUBLE_EQ(s.cpu_ms_p90, 5.5);
  EXPECT_DOUBLE_EQ(s.wall_ms_median, 7.0);
}

TEST(SunEvalMetrics, NoValidFrameLeavesTheErrorStatisticsUndefined) {
  const sunvo::suneval::EstimatorSummary s =
      sunvo::suneval::summarize({frame(false, 170.0, kNaN, 5.0, 1.0)});
  EXPECT_EQ(s.valid, 0);
  EXPECT_DOUBLE_EQ(s.valid_share, 0.0);
  EXPECT_TRUE(std::isnan(s.azimuth_median_deg));
  EXPECT_TRUE(std::isnan(s.azimuth_bias_deg));
  EXPECT_TRUE(std::isnan(s.gross_share));
  EXPECT_TRUE(std::isnan(s.within_2sigma_share));
  EXPECT_DOUBLE_EQ(s.gross_flagged, 1.0);  // the one gross estimate was flagged
  const sunvo::suneval::EstimatorSummary empty = sunvo::suneval::summarize({});
  EXPECT_EQ(empty.frames, 0);
  EXPECT_TRUE(std::isnan(empty.valid_share));
  EXPECT_TRUE(std::isnan(empty.cpu_ms_median));
}

TEST(SunEvalMetrics, SummarizesACueOverItsInformativeFrames) {
  // Informative: 10, -50, 90 -> |.| median 50, p90 at position 1.8: 50 + 0.8 * 40; gross 50, 90.
  const sunvo::suneval::CueSummary c =
      sunvo::suneval::summarizeCue({kNaN, 10.0, -50.0, 90.0, kNaN});
  EXPECT_EQ(c.frames, 5);
  EXPECT_EQ(c.informative, 3);
  EXPECT_DOUBLE_EQ(c.informative_share, 0.6);
  EXPECT_DOUBLE_EQ(c.median_deg, 50.0);
  EXPECT_DOUBLE_EQ(c.p90_deg, 82.0);
  EXPECT_EQ(c.gross, 2);
  EXPECT_DOUBLE_EQ(c.gross_share, 2.0 / 3.0);
}

}  // namespace
