#include "sunvo/sunvision/lalonde_estimator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "synthetic_scene.hpp"

namespace sunvo::sunvision {
namespace {
using sunfusion::ImageSunEstimate;
using sunfusion::ImageSunInput;
using sunfusion::SunPrior;
using testing::kittiCamera;
using testing::renderScene;
using testing::sunInLevelCamera;
constexpr double kDeg = std::numbers::pi / 180.0;

LalondeEstimator make(LalondePrior prior) {
  LalondeOptions o;
  o.prior = prior;
  LalondeEstimator e(o);
  EXPECT_TRUE(e.init().isOk());
  return e;
}

// Azimuth of sun_c from the optical axis toward the right (level camera), deg.
double azimuthDeg(const Eigen::Vector3d& sun_c) {
  return std::atan2(sun_c.x(), sun_c.z()) / kDeg;
}
double azimuthErrorDeg(double a, double b) {
  return std::abs(wrapPi((a - b) * kDeg)) / kDeg;
}

void expectFinite(const ImageSunEstimate& e) {
  EXPECT_TRUE(e.measurement.sun_c.allFinite());
  EXPECT_NEAR(e.measurement.sun_c.norm(), 1.0, 1e-9);
  EXPECT_TRUE(std::isfinite(e.azimuth_deg) && std::isfinite(e.zenith_deg));
  EXPECT_TRUE(std::isfinite(e.measurement.sigma) && e.measurement.sigma > 0.0);
  EXPECT_TRUE(e.confidence >= 0.0 && e.confidence <= 1.0);
  EXPECT_TRUE(std::isfinite(e.time_ms) && e.time_ms >= 0.0);
}

TEST(Lalonde, RecoversTheSunFromSkyAndShadows) {
  LalondeEstimator est = make(LalondePrior::kZenith);
  const StereoCamera cam = kittiCamera();
  for (const auto& [az, zen] : {std::pair{30.0, 45.0}, std::pair{-50.0, 55.0}}) {
    const Eigen::Vector3d sun_c = sunInLevelCamera(az, zen);
    const ImageSunInput in{renderScene(cam, sun_c, true, true), cam, SunPrior{}};
    Expected<ImageSunEstimate> e = est.estimate(in);
    ASSERT_TRUE(e) << e.status().toString();
    expectFinite(*e);
    EXPECT_TRUE(e->valid);
    EXPECT_TRUE(est.lastCues().sky_informative);
    EXPECT_TRUE(est.lastCues().shadow_informative);
    EXPECT_LT(azimuthErrorDeg(e->azimuth_deg, az), 8.0) << "true az " << az;
    EXPECT_LT(std::abs(e->zenith_deg - zen), 15.0) << "true zenith " << zen;
    EXPECT_NEAR(e->azimuth_deg, azimuthDeg(e->measurement.sun_c), 1e-9);
  }
}

TEST(Lalonde, ShadowsAloneGiveTwoPeaksAndTheVoPriorPicksOne) {
  const StereoCamera cam = kittiCamera();
  const double az = 120.0, zen = 50.0;
  const cv::Mat img = renderScene(cam, sunInLevelCamera(az, zen), false, true);
  LalondeEstimator plain = make(LalondePrior::kZenith);
  Expected<ImageSunEstimate> e = plain.estimate({img, cam, SunPrior{}});
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->valid);
  EXPECT_FALSE(plain.lastCues().sky_informative);
  EXPECT_TRUE(plain.lastCues().shadow_informative);
  // Either the sun or the mirrored sun (shadow lines have no sign).
  EXPECT_LT(
      std::min(azimuthErrorDeg(e->azimuth_deg, az), azimuthErrorDeg(e->azimuth_deg, az - 180.0)),
      8.0);
  const double plain_sigma = e->measurement.sigma;

