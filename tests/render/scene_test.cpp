#include "sunvo/render/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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
  for (const char* n : {"ci_short", "bench_karlsruhe_summer_noon", "bench_oslo_winter_lowsun",
                        "bench_phoenix_autumn_evening"}) {
    auto s = loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/" + n + ".yaml");
    EXPECT_TRUE(s) << n << ": " << s.status().toString();
  }
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

}  // namespace
}  // namespace sunvo::render
