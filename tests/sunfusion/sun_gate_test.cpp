#include "sunvo/sunfusion/sun_gate.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "sunvo/sunfusion/simulated_sun_source.hpp"

namespace sunvo::sunfusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

SunMeasurement full(const Eigen::Vector3d& s) {
  SunMeasurement m;
  m.sun_c = s.normalized();
  return m;
}

TEST(SunGate, CosineDistanceThreshold) {
  SunGateOptions opt;  // 0.3 as in the paper: about 45.6 degrees
  opt.max_vertical_error = 2.0;
  const Eigen::Vector3d pred = sunFromAzimuthZenith(0.0, 60.0 * kDeg);
  const double up = 0.5;
  EXPECT_EQ(gateSunMeasurement(opt, pred, up, full(sunFromAzimuthZenith(40.0 * kDeg, 60.0 * kDeg))),
            GateResult::kAccepted);  // 1 - cos(angle) = 0.2 < 0.3
  EXPECT_EQ(gateSunMeasurement(opt, pred, up, full(sunFromAzimuthZenith(70.0 * kDeg, 60.0 * kDeg))),
            GateResult::kRejectedCosine);  // angle 60.6 deg -> 0.51
}

TEST(SunGate, VerticalErrorCutsTheZenithTail) {
  SunGateOptions opt;
  opt.max_vertical_error = 0.1;
  const Eigen::Vector3d pred = sunFromAzimuthZenith(0.0, 60.0 * kDeg);
  // Same azimuth, zenith 20 degrees off: y changes by cos(40) - cos(60) = 0.27 > 0.1.
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.5, full(sunFromAzimuthZenith(0.0, 40.0 * kDeg))),
            GateResult::kRejectedVertical);
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.5, full(sunFromAzimuthZenith(0.0, 63.0 * kDeg))),
            GateResult::kAccepted);
}

TEST(SunGate, AzimuthOnlyIsGatedInThePlaneAndIgnoresElevation) {
  SunGateOptions opt;
  opt.max_vertical_error = 0.01;  // would reject any 3-D vector with a different y
  SunMeasurement m;
  m.kind = SunMeasurementKind::kAzimuthOnly;
  m.sun_c = sunFromAzimuthZenith(10.0 * kDeg, 90.0 * kDeg);             // in the plane, y = 0
  const Eigen::Vector3d pred = sunFromAzimuthZenith(0.0, 30.0 * kDeg);  // high sun
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.8, m), GateResult::kAccepted);
  m.sun_c = sunFromAzimuthZenith(120.0 * kDeg, 90.0 * kDeg);
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.8, m), GateResult::kRejectedCosine);
}

TEST(SunGate, SunBelowHorizonAndInvalidInput) {
  SunGateOptions opt;
  const Eigen::Vector3d pred = sunFromAzimuthZenith(0.0, 60.0 * kDeg);
  EXPECT_EQ(gateSunMeasurement(opt, pred, -0.1, full(pred)), GateResult::kRejectedSunDown);
  SunMeasurement bad = full(pred);
  bad.sun_c.x() = std::nan("");
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.5, bad), GateResult::kRejectedInvalid);
  bad = full(pred);
  bad.sun_c *= 2.0;
  EXPECT_EQ(gateSunMeasurement(opt, pred, 0.5, bad), GateResult::kRejectedInvalid);
  GateCounters c;
  c.count(GateResult::kAccepted);
  c.count(GateResult::kRejectedCosine);
  c.count(GateResult::kRejectedCosine);
  EXPECT_EQ(c.total(), 3u);
  EXPECT_EQ(c.rejected_cosine, 2u);
}

TEST(SunGate, OptionsValidationNamesTheKey) {
  SunGateOptions opt;
  opt.max_cosine_distance = -1.0;
  EXPECT_NE(opt.validate().message().find("sun_gate.max_cosine_distance"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::sunfusion
