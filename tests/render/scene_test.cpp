#include "sunvo/render/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "sunvo/render/drive.hpp"
#include "sunvo/render/pov.hpp"

namespace sunvo::render {
namespace {

TEST(City, DeterministicForASeedAndDifferentAcrossSeeds) {
  CityOptions o;
  o.blocks_x = 3;
  o.blocks_y = 3;
  const std::string a = povSceneBody(generateCity(o, 11).scene);
  const std::string b = povSceneBody(generateCity(o, 11).scene);
  const std::string c = povSceneBody(generateCity(o, 12).scene);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_GT(generateCity(o, 11).scene.primitives.size(), 200u);
}

// Low-texture stretches: a plain block has only plain walls and ground, no street furniture, and
// bare road up to the centre lines around it; with probability 0 nothing plain is drawn.
TEST(City, PlainBlocksAreLowTextureStretches) {
  CityOptions o;
  o.blocks_x = 4;
  o.blocks_y = 4;
  auto textures = [](const City& c) {
    std::map<std::string, int> n;
    for (const Primitive& p : c.scene.primitives) ++n[p.texture.substr(0, 7)];
    return n;
  };
  const City none = generateCity(o, 11);
  EXPECT_EQ(none.scene.declarations.find("T_plain"), std::string::npos);
  EXPECT_EQ(textures(none).count("T_plain"), 0u);
  o.plain_block_probability = 1.0;
  const City all = generateCity(o, 11);
  const auto n = textures(all);
  EXPECT_NE(all.scene.declarations.find("#declare T_plain_wall"), std::string::npos);
  EXPECT_EQ(n.count("T_pole"), 0u);
  EXPECT_EQ(n.count("T_trunk"), 0u);
  EXPECT_EQ(n.count("T_mark"), 1u);  // the centre-line dashes stay, under the bare road
  int road = 0, walls = 0;
  for (const Primitive& p : all.scene.primitives) {
    if (p.texture == "T_plain_road") {
      ++road;
      EXPECT_NEAR(p.b.x() - p.a.x(), all.pitch_m, 1e-9);  // centre line to centre line
      EXPECT_GT(p.b.z(), 0.005);                          // above the dashes' top
    }
    walls += p.texture == "T_plain_wall";
  }
  EXPECT_EQ(road, 16);
  EXPECT_GT(walls, 16 * 4);
  o.plain_block_probability = 0.3;
  const auto some = textures(generateCity(o, 11));
  EXPECT_GT(some.count("T_plain"), 0u);
  EXPECT_GT(some.count("T_pole"), 0u);
  o.plain_block_probability = 1.5;
  EXPECT_NE(o.validate().message().find("city.plain_block_probability"), std::string::npos);
}

TEST(Route, DeterministicSpeedsHeightAndTurns) {
  auto s = loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/ci_short.yaml");
  ASSERT_TRUE(s) << s.status().toString();
  const City city = generateCity(s->city, s->seed);
  auto r1 = generateRoute(city, s->route, 300, s->seed);
  auto r2 = generateRoute(city, s->route, 300, s->seed);
  ASSERT_TRUE(r1) << r1.status().toString();
  ASSERT_TRUE(r2);
  ASSERT_EQ(r1->size(), 300u);
  double max_speed = 0, min_speed = 1e9, yaw_travel = 0, max_tilt = 0;
  for (std::size_t k = 0; k < r1->size(); ++k) {
    EXPECT_TRUE((*r1)[k].T_enu_b.isApprox((*r2)[k].T_enu_b, 0.0));
    const auto& st = (*r1)[k];
    max_speed = std::max(max_speed, st.speed_mps);
    min_speed = std::min(min_speed, st.speed_mps);
    max_tilt = std::max({max_tilt, std::abs(st.roll_rad), std::abs(st.pitch_rad)});
    const double h = (st.T_enu_b * bodyFromCamera0()).translation().z();
    EXPECT_NEAR(h, 1.65, 0.05);
    if (k > 0) {
      const double dy = st.yaw_rad - (*r1)[k - 1].yaw_rad;
      yaw_travel += std::abs(std::atan2(std::sin(dy), std::cos(dy)));
      // 10 Hz: displacement = speed / 10 within the speed change of one frame.
      const double step = (st.T_enu_b.translation() - (*r1)[k - 1].T_enu_b.translation()).norm();
      EXPECT_NEAR(step, 0.05 * (st.speed_mps + (*r1)[k - 1].speed_mps), 0.05);
    }
  }
  EXPECT_LE(max_speed, s->route.speed_max_mps + 1e-9);
  EXPECT_GE(max_speed, s->route.speed_min_mps);
  EXPECT_GT(min_speed, 3.0);   // turns slow down to sqrt(a_lat R), never stop
  EXPECT_GT(yaw_travel, 1.4);  // at least one ~90 deg turn in 30 s
  EXPECT_LT(max_tilt, 3.0 * 3.14159 / 180.0);
  EXPECT_GT(max_tilt, 0.05 * 3.14159 / 180.0);
}

TEST(Scenario, ValidationNamesTheBadKey) {
  auto a = parseScenario("route: {speed_maxx_mps: 3}\n", "t.yaml");
  ASSERT_FALSE(a);
  EXPECT_NE(a.status().message().find("route.speed_maxx_mps"), std::string::npos);
  auto b = parseScenario("route: {speed_max_mps: 50}\n", "t.yaml");
  ASSERT_FALSE(b);
  EXPECT_NE(b.status().message().find("route.speed_max_mps"), std::string::npos);
  auto c = parseScenario("sky: {turbidity: abc}\n", "t.yaml");
  ASSERT_FALSE(c);
  EXPECT_NE(c.status().message().find("sky.turbidity"), std::string::npos);
  auto d = parseScenario("start_utc: \"2026-13-01 00:00:00\"\n", "t.yaml");
  EXPECT_FALSE(d);
  auto e = parseScenario("frames: 20\nplace: {latitude_deg: 10}\n", "t.yaml");
  ASSERT_TRUE(e) << e.status().toString();
  EXPECT_EQ(e->frames, 20);
  EXPECT_EQ(e->latitude_deg, 10.0);
}

TEST(Scenario, EveryShippedScenarioLoads) {
  int n = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    auto s = loadScenario(entry.path().string());
    EXPECT_TRUE(s) << entry.path() << ": " << s.status().toString();
    ++n;
  }
  EXPECT_GE(n, 48);
}

TEST(Scenario, BenchmarkDrivesAreLongerThanOneKilometre) {
  for (const char* n : {"bench_karlsruhe_summer_noon", "bench_oslo_winter_lowsun",
                        "bench_phoenix_autumn_evening"}) {
    auto s = loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/" + n + ".yaml");
    ASSERT_TRUE(s) << n << ": " << s.status().toString();
    auto r = generateRoute(generateCity(s->city, s->seed), s->route, s->frames, s->seed);
    ASSERT_TRUE(r) << n << ": " << r.status().toString();
    double len = 0;
    for (std::size_t k = 1; k < r->size(); ++k)
      len += ((*r)[k].T_enu_b.translation() - (*r)[k - 1].T_enu_b.translation()).norm();
    std::printf("%s: %d frames, %.0f m\n", n, s->frames, len);
    EXPECT_GT(len, 1000.0) << n;
  }
}

TEST(Kitti, TimestampFormat) {
  EXPECT_EQ(kittiTimestamp(civilToUtcNs(2011, 9, 26, 13, 2, 25, 967790592)),
            "2011-09-26 13:02:25.967790592");
}

TEST(Scenario, RigErrorIsReadAndRangeChecked) {
  auto a = parseScenario("rig_error: {right_roll_start_deg: 0.02, right_roll_end_deg: 0.08}\n",
                         "t.yaml");
  ASSERT_TRUE(a) << a.status().toString();
  EXPECT_EQ(a->rig_error.right_roll_start_deg, 0.02);
  EXPECT_EQ(a->rig_error.right_roll_end_deg, 0.08);
  EXPECT_TRUE(a->rig_error.any());
  EXPECT_FALSE(Scenario{}.rig_error.any());
  auto b = parseScenario("rig_error: {right_pitch_end_deg: 3}\n", "t.yaml");
  ASSERT_FALSE(b);
  EXPECT_NE(b.status().message().find("rig_error.right_pitch_end_deg"), std::string::npos);
  auto c = parseScenario("rig_error: {right_rol_end_deg: 0.1}\n", "t.yaml");
  ASSERT_FALSE(c);
  EXPECT_NE(c.status().message().find("rig_error.right_rol_end_deg"), std::string::npos);
}

// What the rendered images carry (small angles): a right-camera roll theta about its optical
// axis makes vL - vR = theta (u - cu) fv / fu, a pitch delta makes vL - vR = -fv delta
// (1 + ((v - cv) / fv)^2) (0.3 px at the centre row for delta = 0.3 / fv), both changing linearly
// from the first to the last frame. Checked by projecting points through the nominal and the
// turned right camera.
TEST(Drive, RightCameraErrorTurnsTheRightCameraLinearlyOverTheDrive) {
  const StereoCamera cam{721.5377, 721.5377, 609.5593, 172.854, 0.537, 1242, 375};
  RigErrorOptions o;
  o.right_roll_start_deg = 0.02;
  o.right_roll_end_deg = 0.08;
  o.right_pitch_start_deg = 0.0;
  o.right_pitch_end_deg = 0.3 / cam.fv * 180.0 / 3.141592653589793;
  const Eigen::Vector3d mid = rightCameraErrorDeg(o, 0.5);
  EXPECT_NEAR(mid.x(), 0.05, 1e-12);
  EXPECT_NEAR(mid.y(), 0.5 * o.right_pitch_end_deg, 1e-12);
  EXPECT_EQ(rightCameraErrorDeg(o, 2.0), rightCameraErrorDeg(o, 1.0));  // clamped
  EXPECT_TRUE(rightCameraError(RigErrorOptions{}, 0.7).isApprox(Isometry3::Identity()));
  for (const double progress : {0.0, 1.0}) {
    const Eigen::Vector3d e = rightCameraErrorDeg(o, progress) * 3.141592653589793 / 180.0;
    const Isometry3 T_c1nom_c1 = rightCameraError(o, progress);
    for (const Eigen::Vector3d& p_c1nom :
         {Eigen::Vector3d(-8, 1, 20), Eigen::Vector3d(6, -2, 15), Eigen::Vector3d(0.5, 0.2, 30)}) {
      const Eigen::Vector3d p_c1 = T_c1nom_c1.inverse() * p_c1nom;
      const double u_nom = cam.cu + cam.fu * p_c1nom.x() / p_c1nom.z();
      const double v_nom = cam.cv + cam.fv * p_c1nom.y() / p_c1nom.z();  // = vL of a true rig
      const double v_right = cam.cv + cam.fv * p_c1.y() / p_c1.z();
      const double y_n = (v_nom - cam.cv) / cam.fv;  // the pitch term grows off-centre
      const double expected =
          e.x() * (u_nom - cam.cu) * cam.fv / cam.fu - cam.fv * e.y() * (1.0 + y_n * y_n);
      EXPECT_NEAR(v_nom - v_right, expected, 2e-3) << "progress " << progress;
    }
  }
}

// Path length of a scenario's route, m; the twin's route must be the same pose for pose.
double twinRouteLength(const std::string& bad_name, const std::string& good_name) {
  auto bad = loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/" + bad_name);
  auto good = loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/" + good_name);
  EXPECT_TRUE(bad) << bad.status().toString();
  EXPECT_TRUE(good) << good.status().toString();
  if (!bad || !good) return 0.0;
  EXPECT_TRUE(bad->rig_error.any());
  EXPECT_FALSE(good->rig_error.any());
  EXPECT_EQ(bad->seed, good->seed);
  EXPECT_EQ(bad->frames, good->frames);
  EXPECT_EQ(bad->start_utc, good->start_utc);
  auto r = generateRoute(generateCity(bad->city, bad->seed), bad->route, bad->frames, bad->seed);
  auto r2 =
      generateRoute(generateCity(good->city, good->seed), good->route, good->frames, good->seed);
  EXPECT_TRUE(r && r2);
  if (!r || !r2) return 0.0;
  double len = 0;
  for (std::size_t k = 1; k < r->size(); ++k) {
    len += ((*r)[k].T_enu_b.translation() - (*r)[k - 1].T_enu_b.translation()).norm();
    EXPECT_TRUE((*r)[k].T_enu_b.isApprox((*r2)[k].T_enu_b)) << k;
  }
  std::printf("%s: %d frames, %.0f m\n", bad_name.c_str(), bad->frames, len);
  return len;
}

TEST(Scenario, DriftBenchmarkTwinsDifferOnlyInTheRigAndAreLongerThanThreeKilometres) {
  EXPECT_GT(twinRouteLength("bench_drift_miscalibrated.yaml", "bench_drift_calibrated.yaml"),
            3000.0);
}

TEST(Scenario, BusyShortDriftTwinsDifferOnlyInTheRig) {
  EXPECT_GT(twinRouteLength("bench_drift_short_aa_busy_miscalibrated.yaml",
                            "bench_drift_short_aa_busy_calibrated.yaml"),
            250.0);
}

TEST(Scenario, ShortDriftTwinsDifferOnlyInTheRig) {
  EXPECT_GT(
      twinRouteLength("bench_drift_short_miscalibrated.yaml", "bench_drift_short_calibrated.yaml"),
      250.0);
}

}  // namespace
}  // namespace sunvo::render
