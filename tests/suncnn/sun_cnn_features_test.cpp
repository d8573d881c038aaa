// Sun-CNN's feature term: the distance of the trunk's features from the training images'
// (sun_cnn_features.hpp), its JSON, and how it widens the estimator's sigma.
#include "sunvo/suncnn/sun_cnn_features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "sunvo/suncnn/sun_cnn_estimator.hpp"

namespace sunvo::suncnn {
namespace {

const std::string kModel = std::string(SUNVO_SOURCE_DIR) + "/config/sun_cnn.onnx";

// Two members, three features, two axes each.
SunCnnFeaturePrior smallPrior() {
  SunCnnFeaturePrior p;
  p.components = 2;
  p.features = 3;
  p.mean = {1, 0, 0, 0, 0, 2};
  p.axes = {1, 0, 0, 0, 1, 0, /* member 1 */ 0, 0, 1, 0.6, 0.8, 0};
  p.variances = {4, 1, 1, 25};
  return p;
}

TEST(SunCnnFeaturePrior, DistanceIsTheWhitenedProjection) {
  const SunCnnFeaturePrior p = smallPrior();
  ASSERT_TRUE(p.validate(2, 3, "feature_prior").isOk());
  EXPECT_EQ(p.members(), 2);
  const float x0[] = {3, -1, 7};  // (2^2 / 4 + 1^2 / 1) / 2 = 1
  EXPECT_DOUBLE_EQ(p.memberDistance(0, x0), 1.0);
  const float x1[] = {5, 10, 2};  // z = (0, 0.6 * 5 + 0.8 * 10 = 11): (0 + 121 / 25) / 2
  EXPECT_NEAR(p.memberDistance(1, x1), 121.0 / 50.0, 1e-12);
  EXPECT_TRUE(SunCnnFeaturePrior{}.empty());
  EXPECT_TRUE(SunCnnFeaturePrior{}.validate(3, 768, "k").isOk()) << "no prior is valid";
}

TEST(SunCnnFeaturePrior, ValidateNamesTheKey) {
  SunCnnFeaturePrior p = smallPrior();
  const Status members = p.validate(3, 3, "suncnn.feature_prior");
  EXPECT_FALSE(members.isOk());
  EXPECT_NE(members.message().find("suncnn.feature_prior"), std::string::npos);
  EXPECT_FALSE(p.validate(2, 4, "k").isOk()) << "features differ from the model's";
  p.variances[3] = 0.0;
  EXPECT_NE(p.validate(2, 3, "k").message().find("variances"), std::string::npos);
  p = smallPrior();
  p.axes[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(p.validate(2, 3, "k").isOk());
  p = smallPrior();
  p.components = 4;
  EXPECT_FALSE(p.validate(2, 3, "k").isOk());
}

TEST(SunCnnFeaturePrior, WeaknessIsTheNegativeLogBelowOne) {
  EXPECT_EQ(featureWeakness(1.0), 0.0);
  EXPECT_EQ(featureWeakness(3.0), 0.0);
  EXPECT_NEAR(featureWeakness(std::exp(-2.0)), 2.0, 1e-12);
  EXPECT_NEAR(featureWeakness(0.0), -std::log(1e-12), 1e-9);
  EXPECT_EQ(featureWeakness(std::numeric_limits<double>::quiet_NaN()), 0.0);
}

TEST(SunCnnFeatures, TheShippedJsonCarriesTheColourPrior) {
  auto j = loadSunCnnOptions(modelJsonPath(kModel));
  ASSERT_TRUE(j.hasValue()) << j.status().toString();
  const SunCnnOptions defaults;
  EXPECT_NEAR(defaults.feature_gain, j->feature_gain, 5e-5) << "feature_gain";
  EXPECT_NEAR(defaults.gray_feature_gain, j->gray_feature_gain, 5e-5);
  EXPECT_GT(j->feature_gain, 0.0);
  EXPECT_EQ(j->feature_prior.members(), j->ensemble_members);
  EXPECT_EQ(j->feature_prior.features, j->mask1_size);
  EXPECT_GE(j->feature_prior.components, 1);
  EXPECT_TRUE(defaults.feature_prior.empty()) << "the defaults carry no prior";
}

// The term as the header writes it: sigma^2 = scale^2 (raw^2 + gain max(0, -ln d)). A prior with
// every variance 1e6 times larger gives d / 1e6 (weak features), 1e-6 times larger d * 1e6.
TEST(SunCnnFeatures, WeakFeaturesWidenSigmaByTheFormula) {
  auto j = loadSunCnnOptions(modelJsonPath(kModel));
  ASSERT_TRUE(j.hasValue()) << j.status().toString();
  SunCnnOptions o = *j;
  o.sigma_min_rad = 0.0;
  o.sigma_max_rad = 10.0;
  cv::Mat img(125, 414, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(img, img, cv::Size(9, 9), 3.0);
  sunfusion::ImageSunInput in;
  in.color = img;
  const auto run = [&](const SunCnnOptions& opt) {
    SunCnnEstimator est;  // fresh: the same dropout masks every time
    const Status st = est.init(opt, kModel);
    EXPECT_TRUE(st.isOk()) << st.toString();
    auto e = est.estimate(in);
    EXPECT_TRUE(e.hasValue());
    return std::pair{e ? *e : sunfusion::ImageSunEstimate{}, est.lastRaw()};
  };
  SunCnnOptions off = o;
  off.feature_gain = 0.0;
  const auto [e0, raw0] = run(off);
  const double base2 = std::pow(e0.measurement.sigma / o.sigma_scale, 2);
  const auto [e1, raw1] = run(o);
  ASSERT_GT(raw1.feature_distance, 0.0);
  EXPECT_NEAR(raw1.feature_weakness, featureWeakness(raw1.feature_distance), 1e-12);
  EXPECT_NEAR(e1.measurement.sigma,
              o.sigma_scale * std::sqrt(base2 + o.feature_gain * raw1.feature_weakness), 1e-9);
  EXPECT_EQ(e1.azimuth_deg, e0.azimuth_deg) << "the answer itself does not change";
  for (const double k : {1e6, 1e-6}) {
    SunCnnOptions scaled = o;
    for (double& v : scaled.feature_prior.variances) v *= k;
    const auto [e, raw] = run(scaled);
    EXPECT_NEAR(raw.feature_distance, raw1.feature_distance / k, 1e-9 * raw1.feature_distance / k);
    const double weak = std::max(0.0, -std::log(raw1.feature_distance / k));
    EXPECT_NEAR(raw.feature_weakness, weak, 1e-9);
    EXPECT_NEAR(e.measurement.sigma, o.sigma_scale * std::sqrt(base2 + o.feature_gain * weak),
                1e-9);
    if (k > 1.0) {
      EXPECT_FALSE(e.valid) << "features a thousand sigma weak are not valid";
    }
  }
  // Without a prior there is no term, whatever the gain.
  SunCnnOptions no_prior = o;
  no_prior.feature_prior = SunCnnFeaturePrior{};
  const auto [e2, raw2] = run(no_prior);
  EXPECT_EQ(raw2.feature_distance, -1.0);
  EXPECT_DOUBLE_EQ(e2.measurement.sigma, e0.measurement.sigma);
  // A gain out of range is refused by init, naming the key.
  o.feature_gain = -1.0;
  SunCnnEstimator bad;
  const Status st = bad.init(o, kModel);
  EXPECT_NE(st.message().find("suncnn.feature_gain"), std::string::npos) << st.message();
}

std::string writeJson(const std::string& name, const std::string& text) {
  const std::string dir = std::string(SUNVO_BINARY_DIR) + "/suncnn_features_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/" + name) << text;
  return dir + "/" + name;
}

TEST(SunCnnFeatures, AJsonWithoutTheTermMeansNoneAndABadPriorNamesTheKey) {
  auto none = loadSunCnnOptions(writeJson("none.json", "{ \"sigma_scale\": 0.6 }\n"));
  ASSERT_TRUE(none.hasValue()) << none.status().toString();
  EXPECT_EQ(none->feature_gain, 0.0);
  EXPECT_TRUE(none->feature_prior.empty());
  const std::string small =
      "\"components\": 1, \"features\": 2, \"members\": [{\"mean\": [0, 0], \"axes\": [1, 0], "
      "\"variances\": [2]}]";
  auto ok = loadSunCnnOptions(
      writeJson("small.json",
                "{ \"mc\": {\"members\": 1, \"mask1\": 2}, \"feature_gain\": 0.5, "
                "\"feature_prior\": {" +
                    small + "} }\n"));
  ASSERT_TRUE(ok.hasValue()) << ok.status().toString();
  EXPECT_EQ(ok->feature_prior.variances, std::vector<double>{2.0});
  EXPECT_EQ(ok->gray_feature_prior.mean, ok->feature_prior.mean) << "no gray_input: the colour's";
  EXPECT_DOUBLE_EQ(ok->gray_feature_gain, 0.5);
  struct Case {
    const char* file;
    std::string text;
    const char* key;
  };
  for (const Case& c :
       {Case{"text.json",
             "{ \"feature_prior\": {\"components\": 1, \"features\": 2, "
             "\"members\": [{\"mean\": [0, \"x\"]}]} }",
             "feature_prior.members[0].mean[1]"},
        Case{"list.json", "{ \"feature_prior\": {\"components\": 1, \"members\": 3} }",
             "feature_prior.members"},
        Case{"sizes.json",
             "{ \"mc\": {\"members\": 2, \"mask1\": 2}, \"feature_prior\": {" + small + "} }",
             "feature_prior"},
        Case{"grey.json", "{ \"gray_input\": { \"feature_prior\": [1] } }",
             "gray_input.feature_prior"}}) {
    auto bad = loadSunCnnOptions(writeJson(c.file, c.text));
    ASSERT_FALSE(bad.hasValue()) << c.file;
    EXPECT_NE(bad.status().message().find(c.file), std::string::npos) << bad.status().message();
    EXPECT_NE(bad.status().message().find(c.key), std::string::npos) << bad.status().message();
  }
}

}  // namespace
}  // namespace sunvo::suncnn
