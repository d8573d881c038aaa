// The camera model applied to the renders (sensor.hpp): response curves and white balance.
#include "sunvo/render/sensor.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sunvo::render {
namespace {

TEST(Sensor, ResponseCurvesMapZeroToZeroAndAreMonotonic) {
  for (const char* r : {"srgb", "gamma", "scurve", "filmic"}) {
    SensorOptions o;
    o.response = r;
    o.gamma = 2.2;
    o.contrast = 0.6;
    EXPECT_NEAR(responseCurve(o, 0.0), 0.0, 1e-12) << r;
    double prev = -1.0;
    for (int i = 0; i <= 100; ++i) {
      const double y = responseCurve(o, i / 100.0);
      EXPECT_GE(y, prev) << r << " at " << i;
      EXPECT_LE(y, 1.0) << r;
      prev = y;
    }
  }
}

TEST(Sensor, ResponseCurvesFollowTheirFormulas) {
  SensorOptions o;
  EXPECT_NEAR(responseCurve(o, 0.18), linearToSrgb(0.18), 1e-12);
  o.response = "gamma";
  o.gamma = 2.5;
  EXPECT_NEAR(responseCurve(o, 0.18), std::pow(0.18, 1 / 2.5), 1e-12);
  o.response = "filmic";  // (1 + 1/4) s / (1 + s), then ^(1/gamma): 1 -> 0.625^(1/2.5)
  EXPECT_NEAR(responseCurve(o, 1.0), std::pow(0.625, 1 / 2.5), 1e-12);
  o.response = "scurve";  // fixed ends, steeper at mid-grey than sRGB
  o.contrast = 0.5;
  EXPECT_NEAR(responseCurve(o, 1.0), 1.0, 1e-12);
  const double s = srgbToLinear(0.5);
  SensorOptions srgb;
  EXPECT_NEAR(responseCurve(o, s), 0.5, 1e-9);
  EXPECT_GT(responseCurve(o, s * 1.1) - responseCurve(o, s),
            responseCurve(srgb, s * 1.1) - responseCurve(srgb, s));
}

TEST(Sensor, WhiteBalanceScalesRedAndBlueOnly) {
  cv::Mat grey(8, 8, CV_8UC3, cv::Scalar::all(120));
  SensorOptions o;
  o.full_well_e = 0;
  o.read_noise_e = 0;
  o.vignetting = 0;
  const cv::Mat plain = applySensor(grey, o, 1.0, 100, 4, 4, 1);
  o.white_balance_r = 1.5;
  o.white_balance_b = 0.7;
  const cv::Mat wb = applySensor(grey, o, 1.0, 100, 4, 4, 1);
  const cv::Vec3b p = plain.at<cv::Vec3b>(3, 3), q = wb.at<cv::Vec3b>(3, 3);
  EXPECT_EQ(p[0], p[2]);  // noise off, no white balance: grey stays grey
  EXPECT_GT(q[2], p[2]);  // red up
  EXPECT_LT(q[0], p[0]);  // blue down
  EXPECT_EQ(q[1], p[1]);  // green unchanged
  // Linear light: the red gain of 1.5 multiplies the linear value.
  EXPECT_NEAR(srgbToLinear(q[2] / 255.0) / srgbToLinear(p[2] / 255.0), 1.5, 0.03);
}

TEST(Sensor, OptionsNameTheirKey) {
  SensorOptions o;
  o.gamma = 9;
  EXPECT_NE(o.validate().message().find("sensor.gamma"), std::string::npos);
  o = SensorOptions{};
  o.response = "log";
  EXPECT_NE(o.validate().message().find("sensor.response"), std::string::npos);
  o = SensorOptions{};
  o.defocus_sigma_px = -1;
  EXPECT_NE(o.validate().message().find("sensor.defocus_sigma_px"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::render
