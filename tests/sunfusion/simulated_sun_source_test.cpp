#include "sunvo/sunfusion/simulated_sun_source.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sunvo/core/geometry.hpp"

namespace sunvo::sunfusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

double wrap(double a) {
  return std::remainder(a, 2.0 * M_PI);
}

TEST(SimulatedSunSource, AzimuthZenithRoundTrip) {
  for (double az = -170.0; az <= 170.0; az += 20.0) {
    for (double zen = 5.0; zen <= 175.0; zen += 10.0) {
      double a = 0, z = 0;
      azimuthZenithFromSun(sunFromAzimuthZenith(az * kDeg, zen * kDeg), a, z);
      EXPECT_NEAR(a, az * kDeg, 1e-12);
      EXPECT_NEAR(z, zen * kDeg, 1e-12);
    }
  }
}

TEST(SimulatedSunSource, ErrorStatisticsMatchTheModel) {
  SunErrorModel model;
  model.azimuth_sigma_deg = 12.0;
  model.zenith_sigma_deg = 6.0;
  model.zenith_bias_deg = 4.0;
  model.dropout_share = 0.2;
  model.flip_share = 0.1;
  ASSERT_TRUE(model.validate().isOk());
  SimulatedSunSource source(model);
  const Eigen::Vector3d truth = sunFromAzimuthZenith(30.0 * kDeg, 50.0 * kDeg);
  int n = 0, dropped = 0, flipped = 0;
  double sum_az2 = 0, sum_zen = 0, sum_zen2 = 0;
  for (int i = 0; i < 20000; ++i) {
    auto m = source.measure(static_cast<std::uint64_t>(i), 0, truth);
    if (!m) {
      ++dropped;
      continue;
    }
    EXPECT_NEAR(m->sun_c.norm(), 1.0, 1e-12);
    double a = 0, z = 0;
    azimuthZenithFromSun(m->sun_c, a, z);
    const double da = wrap(a - 30.0 * kDeg);
    if (std::abs(da) > 90.0 * kDeg) {
      ++flipped;
      continue;
    }
    ++n;
    sum_az2 += da * da;
    sum_zen += z - 50.0 * kDeg;
    sum_zen2 += (z - 50.0 * kDeg) * (z - 50.0 * kDeg);
  }
  EXPECT_NEAR(dropped / 20000.0, 0.2, 0.01);
  EXPECT_NEAR(flipped / 16000.0, 0.1, 0.01);
  EXPECT_NEAR(std::sqrt(sum_az2 / n) / kDeg, 12.0, 0.4);
  const double mean_zen = sum_zen / n;
  EXPECT_NEAR(mean_zen / kDeg, 4.0, 0.2);
  EXPECT_NEAR(std::sqrt(sum_zen2 / n - mean_zen * mean_zen) / kDeg, 6.0, 0.2);
}

TEST(SimulatedSunSource, AzimuthOnlyLiesInThePlaneAndIsReproducible) {
  SunErrorModel model;
  model.azimuth_only = true;
  SimulatedSunSource a(model), b(model);
  const Eigen::Vector3d truth = sunFromAzimuthZenith(-45.0 * kDeg, 30.0 * kDeg);
  for (int i = 0; i < 100; ++i) {
    auto ma = a.measure(1, 0, truth);
    auto mb = b.measure(1, 0, truth);
    ASSERT_TRUE(ma && mb);
    EXPECT_EQ(ma->kind, SunMeasurementKind::kAzimuthOnly);
    EXPECT_NEAR(ma->sun_c.y(), 0.0, 1e-12);
    EXPECT_EQ(ma->sun_c, mb->sun_c);
  }
}

// The correlated azimuth error: its std and its autocorrelation at lags 1 and tau are those of the
// Gauss-Markov process, and it is the only difference to the same source without it (its own
// generator leaves the other draws alone).
TEST(SimulatedSunSource, CorrelatedAzimuthBiasIsAGaussMarkovProcessOnTop) {
  SunErrorModel plain;
  plain.azimuth_sigma_deg = 10.0;
  plain.dropout_share = 0.2;
  SunErrorModel biased = plain;
  biased.azimuth_bias_deg = 6.0;
  biased.azimuth_bias_length = 20.0;
  ASSERT_TRUE(biased.validate().isOk());
  SimulatedSunSource a(biased), b(plain);
  const Eigen::Vector3d truth = sunFromAzimuthZenith(10.0 * kDeg, 60.0 * kDeg);
  constexpr int kN = 100000;
  std::vector<double> bias(kN);
  for (int i = 0; i < kN; ++i) {
    const auto ma = a.measure(static_cast<std::uint64_t>(i), 0, truth);
    const auto mb = b.measure(static_cast<std::uint64_t>(i), 0, truth);
    bias[static_cast<std::size_t>(i)] = a.azimuthBias();
    ASSERT_EQ(ma.has_value(), mb.has_value());
    if (!ma) continue;
    double az_a = 0, az_b = 0, z = 0;
    azimuthZenithFromSun(ma->sun_c, az_a, z);
    azimuthZenithFromSun(mb->sun_c, az_b, z);
    ASSERT_NEAR(wrap(az_a - az_b - a.azimuthBias()), 0.0, 1e-9) << i;
  }
  const auto lagged = [&](int lag) {
    double sum = 0.0;
    for (int i = lag; i < kN; ++i) {
      sum += bias[static_cast<std::size_t>(i)] * bias[static_cast<std::size_t>(i - lag)];
    }
    return sum / (kN - lag);
  };
  const double var = lagged(0);
  EXPECT_NEAR(std::sqrt(var) / kDeg, 6.0, 0.3);
  EXPECT_NEAR(lagged(1) / var, std::exp(-1.0 / 20.0), 0.01);
  EXPECT_NEAR(lagged(20) / var, std::exp(-1.0), 0.05);
  SunErrorModel bad = biased;
  bad.azimuth_bias_length = 0.5;
  EXPECT_NE(bad.validate().message().find("sun_error.azimuth_bias_length"), std::string::npos);
}

