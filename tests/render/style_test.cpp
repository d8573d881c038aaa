// Domain randomisation (style.hpp): determinism, the split of kinds between the training and
// held-out looks, every named texture declared, and a styled frame through the real POV-Ray.
#include "sunvo/render/style.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "sunvo/render/drive.hpp"
#include "sunvo/render/pov.hpp"

namespace sunvo::render {
namespace {

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// A small styled city of `blocks` x `blocks` with every hedge and clutter slot filled.
City styledCity(const StyleOptions& style, int blocks) {
  DriveLook d = drawDriveLook(style, CityOptions{});
  d.city.blocks_x = d.city.blocks_y = blocks;
  d.city_look.hedge_probability = d.city_look.clutter_probability = 1.0;
  return generateCity(d.city, style.seed, d.city_look);
}

TEST(Style, SeedZeroIsTheClassicLook) {
  StyleOptions style;
  CityOptions base;
  base.street_width_m = 17.0;
  const DriveLook d = drawDriveLook(style, base);
  EXPECT_FALSE(d.city_look.styled);
  EXPECT_EQ(d.city.street_width_m, 17.0);
  const FrameLook f = drawFrameLook(style, 5, SkyOptions{}, SensorOptions{});
  EXPECT_TRUE(f.materials.empty());
  EXPECT_EQ(f.sensor.response, "srgb");
  EXPECT_EQ(f.glow_level, 0.0);
  // The classic city keeps its own materials; a styled one names declared textures.
  CityOptions o;
  o.blocks_x = o.blocks_y = 2;
  EXPECT_FALSE(generateCity(o, 3).scene.declarations.empty());
  CityLook styled;
  styled.styled = true;
  EXPECT_TRUE(generateCity(o, 3, styled).scene.declarations.empty());
}

TEST(Style, DeterministicPerPeriodAndDifferentAcrossPeriods) {
  const StyleOptions style{42, "train", 1};
  const FrameLook a = drawFrameLook(style, 3, SkyOptions{}, SensorOptions{});
  const FrameLook b = drawFrameLook(style, 3, SkyOptions{}, SensorOptions{});
  const FrameLook c = drawFrameLook(style, 4, SkyOptions{}, SensorOptions{});
  EXPECT_EQ(a.materials, b.materials);
  EXPECT_EQ(a.sensor.white_balance_r, b.sensor.white_balance_r);
  EXPECT_NE(a.materials, c.materials);
  EXPECT_TRUE(a.sensor.validate().isOk()) << a.sensor.validate().toString();
  EXPECT_TRUE(a.sky.validate().isOk());
}

TEST(Style, HeldOutKindsAreNeverDrawnForTraining) {
  std::set<std::string> train_responses, heldout_responses;
  std::set<int> train_trees, heldout_trees, train_cars, heldout_cars;
  int train_heldout_materials = 0, heldout_panels = 0, heldout_train_walls = 0;
  for (std::uint64_t seed = 1; seed <= 150; ++seed) {
    for (const char* set : {"train", "heldout"}) {
      const StyleOptions style{seed, set, 1};
      const FrameLook f = drawFrameLook(style, 0, SkyOptions{}, SensorOptions{});
      const DriveLook d = drawDriveLook(style, CityOptions{});
      ASSERT_TRUE(d.city.validate().isOk()) << d.city.validate().toString();
      ASSERT_TRUE(f.sensor.validate().isOk()) << f.sensor.validate().toString();
      if (std::string(set) == "train") {
        train_responses.insert(f.sensor.response);
        train_trees.insert(static_cast<int>(d.city_look.tree));
        train_cars.insert(static_cast<int>(d.city_look.car));
        train_heldout_materials += count(f.materials, "checker") + count(f.materials, "marble") +
                                   count(f.materials, "hexagon");
      } else {
        heldout_responses.insert(f.sensor.response);
        heldout_trees.insert(static_cast<int>(d.city_look.tree));
        heldout_cars.insert(static_cast<int>(d.city_look.car));
        heldout_panels += count(f.materials, "checker") + count(f.materials, "marble");
        heldout_train_walls += count(f.materials, "bozo") + count(f.materials, "gradient y");
      }
    }
  }
  EXPECT_EQ(train_responses, (std::set<std::string>{"gamma", "scurve", "srgb"}));
  EXPECT_EQ(heldout_responses, (std::set<std::string>{"filmic"}));
  EXPECT_EQ(train_trees, (std::set<int>{0, 1}));
  EXPECT_EQ(heldout_trees, (std::set<int>{2, 3}));
  EXPECT_EQ(train_cars, (std::set<int>{0}));
  EXPECT_EQ(heldout_cars, (std::set<int>{1}));
  EXPECT_EQ(train_heldout_materials, 0);
  EXPECT_EQ(heldout_panels, 150 * kStyleFacades);  // every held-out facade is panels or marble
  EXPECT_EQ(heldout_train_walls, 0);
}

TEST(Style, EveryTextureAStyledCityNamesIsDeclared) {
  for (const char* set : {"train", "heldout"}) {
    const StyleOptions style{7, set, 1};
    const City city = styledCity(style, 3);
    const FrameLook f = drawFrameLook(style, 0, SkyOptions{}, SensorOptions{});
    std::set<std::string> names = {city.scene.ground_texture};
    for (const Primitive& p : city.scene.primitives) names.insert(p.texture);
    EXPECT_GT(names.size(), 20u) << set;
    for (const std::string& n : names) {
      ASSERT_EQ(n.find(' '), std::string::npos) << set << ": inline texture " << n;
      EXPECT_EQ(count(f.materials, "#declare " + n + " = "), 1) << set << ": " << n;
    }
  }
}

TEST(Style, SunGlowBrightensTheSkyAroundTheSunOnly) {
  FrameLook look;
  look.glow_level = 2.0;
  look.glow_width_deg = 3.0;
  cv::Mat sky(64, 128, CV_32FC3, cv::Scalar::all(0.1));
  const Eigen::Vector3d sun_enu(0.0, 1.0, 1.0);  // north, 45 deg up: column 32, row 16
  addSunGlow(sky, sun_enu, look, 0.3);
  EXPECT_GT(sky.at<cv::Vec3f>(15, 31)[1], 10.0f);          // disc: far above saturation
  EXPECT_NEAR(sky.at<cv::Vec3f>(15, 95)[1], 0.1f, 1e-6f);  // opposite side: untouched
  EXPECT_NEAR(sky.at<cv::Vec3f>(48, 31)[1], 0.1f, 1e-6f);  // below the horizon: untouched
  look.glow_level = 0.0;
  cv::Mat plain(64, 128, CV_32FC3, cv::Scalar::all(0.1));
  addSunGlow(plain, sun_enu, look, 0.3);
  EXPECT_EQ(cv::countNonZero(plain.reshape(1) != 0.1f), 0);
}

TEST(Style, SkyKindsRemoveTheAzimuthOrAddClouds) {
  cv::Mat sky(64, 128, CV_32FC3);
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 128; ++j) sky.at<cv::Vec3f>(i, j) = cv::Vec3f::all(0.1f + 0.005f * j);
  FrameLook look;
  cv::Mat perez = sky.clone();
  styleSky(perez, look);
  EXPECT_EQ(cv::norm(perez, sky, cv::NORM_INF), 0.0);
  look.sky_kind = FrameLook::Sky::kAzimuthFree;
  cv::Mat flat = sky.clone();
  styleSky(flat, look);
  EXPECT_NEAR(flat.at<cv::Vec3f>(10, 0)[0], flat.at<cv::Vec3f>(10, 127)[0], 1e-6f);
  EXPECT_NEAR(cv::mean(flat)[0], cv::mean(sky)[0], 1e-6);
  look.sky_kind = FrameLook::Sky::kClouds;
  look.cloud_cover = 0.5;
  look.cloud_seed = 9;
  cv::Mat a = sky.clone(), b = sky.clone();
  styleSky(a, look);
  styleSky(b, look);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);  // deterministic for the seed
  const cv::Mat diff = a != sky;
  const double changed = cv::countNonZero(diff.reshape(1)) / (3.0 * 64 * 128);
  EXPECT_GT(changed, 0.1);  // some of the upper half is cloud
  EXPECT_LT(changed, 0.5);  // never below the horizon
}

