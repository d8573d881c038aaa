#pragma once
// Moving cars: other vehicles that drive along the city's streets while the camera passes, so a
// drive's images hold objects whose motion is not the camera's, as real traffic does (outliers
// for the odometry). Each car keeps to the right-hand lane of one street, at a constant speed,
// straight through the intersections, and starts over at the street's far end.
// Grid frame of scene.hpp (x along the first street axis, z up, metres); deterministic per seed.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/render/scene.hpp"

namespace sunvo::render {

struct TrafficOptions {
  int cars = 0;                 // moving cars in the city, [0, 2000]; 0: none (the default)
  double speed_min_mps = 5.0;   // each car's constant speed is drawn in [min, max], m/s, [0, 30]
  double speed_max_mps = 12.0;  // m/s, [speed_min_mps, 30]
  double lane_offset_m = 1.75;  // lane centre right of the street's centre line, m, [0, 10]
  double clearance_m = 12.0;    // a car nearer than this to the ego vehicle is left out of the
                                // frame (no collision model), m, [0, 100]
  Status validate() const;      // names the key: "traffic.cars ..."
};

struct MovingCar {
  Eigen::Vector2d lane_start = Eigen::Vector2d::Zero();  // lane point at arc length 0, m
  Eigen::Vector2d dir = Eigen::Vector2d::UnitX();        // unit direction of travel
  double lane_length_m = 0.0;                            // the street's length, m
  double s0_m = 0.0;                                     // arc length at t = 0, m
  double speed_mps = 0.0;
  int paint = 0;  // styled: T_car<paint>; classic: an index into a fixed colour table

  Eigen::Vector2d positionAt(double t_s) const;  // centre on the ground, wraps at the far end
};

std::vector<MovingCar> generateTraffic(const City& city, const TrafficOptions& options,
                                       std::uint64_t seed);

// The cars at time t_s as primitives (body, cabin, tyres) with the city's textures (styled:
// T_car*, T_glass, T_tyre; classic: plain paints), leaving out those within
// options.clearance_m of ego_xy (the ego vehicle's position in the grid frame).
std::vector<Primitive> trafficAt(const std::vector<MovingCar>& cars, double t_s,
                                 const Eigen::Vector2d& ego_xy, const TrafficOptions& options,
                                 const CityLook& look);

}  // namespace sunvo::render