// A constant azimuth offset (a source biased for a whole drive) turns every non-outlier
// measurement by exactly that angle and changes no other draw; outliers stay uniform.
TEST(SimulatedSunSource, AzimuthOffsetTurnsEveryMeasurementByTheSameAngle) {
  SunErrorModel plain;
  plain.azimuth_sigma_deg = 10.0;
  plain.outlier_share = 0.1;
  plain.dropout_share = 0.2;
  SunErrorModel offset = plain;
  offset.azimuth_offset_deg = -66.0;
  ASSERT_TRUE(offset.validate().isOk());
  SimulatedSunSource a(offset), b(plain);
  const Eigen::Vector3d truth = sunFromAzimuthZenith(10.0 * kDeg, 60.0 * kDeg);
  int turned = 0, same = 0, measured = 0;
  for (int i = 0; i < 2000; ++i) {
    const auto ma = a.measure(static_cast<std::uint64_t>(i), 0, truth);
    const auto mb = b.measure(static_cast<std::uint64_t>(i), 0, truth);
    ASSERT_EQ(ma.has_value(), mb.has_value());
    if (!ma) continue;
    ++measured;
    double az_a = 0, az_b = 0, z_a = 0, z_b = 0;
    azimuthZenithFromSun(ma->sun_c, az_a, z_a);
    azimuthZenithFromSun(mb->sun_c, az_b, z_b);
    ASSERT_NEAR(z_a, z_b, 1e-9) << i;
    const double d = wrap(az_a - az_b);
    if (std::abs(d + 66.0 * kDeg) < 1e-9) ++turned;
    if (std::abs(d) < 1e-9) ++same;  // an outlier: the offset is not added
  }
  EXPECT_EQ(turned + same, measured);  // nothing else changed
  EXPECT_GT(turned, 1300);             // about 0.8 x 0.9 x 2000
  EXPECT_GT(same, 100);                // the outliers, about 0.8 x 0.1 x 2000
  SunErrorModel bad = plain;
  bad.azimuth_offset_deg = 181.0;
  EXPECT_NE(bad.validate().message().find("sun_error.azimuth_offset_deg"), std::string::npos);
}

TEST(SimulatedVerticalSource, ErrorsDropoutsOutliersAndBiasAsModelled) {
  // Truth: a camera rolled by 3 deg. The pitch error (about camera x) and roll error (about z) of
  // each measurement: mean = bias, std = sigma; 8 deg outliers; dropouts.
  VerticalErrorModel model;
  model.sigma_deg = 1.0;
  model.roll_bias_deg = 0.5;
  model.outlier_share = 0.1;
  model.dropout_share = 0.3;
  model.reported_sigma_deg = 1.5;
  SimulatedVerticalSource source(model), twin(model);
  const Eigen::Vector3d truth =
      expSO3(Eigen::Vector3d(0.0, 0.0, 3.0 * kDeg)) * Eigen::Vector3d(0.0, -1.0, 0.0);
  int dropped = 0, outliers = 0, n = 0;
  double sum_roll = 0.0, sum_roll2 = 0.0, sum_pitch2 = 0.0;
  for (int i = 0; i < 20000; ++i) {
    auto m = source.measure(7, 0, truth);
    auto m2 = twin.measure(7, 0, truth);
    ASSERT_EQ(m.has_value(), m2.has_value());
    if (!m) {
      ++dropped;
      continue;
    }
    EXPECT_EQ(m->sun_c, m2->sun_c);
    EXPECT_EQ(m->kind, SunMeasurementKind::kFull3d);
    EXPECT_NEAR(m->sigma, 1.5 * kDeg, 1e-15);
    EXPECT_NEAR(m->sun_c.norm(), 1.0, 1e-12);
    const Eigen::Vector3d e = truth.cross(m->sun_c);  // small rotation truth -> measurement
    const double angle = std::asin(std::min(1.0, e.norm()));
    if (std::abs(angle - 8.0 * kDeg) < 1e-9) {
      ++outliers;
      continue;
    }
    ++n;
    sum_roll += e.z();
    sum_roll2 += e.z() * e.z();
    sum_pitch2 += e.x() * e.x();
  }
  EXPECT_NEAR(dropped / 20000.0, 0.3, 0.01);
  EXPECT_NEAR(outliers / 14000.0, 0.1, 0.01);
  const double mean_roll = sum_roll / n;
  EXPECT_NEAR(mean_roll / kDeg, 0.5, 0.03);
  EXPECT_NEAR(std::sqrt(sum_roll2 / n - mean_roll * mean_roll) / kDeg, 1.0, 0.03);
  EXPECT_NEAR(std::sqrt(sum_pitch2 / n) / kDeg, 1.0, 0.03);
}

TEST(SimulatedSunSource, ValidationNamesTheKey) {
  SunErrorModel model;
  model.flip_share = 2.0;
  EXPECT_NE(model.validate().message().find("sun_error.flip_share"), std::string::npos);
  VerticalErrorModel vertical;
  vertical.reported_sigma_deg = 0.0;
  EXPECT_NE(vertical.validate().message().find("vertical_error.reported_sigma_deg"),
            std::string::npos);
}

}  // namespace
}  // namespace sunvo::sunfusion