TEST(Style, AStyledFrameRendersThroughPovRay) {
  for (const char* set : {"train", "heldout"}) {
    const StyleOptions style{11, set, 1};
    const City city = styledCity(style, 2);
    const FrameLook f = drawFrameLook(style, 0, SkyOptions{}, SensorOptions{});
    Lighting light;
    light.sun_enu = Eigen::Vector3d(0.3, 0.5, 0.8).normalized();
    light.materials = f.materials;
    Isometry3 T_enu_c = Isometry3::Identity();  // on a street, looking east
    T_enu_c.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    T_enu_c.translation() = Eigen::Vector3d(20.0, city.pitch_m - 2.0, 1.6);
    const StereoCamera cam{40.0, 40.0, 31.5, 11.5, 0.5, 64, 24};
    const std::string dir = std::string(SUNVO_BINARY_DIR) + "/render_test/style_" + set;
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/scene.pov") << povFrame({cam}, {T_enu_c}, light, "", &city.scene);
    RenderJob j{dir, "scene.pov", "out.png", cam.width, cam.height, 0, "povray.log"};
    RenderQuality q;
    q.antialias_threshold = 0.0;
    const Status st = runPovray(j, q);
    ASSERT_TRUE(st.isOk()) << set << ": " << st.toString();
    const cv::Mat img = cv::imread(dir + "/out.png", cv::IMREAD_COLOR);
    ASSERT_EQ(img.cols, 64) << set;
    EXPECT_GT(cv::norm(img, cv::NORM_L1), 0.0) << set;
  }
}

TEST(Style, ScenarioKeysAreReadAndCheckedByName) {
  const std::string base = "name: s\nframes: 2\n";
  auto ok = parseScenario(base +
                              "style: {seed: 5, set: heldout, frames_per_look: 3}\n"
                              "sensor: {response: filmic, gamma: 2.0, white_balance_r: 1.2}\n",
                          "t.yaml");
  ASSERT_TRUE(ok) << ok.status().toString();
  EXPECT_EQ(ok->style.seed, 5u);
  EXPECT_EQ(ok->style.set, "heldout");
  EXPECT_EQ(ok->style.frames_per_look, 3);
  EXPECT_EQ(ok->sensor.response, "filmic");
  auto bad_set = parseScenario(base + "style: {set: validation}\n", "t.yaml");
  ASSERT_FALSE(bad_set);
  EXPECT_NE(bad_set.status().message().find("style.set"), std::string::npos);
  auto bad_resp = parseScenario(base + "sensor: {response: log}\n", "t.yaml");
  ASSERT_FALSE(bad_resp);
  EXPECT_NE(bad_resp.status().message().find("sensor.response"), std::string::npos);
  auto bad_key = parseScenario(base + "style: {sed: 5}\n", "t.yaml");
  ASSERT_FALSE(bad_key);
  EXPECT_NE(bad_key.status().message().find("style.sed"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::render