  LalondeEstimator vo = make(LalondePrior::kVisualOdometry);
  // A VO prediction 25 deg off on the sun's side selects the true peak ...
  SunPrior near{sunInLevelCamera(az - 25.0, zen + 10.0), Eigen::Vector3d(0.0, -1.0, 0.0)};
  e = vo.estimate({img, cam, near});
  ASSERT_TRUE(e);
  EXPECT_LT(azimuthErrorDeg(e->azimuth_deg, az), 8.0);
  EXPECT_LT(std::abs(e->zenith_deg - zen), 15.0);
  EXPECT_LT(e->measurement.sigma, plain_sigma);  // the prior removed the second peak's mass
  // ... and one on the other side selects the mirrored peak: the prior decides, not the image.
  SunPrior far{sunInLevelCamera(az - 180.0 + 25.0, zen), Eigen::Vector3d(0.0, -1.0, 0.0)};
  e = vo.estimate({img, cam, far});
  ASSERT_TRUE(e);
  EXPECT_LT(azimuthErrorDeg(e->azimuth_deg, az - 180.0), 8.0);
}

TEST(Lalonde, GrayImagesWork) {
  LalondeEstimator est = make(LalondePrior::kZenith);
  const StereoCamera cam = kittiCamera();
  cv::Mat gray;
  cv::cvtColor(renderScene(cam, sunInLevelCamera(30.0, 45.0), true, true), gray,
               cv::COLOR_BGR2GRAY);
  Expected<ImageSunEstimate> e = est.estimate({gray, cam, SunPrior{}});
  ASSERT_TRUE(e);
  expectFinite(*e);
  EXPECT_TRUE(e->valid);
  EXPECT_LT(azimuthErrorDeg(e->azimuth_deg, 30.0), 15.0);
}

TEST(Lalonde, DegenerateImagesAreInvalidNeverNaN) {
  const StereoCamera cam = kittiCamera();
  for (LalondePrior prior : {LalondePrior::kZenith, LalondePrior::kVisualOdometry}) {
    LalondeEstimator est = make(prior);
    const SunPrior p{sunInLevelCamera(10.0, 40.0), Eigen::Vector3d(0.0, -1.0, 0.0)};
    for (int value : {0, 255}) {
      const cv::Mat img(cam.height, cam.width, CV_8UC3, cv::Scalar::all(value));
      Expected<ImageSunEstimate> e = est.estimate({img, cam, p});
      ASSERT_TRUE(e) << e.status().toString();
      EXPECT_FALSE(e->valid) << "uniform " << value;
      expectFinite(*e);
    }
    // Sky only, no ground texture: the ground is uniform, the sky still counts.
    Expected<ImageSunEstimate> e =
        est.estimate({renderScene(cam, sunInLevelCamera(30.0, 45.0), true, false), cam, p});
    ASSERT_TRUE(e);
    EXPECT_TRUE(e->valid);
    EXPECT_FALSE(est.lastCues().shadow_informative);
  }
}

TEST(Lalonde, CuesCanBeSwitchedOff) {
  const StereoCamera cam = kittiCamera();
  const cv::Mat sky_only = renderScene(cam, sunInLevelCamera(30.0, 45.0), true, false);
  LalondeOptions o;
  o.use_sky = false;
  LalondeEstimator est(o);
  ASSERT_TRUE(est.init().isOk());
  Expected<ImageSunEstimate> e = est.estimate({sky_only, cam, SunPrior{}});
  ASSERT_TRUE(e);
  EXPECT_FALSE(e->valid);  // the sky was the only cue
  EXPECT_EQ(cv::countNonZero(est.lastCues().sky_loglik != 0.0), 0);
}

// sRGB 8-bit <-> linear, to apply lens vignetting in linear light.
double toLinear(unsigned char v8) {
  const double v = v8 / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

TEST(Lalonde, SkyMaskFollowsTheImageOwnLevels) {
  // A flat, bright, top-connected wall (a plain facade) at 75 % of the sky's bright level: an
  // absolute 8-bit threshold takes it for sky, the relative one (share of the image's 99th
  // percentile above the horizon) does not.
  const StereoCamera cam = kittiCamera();
  cv::Mat img = renderScene(cam, sunInLevelCamera(30.0, 45.0), true, false);
  cv::Mat gray;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  const int horizon_v = static_cast<int>(cam.cv);
  double sky_max = 0.0;
  cv::minMaxLoc(gray.rowRange(0, horizon_v), nullptr, &sky_max);
  const double wall = 0.75 * sky_max;
  ASSERT_GT(wall, LalondeOptions{}.sky_min_gray) << "the wall must pass the absolute threshold";
  const int wall_w = cam.width / 3;
  img(cv::Rect(0, 0, wall_w, horizon_v)).setTo(cv::Scalar::all(wall));
  for (double relative : {0.0, LalondeOptions{}.sky_min_relative_gray}) {
    LalondeOptions o;
    o.sky_min_relative_gray = relative;
    LalondeEstimator est(o);
    ASSERT_TRUE(est.init().isOk());
    ASSERT_TRUE(est.estimate({img, cam, SunPrior{}}));
    const cv::Mat& mask = est.lastCues().sky_mask;  // work resolution
    const int wall_work = wall_w * mask.cols / cam.width - 2;
    const int wall_in_mask = cv::countNonZero(mask.colRange(0, wall_work));
    if (relative == 0.0) {
      EXPECT_GT(wall_in_mask, 1000) << "absolute threshold only";
    } else {
      EXPECT_EQ(wall_in_mask, 0) << "relative threshold";
      EXPECT_TRUE(est.lastCues().sky_informative);
    }
  }
}

TEST(Lalonde, TextureWindowKeepsAWindowedFacadeOutOfTheSky) {
  // A facade as bright as the sky, with a grid of dark windows: the 3x3 gradient test passes
  // the flat wall between the windows, the mean gradient over a 9 px window does not.
  const StereoCamera cam = kittiCamera();
  cv::Mat img = renderScene(cam, sunInLevelCamera(30.0, 45.0), true, false);
  const int horizon_v = static_cast<int>(cam.cv), wall_w = cam.width / 3;
  img(cv::Rect(0, 0, wall_w, horizon_v)).setTo(cv::Scalar::all(250));
  for (int v = 4; v + 12 < horizon_v; v += 24) {
    for (int u = 4; u + 12 < wall_w; u += 24) {
      img(cv::Rect(u, v, 12, 12)).setTo(cv::Scalar::all(40));
    }
  }
  for (int window : {0, 9}) {
    LalondeOptions o;
    o.sky_texture_window_px = window;
    o.sky_min_relative_gray = 0.0;  // the wall is as bright as the sky: only texture tells
    LalondeEstimator est(o);
    ASSERT_TRUE(est.init().isOk());
    ASSERT_TRUE(est.estimate({img, cam, SunPrior{}}));
    const cv::Mat& mask = est.lastCues().sky_mask;
    const int wall_in_mask = cv::countNonZero(mask.colRange(0, wall_w * mask.cols / cam.width - 2));
    if (window == 0) {
      EXPECT_GT(wall_in_mask, 500) << "3x3 gradient only";
    } else {
      EXPECT_EQ(wall_in_mask, 0) << "9 px window";
      EXPECT_TRUE(est.lastCues().sky_informative);
    }
  }
}

TEST(Lalonde, FreeVignettingFitKeepsTheSunBehindTheCamera) {
  // Sun 110 deg right of the optical axis (out of view): the visible sky's only azimuth evidence
  // is a faint left-right slope, which a 30 % cos^4 lens fall-off (the renderer's classic
  // camera) overwhelms, pulling a plain fit toward a sun ahead. Fitting the fall-off's strength
  // as a second linear coefficient removes that pull.
  const StereoCamera cam = kittiCamera();
  const double az = 110.0, zen = 45.0;
  cv::Mat img = renderScene(cam, sunInLevelCamera(az, zen), true, false);
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      const double c =
          1.0 / Eigen::Vector3d((u - cam.cu) / cam.fu, (v - cam.cv) / cam.fv, 1.0).norm();
      const double gain = 2.0 * (1.0 - 0.3 * (1.0 - c * c * c * c));  // exposure x vignetting
      cv::Vec3b& px = img.at<cv::Vec3b>(v, u);
      for (int ch = 0; ch < 3; ++ch) px[ch] = testing::toSrgb8(gain * toLinear(px[ch]));
    }
  }
  double err[2] = {0.0, 0.0};
  for (int fit : {0, 1}) {
    LalondeOptions o;
    o.use_shadows = false;
    o.sky_fit_vignetting = fit == 1;
    LalondeEstimator est(o);
    ASSERT_TRUE(est.init().isOk());
    ASSERT_TRUE(est.estimate({img, cam, SunPrior{}}));
    ASSERT_TRUE(est.lastCues().sky_informative);
    cv::Point best;
    cv::minMaxLoc(est.lastCues().sky_loglik, nullptr, nullptr, nullptr, &best);
    err[fit] = azimuthErrorDeg(est.azimuthOfColRad(best.x) / kDeg, az);
  }
  std::printf("sky cue azimuth error: plain fit %.1f deg, free vignetting %.1f deg\n", err[0],
              err[1]);
  EXPECT_GT(err[0], 45.0);
  EXPECT_LT(err[1], 10.0);
}

