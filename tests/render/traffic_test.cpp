// Moving cars (traffic.hpp): on their lanes, driving on the right at their own speed, wrapping at
// the street's end, left out near the ego vehicle, deterministic per seed, options by key.
#include "sunvo/render/traffic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace sunvo::render {
namespace {

City smallCity() {
  CityOptions o;
  o.blocks_x = 3;
  o.blocks_y = 2;
  return generateCity(o, 5);
}

TEST(Traffic, CarsKeepToTheRightHandLaneOfAStreetAndMoveAtTheirSpeed) {
  const City city = smallCity();
  TrafficOptions o;
  o.cars = 200;
  const auto cars = generateTraffic(city, o, 7);
  ASSERT_EQ(cars.size(), 200u);
  const double P = city.pitch_m;
  int along_x = 0, along_y = 0;
  for (const MovingCar& c : cars) {
    EXPECT_GE(c.speed_mps, o.speed_min_mps);
    EXPECT_LE(c.speed_mps, o.speed_max_mps);
    // Right of the centre line seen in the direction of travel: centre + offset * (dir_y, -dir_x).
    const Eigen::Vector2d right(c.dir.y(), -c.dir.x());
    for (const double t : {0.0, 3.0, 17.5}) {
      const Eigen::Vector2d p = c.positionAt(t);
      const Eigen::Vector2d centre = p - o.lane_offset_m * right;
      const double across = std::abs(c.dir.x()) > 0.5 ? centre.y() : centre.x();
      EXPECT_NEAR(across / P, std::round(across / P), 1e-9) << "not on a street centre line";
      EXPECT_GE(p.x(), -o.lane_offset_m - 1e-9);
      EXPECT_GE(p.y(), -o.lane_offset_m - 1e-9);
      EXPECT_LE(p.x(), city.options.blocks_x * P + o.lane_offset_m + 1e-9);
      EXPECT_LE(p.y(), city.options.blocks_y * P + o.lane_offset_m + 1e-9);
    }
    // Between two nearby times it moves speed * dt along its direction (unless it wrapped).
    const Eigen::Vector2d d = c.positionAt(1.0) - c.positionAt(0.5);
    if (d.norm() < c.lane_length_m / 2) {
      EXPECT_TRUE(d.isApprox(0.5 * c.speed_mps * c.dir, 1e-9));
    }
    (std::abs(c.dir.x()) > 0.5 ? along_x : along_y)++;
  }
  EXPECT_GT(along_x, 20);
  EXPECT_GT(along_y, 20);
  // Wraps: after one lane length at its speed it is back where it started.
  const MovingCar& c = cars.front();
  EXPECT_TRUE(c.positionAt(c.lane_length_m / c.speed_mps).isApprox(c.positionAt(0.0), 1e-9));
}

TEST(Traffic, DeterministicPerSeedAndNoneByDefault) {
  const City city = smallCity();
  TrafficOptions o;
  EXPECT_TRUE(generateTraffic(city, o, 7).empty());
  o.cars = 20;
  const auto a = generateTraffic(city, o, 7), b = generateTraffic(city, o, 7),
             c = generateTraffic(city, o, 8);
  ASSERT_EQ(a.size(), b.size());
  bool differs = false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].positionAt(2.0), b[k].positionAt(2.0));
    differs |= a[k].positionAt(2.0) != c[k].positionAt(2.0);
  }
  EXPECT_TRUE(differs);
}

TEST(Traffic, CarsNearTheEgoVehicleAreLeftOutAndTheRestAreDrawn) {
  const City city = smallCity();
  TrafficOptions o;
  o.cars = 30;
  const auto cars = generateTraffic(city, o, 3);
  CityLook styled;
  styled.styled = true;
  const Eigen::Vector2d far(-1000, -1000);
  const auto all = trafficAt(cars, 4.0, far, o, styled);
  ASSERT_EQ(all.size(), 3 * cars.size());  // body, cabin, tyres
  EXPECT_EQ(all[0].texture.rfind("T_car", 0), 0u);
  EXPECT_EQ(all[1].texture, "T_glass");
  const auto near = trafficAt(cars, 4.0, cars[0].positionAt(4.0), o, styled);
  EXPECT_LT(near.size(), all.size());
  for (const Primitive& p : near) {
    const Eigen::Vector2d c = 0.5 * (p.a + p.b).head<2>();
    EXPECT_GE((c - cars[0].positionAt(4.0)).norm(), o.clearance_m - 2.2);
  }
  const auto classic = trafficAt(cars, 4.0, far, o, CityLook{});
  EXPECT_NE(classic[0].texture.find("pigment"), std::string::npos);
}

TEST(Traffic, OptionsNameTheirKey) {
  TrafficOptions o;
  EXPECT_TRUE(o.validate().isOk());
  o.cars = -1;
  EXPECT_NE(o.validate().message().find("traffic.cars"), std::string::npos);
  o = TrafficOptions{};
  o.speed_max_mps = 2.0;  // below speed_min_mps
  EXPECT_NE(o.validate().message().find("traffic.speed_max_mps"), std::string::npos);
  o = TrafficOptions{};
  o.clearance_m = 200;
  EXPECT_NE(o.validate().message().find("traffic.clearance_m"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::render
