#include "sunvo/render/traffic.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <random>

namespace sunvo::render {
namespace {

Status range(const std::string& key, const std::string& r) {
  return invalidArgument("traffic." + key + " out of range " + r);
}

constexpr std::array<const char*, kStyleCars> kClassicPaint = {
    "pigment { rgb <0.55,0.08,0.06> } finish { specular 0.3 }",
    "pigment { rgb <0.08,0.15,0.45> } finish { specular 0.3 }",
    "pigment { rgb <0.70,0.70,0.68> } finish { specular 0.3 }",
    "pigment { rgb <0.05,0.05,0.05> } finish { specular 0.3 }",
    "pigment { rgb <0.20,0.35,0.18> } finish { specular 0.3 }",
    "pigment { rgb <0.62,0.52,0.20> } finish { specular 0.3 }"};

}  // namespace

Status TrafficOptions::validate() const {
  if (!(cars >= 0 && cars <= 2000)) return range("cars", "[0, 2000]");
  if (!(speed_min_mps >= 0 && speed_min_mps <= 30)) return range("speed_min_mps", "[0, 30]");
  if (!(speed_max_mps >= speed_min_mps && speed_max_mps <= 30))
    return range("speed_max_mps", "[speed_min_mps, 30]");
  if (!(lane_offset_m >= 0 && lane_offset_m <= 10)) return range("lane_offset_m", "[0, 10]");
  if (!(clearance_m >= 0 && clearance_m <= 100)) return range("clearance_m", "[0, 100]");
  return Status::ok();
}

Eigen::Vector2d MovingCar::positionAt(double t_s) const {
  double s = std::fmod(s0_m + speed_mps * t_s, lane_length_m);
  if (s < 0) s += lane_length_m;
  return lane_start + dir * s;
}

std::vector<MovingCar> generateTraffic(const City& city, const TrafficOptions& o,
                                       std::uint64_t seed) {
  std::vector<MovingCar> cars;
  if (o.cars <= 0) return cars;
  std::mt19937_64 rng(seed * 2654435761ULL + 99);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const int nx = city.options.blocks_x, ny = city.options.blocks_y;
  const double P = city.pitch_m, Lx = nx * P, Ly = ny * P;
  // Streets: x = i P (i = 0..nx, along y, length Ly) and y = j P (j = 0..ny, along x, length Lx);
  // a lane per street and direction. Driving on the right: heading +y the lane is at +x,
  // heading +x it is at -y.
  const int lanes = 2 * (nx + 1) + 2 * (ny + 1);
  cars.reserve(static_cast<std::size_t>(o.cars));
  for (int k = 0; k < o.cars; ++k) {
    const int lane = static_cast<int>(rng() % static_cast<std::uint64_t>(lanes));
    MovingCar c;
    const double sign = lane % 2 == 0 ? 1.0 : -1.0;
    if (lane < 2 * (nx + 1)) {  // along y
      const double x = (lane / 2) * P;
      c.dir = Eigen::Vector2d(0, sign);
      c.lane_start = Eigen::Vector2d(x + sign * o.lane_offset_m, sign > 0 ? 0.0 : Ly);
      c.lane_length_m = Ly;
    } else {  // along x
      const double y = ((lane - 2 * (nx + 1)) / 2) * P;
      c.dir = Eigen::Vector2d(sign, 0);
      c.lane_start = Eigen::Vector2d(sign > 0 ? 0.0 : Lx, y - sign * o.lane_offset_m);
      c.lane_length_m = Lx;
    }
    c.s0_m = U(rng) * c.lane_length_m;
    c.speed_mps = o.speed_min_mps + (o.speed_max_mps - o.speed_min_mps) * U(rng);
    c.paint = static_cast<int>(rng() % kStyleCars);
    cars.push_back(c);
  }
  return cars;
}

std::vector<Primitive> trafficAt(const std::vector<MovingCar>& cars, double t_s,
                                 const Eigen::Vector2d& ego_xy, const TrafficOptions& o,
                                 const CityLook& look) {
  std::vector<Primitive> out;
  out.reserve(cars.size() * 3);
  for (const MovingCar& car : cars) {
    const Eigen::Vector2d c = car.positionAt(t_s);
    if ((c - ego_xy).norm() < o.clearance_m) continue;
    addSedan(out, c, car.dir,
             look.styled ? "T_car" + std::to_string(car.paint)
                         : std::string(kClassicPaint[static_cast<std::size_t>(car.paint)]),
             look.styled ? "T_tyre" : "pigment { rgb 0.03 }");
  }
  return out;
}

}  // namespace sunvo::render