TEST(Lalonde, WallCueTellsTheLitSide) {
  // A street canyon: sky in the middle, plain facades on both sides, uniform ground. The sun on
  // the right lights the left facades (they face right); mirrored, the right ones.
  const StereoCamera cam = kittiCamera();
  for (bool sun_right : {true, false}) {
    cv::Mat img = renderScene(cam, sunInLevelCamera(sun_right ? 70.0 : -70.0, 45.0), true, false);
    const int side = cam.width / 3, horizon_v = static_cast<int>(cam.cv);
    const double lit = 170.0, shade = 70.0;
    img(cv::Rect(0, 0, side, horizon_v)).setTo(cv::Scalar::all(sun_right ? lit : shade));
    img(cv::Rect(cam.width - side, 0, side, horizon_v))
        .setTo(cv::Scalar::all(sun_right ? shade : lit));
    LalondeOptions o;
    o.use_sky = false;
    o.use_shadows = false;
    o.use_walls = true;
    LalondeEstimator est(o);
    ASSERT_TRUE(est.init().isOk());
    Expected<ImageSunEstimate> e = est.estimate({img, cam, SunPrior{}});
    ASSERT_TRUE(e);
    EXPECT_TRUE(e->valid);
    ASSERT_TRUE(est.lastCues().wall_informative);
    EXPECT_EQ(est.lastCues().wall_log_ratio > 0.0, sun_right);
    // The cue alone only picks the side: the estimate lies on it.
    EXPECT_EQ(e->azimuth_deg > 0.0, sun_right) << e->azimuth_deg;
  }
  // Off (the default): no wall evidence, and a frame with neither sky nor shadows is invalid.
  LalondeEstimator off = make(LalondePrior::kZenith);
  const cv::Mat walls_only(cam.height, cam.width, CV_8UC3, cv::Scalar::all(60));
  Expected<ImageSunEstimate> e = off.estimate({walls_only, cam, SunPrior{}});
  ASSERT_TRUE(e);
  EXPECT_FALSE(off.lastCues().wall_informative);
  EXPECT_EQ(cv::countNonZero(off.lastCues().wall_loglik != 0.0), 0);
}

TEST(Lalonde, RejectsBadInput) {
  const StereoCamera cam = kittiCamera();
  LalondeEstimator uninitialised;
  const cv::Mat img(cam.height, cam.width, CV_8UC3, cv::Scalar::all(100));
  EXPECT_FALSE(uninitialised.estimate({img, cam, SunPrior{}}));

  LalondeEstimator est = make(LalondePrior::kZenith);
  EXPECT_FALSE(est.estimate({cv::Mat(cam.height, cam.width, CV_16UC1), cam, SunPrior{}}));
  EXPECT_FALSE(est.estimate({cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(1)), cam, SunPrior{}}));
  EXPECT_FALSE(
      est.estimate({img, cam, SunPrior{Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()}}));

  StereoCamera bad = cam;
  bad.fu = 0.0;
  EXPECT_FALSE(est.estimate({img, bad, SunPrior{}}));
  StereoCamera mono = cam;  // only the intrinsics are needed
  mono.baseline_m = 0.0;
  EXPECT_TRUE(est.estimate({img, mono, SunPrior{}}));

  LalondeEstimator vo = make(LalondePrior::kVisualOdometry);
  Expected<ImageSunEstimate> e = vo.estimate({img, cam, std::nullopt});
  ASSERT_FALSE(e);
  EXPECT_NE(e.status().message().find("prior"), std::string::npos);
  EXPECT_STREQ(vo.name(), "lalonde_vo");
  EXPECT_STREQ(est.name(), "lalonde");
}

TEST(Lalonde, OptionsNameTheBadKey) {
  LalondeOptions o;
  EXPECT_TRUE(o.validate().isOk());
  o.camera_height_m = -1.0;
  EXPECT_NE(o.validate().message().find("lalonde.camera_height_m"), std::string::npos);
  o = LalondeOptions{};
  o.canny_high = o.canny_low - 1.0;
  EXPECT_NE(o.validate().message().find("lalonde.canny_high"), std::string::npos);
  o = LalondeOptions{};
  o.wall_max_weight = 1.0;
  EXPECT_NE(o.validate().message().find("lalonde.wall_max_weight"), std::string::npos);
  o = LalondeOptions{};
  o.sky_min_relative_gray = 1.5;
  EXPECT_NE(o.validate().message().find("lalonde.sky_min_relative_gray"), std::string::npos);
  o = LalondeOptions{};
  o.vo_sigma_azimuth_deg = 0.0;
  EXPECT_NE(o.validate().message().find("lalonde.vo_sigma_azimuth_deg"), std::string::npos);
  LalondeEstimator e(o);
  EXPECT_FALSE(e.init().isOk());
}

}  // namespace
}  // namespace sunvo::sunvision
