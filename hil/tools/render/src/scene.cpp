#include "sunvo/render/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

namespace sunvo::render {
namespace {
constexpr double kPi = std::numbers::pi;

Status range(const char* key, const char* r) {
  return invalidArgument(std::string(key) + " out of range " + r);
}

std::string rgb(double r, double g, double b) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "rgb <%.3f,%.3f,%.3f>", r, g, b);
  return buf;
}

Primitive box(Eigen::Vector3d a, Eigen::Vector3d b, std::string tex) {
  return {Primitive::Kind::kBox, a, b, 0.0, std::move(tex)};
}

// Static textures shared by the whole city (POV-Ray syntax; POV axes are <east, up, north>).
// WinA..WinC: 1 inside a window, 0 on the wall; the horizontal coordinate along either facade
// orientation is x + z (the other one is constant on a facade), the vertical one is y.
const char* kDeclarations =
    R"(#declare WinA = function(x,y,z) { (mod(abs(x+z),3.0) > 0.8) & (mod(abs(x+z),3.0) < 2.2) & (mod(abs(y),3.2) > 1.0) & (mod(abs(y),3.2) < 2.6) & (y > 1.5) }
#declare WinB = function(x,y,z) { (mod(abs(x+z),4.0) > 0.6) & (mod(abs(x+z),4.0) < 3.4) & (mod(abs(y),3.5) > 0.9) & (mod(abs(y),3.5) < 2.9) & (y > 3.0) }
#declare WinC = function(x,y,z) { (mod(abs(x+z),2.2) > 0.5) & (mod(abs(x+z),2.2) < 1.5) & (mod(abs(y),3.0) > 0.8) & (mod(abs(y),3.0) < 2.4) & (y > 1.2) }
#declare T_sidewalk = texture { pigment { brick color rgb 0.36 color rgb 0.48 brick_size <0.6,0.3,0.6> mortar 0.02 } normal { granite 0.2 scale 0.05 } }
#declare T_sidewalk2 = texture { pigment { granite scale 0.4 color_map { [0 rgb 0.38] [0.5 rgb 0.50] [1 rgb 0.44] } } }
#declare T_mark = texture { pigment { granite scale 0.2 color_map { [0 rgb 0.70] [1 rgb 0.85] } } }
#declare T_pole = texture { pigment { rgb <0.25,0.27,0.28> } }
#declare T_trunk = texture { pigment { granite scale 0.1 color_map { [0 rgb <0.20,0.14,0.09>] [1 rgb <0.32,0.24,0.16>] } } }
#declare T_crown = texture { pigment { granite scale 0.35 color_map { [0 rgb <0.05,0.14,0.04>] [0.6 rgb <0.12,0.26,0.07>] [1 rgb <0.20,0.33,0.10>] } } normal { bumps 0.8 scale 0.25 } }
#declare T_glass = texture { pigment { rgb <0.10,0.13,0.16> } }
)";

// Plain surfaces of the low-texture stretches (CityOptions::plain_block_probability), declared in
// the city itself so that the classic and the styled looks both have them.
const char* kPlainDeclarations =
    "#declare T_plain_wall = texture { pigment { rgb 0.55 } }\n"
    "#declare T_plain_ground = texture { pigment { rgb 0.42 } }\n"
    "#declare T_plain_road = texture { pigment { rgb 0.16 } }\n";

// The buildings of the block (x0, y0)-(x1, y1) (sidewalks included): two rows (south half, north
// half) of lots along x, each lot's width and then its height drawn from uni, and then
// texture() (which may draw too) names its texture.
template <typename Uni, typename Texture>
void addBuildings(Scene& sc, const CityOptions& o, double x0, double y0, double x1, double y1,
                  Uni& uni, Texture&& texture) {
  const double sw = o.sidewalk_width_m;
  for (int row = 0; row < 2; ++row) {
    const double ya = row == 0 ? y0 + sw : 0.5 * (y0 + y1);
    const double yb = row == 0 ? 0.5 * (y0 + y1) : y1 - sw;
    double x = x0 + sw;
    while (x < x1 - sw - 1e-6) {
      double w = uni(o.min_lot_m, o.max_lot_m);
      if (x1 - sw - (x + w) < o.min_lot_m) w = x1 - sw - x;
      const double h = uni(o.min_height_m, o.max_height_m);
      sc.primitives.push_back(box({x, ya, 0.0}, {x + w, yb, h}, texture()));
      x += w;
    }
  }
}

const char* kAsphalt =
    "pigment { granite scale 0.15 color_map { [0 rgb 0.10] [0.5 rgb 0.17] [1 rgb 0.23] } } "
    "normal { granite 0.15 scale 0.03 }";

// Styled crowns: a sphere, an ellipsoid (taller or flatter), a cone (conifer) or a cluster of
// three spheres, all of about the classic crown's size (radius rc, centred at c).
template <typename Uni>
void addCrown(Scene& sc, CityLook::Tree shape, const Eigen::Vector3d& c, double rc, Uni& uni) {
  switch (shape) {
    case CityLook::Tree::kSphere:
      sc.primitives.push_back(
          {Primitive::Kind::kSphere, c, Eigen::Vector3d::Zero(), rc, "T_crown"});
      break;
    case CityLook::Tree::kEllipsoid: {
      const double flat = uni(0.6, 1.6);  // vertical over horizontal semi-axis
      sc.primitives.push_back(
          {Primitive::Kind::kEllipsoid, c, {rc, rc, rc * flat}, 0.0, "T_crown"});
      break;
    }
    case CityLook::Tree::kCone:
      sc.primitives.push_back({Primitive::Kind::kCone, c - Eigen::Vector3d(0, 0, 1.2 * rc),
                               c + Eigen::Vector3d(0, 0, 1.6 * rc), 0.9 * rc, "T_crown"});
      break;
    case CityLook::Tree::kCluster:
      for (int i = 0; i < 3; ++i) {
        const double ang = 2.0944 * i + uni(-0.5, 0.5);
        const Eigen::Vector3d d(0.5 * rc * std::cos(ang), 0.5 * rc * std::sin(ang),
                                uni(-0.3, 0.4) * rc);
        sc.primitives.push_back(
            {Primitive::Kind::kSphere, c + d, Eigen::Vector3d::Zero(), 0.7 * rc, "T_crown"});
      }
      break;
  }
}

// Hedges along the facades and clutter near the curb on one sidewalk (curb from a along t,
// street on the side `out`, length L).
template <typename Uni>
void addSidewalkExtras(Scene& sc, const CityLook& look, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& t, const Eigen::Vector2d& out, double L,
                       double sidewalk_m, Uni& uni) {
  for (double s = 3.0; s < L - 9.0; s += 12.0) {
    if (uni(0.0, 1.0) < look.hedge_probability) {
      const double len = uni(3.0, 8.0), depth = uni(0.6, 1.0), h = uni(0.6, 1.5);
      const Eigen::Vector2d p = a + t * s - out * (sidewalk_m - depth);
      const Eigen::Vector2d q = p + t * len - out * depth;
      sc.primitives.push_back(box({std::min(p.x(), q.x()), std::min(p.y(), q.y()), 0.1},
                                  {std::max(p.x(), q.x()), std::max(p.y(), q.y()), h}, "T_hedge"));
    }
    if (uni(0.0, 1.0) < look.clutter_probability) {
      const Eigen::Vector2d p = a + t * (s + uni(1.0, 8.0)) - out * 0.6;
      if (look.clutter == CityLook::Clutter::kBins) {
        const double r = uni(0.25, 0.4), h = uni(0.8, 1.2);
        sc.primitives.push_back(
            {Primitive::Kind::kCylinder, {p.x(), p.y(), 0.0}, {p.x(), p.y(), h}, r, "T_clutter"});
      } else {  // a row of bollards and a bench behind them
        for (int i = 0; i < 3; ++i) {
          const Eigen::Vector2d b = p + t * (1.4 * i);
          sc.primitives.push_back({Primitive::Kind::kCylinder,
                                   {b.x(), b.y(), 0.0},
                                   {b.x(), b.y(), 0.9},
                                   0.1,
                                   "T_clutter"});
        }
        const Eigen::Vector2d q = p - out * 1.0, r = q + t * 1.8 - out * 0.5;
        sc.primitives.push_back(box({std::min(q.x(), r.x()), std::min(q.y(), r.y()), 0.0},
                                    {std::max(q.x(), r.x()), std::max(q.y(), r.y()), 0.45},
                                    "T_clutter"));
      }
    }
  }
}

// Half extents on the ground of a car whose length runs along the unit street axis `along`.
Eigen::Vector2d carHalfExtents(const Eigen::Vector2d& along, double half_length,
                               double half_width) {
  const Eigen::Vector2d across(-along.y(), along.x());
  return along.cwiseAbs() * half_length + across.cwiseAbs() * half_width;
}

// The dark band between a car's body and the ground.
Primitive tyreBand(const Eigen::Vector2d& c, const Eigen::Vector2d& half, const std::string& tyre) {
  return box({c.x() - half.x() + 0.4, c.y() - half.y() + 0.1, 0.0},
             {c.x() + half.x() - 0.4, c.y() + half.y() - 0.1, 0.25}, tyre);
}

// A styled parked car: a sedan (as the classic one) or a van (one tall body with a glass band);
// its paint is one of the declared T_car textures.
void addStyledCar(Scene& sc, CityLook::Car shape, const Eigen::Vector2d& c,
                  const Eigen::Vector2d& along, std::mt19937_64& rng) {
  const std::string paint = "T_car" + std::to_string(rng() % kStyleCars);
  if (shape == CityLook::Car::kSedan) {
    addSedan(sc.primitives, c, along, paint, "T_tyre");
    return;
  }
  const Eigen::Vector2d half = carHalfExtents(along, 2.1, 0.9);
  sc.primitives.push_back(box({c.x() - half.x(), c.y() - half.y(), 0.25},
                              {c.x() + half.x(), c.y() + half.y(), 1.5}, paint));
  sc.primitives.push_back(box({c.x() - half.x() - 0.01, c.y() - half.y() - 0.01, 1.5},
                              {c.x() + half.x() + 0.01, c.y() + half.y() + 0.01, 2.0}, "T_glass"));
  sc.primitives.push_back(box({c.x() - half.x(), c.y() - half.y(), 2.0},
                              {c.x() + half.x(), c.y() + half.y(), 2.2}, paint));
  sc.primitives.push_back(tyreBand(c, half, "T_tyre"));
}

}  // namespace

void addSedan(std::vector<Primitive>& out, const Eigen::Vector2d& c, const Eigen::Vector2d& along,
              const std::string& paint, const std::string& tyre) {
  const Eigen::Vector2d half = carHalfExtents(along, 2.1, 0.9);
  const Eigen::Vector2d half_cab = carHalfExtents(along, 1.1, 0.8);
  out.push_back(box({c.x() - half.x(), c.y() - half.y(), 0.25},
                    {c.x() + half.x(), c.y() + half.y(), 0.95}, paint));
  out.push_back(box({c.x() - half_cab.x(), c.y() - half_cab.y(), 0.95},
                    {c.x() + half_cab.x(), c.y() + half_cab.y(), 1.45}, "T_glass"));
  out.push_back(tyreBand(c, half, tyre));
}

Status CityOptions::validate() const {
  if (!(blocks_x >= 1 && blocks_x <= 60)) return range("city.blocks_x", "[1, 60]");
  if (!(blocks_y >= 1 && blocks_y <= 60)) return range("city.blocks_y", "[1, 60]");
  if (!(block_size_m >= 20 && block_size_m <= 300)) return range("city.block_size_m", "[20, 300]");
  if (!(street_width_m >= 8 && street_width_m <= 40))
    return range("city.street_width_m", "[8, 40]");
  if (!(sidewalk_width_m >= 1 && sidewalk_width_m <= 10))
    return range("city.sidewalk_width_m", "[1, 10]");
  if (!(min_height_m >= 3 && min_height_m <= 200)) return range("city.min_height_m", "[3, 200]");
  if (!(max_height_m >= min_height_m && max_height_m <= 300))
    return range("city.max_height_m", "[min_height_m, 300]");
  if (!(min_lot_m >= 4 && min_lot_m <= 100)) return range("city.min_lot_m", "[4, 100]");
  if (!(max_lot_m >= min_lot_m && max_lot_m <= 200))
    return range("city.max_lot_m", "[min_lot_m, 200]");
  if (!(pole_spacing_m >= 5 && pole_spacing_m <= 200))
    return range("city.pole_spacing_m", "[5, 200]");
  if (!(tree_probability >= 0 && tree_probability <= 1))
    return range("city.tree_probability", "[0, 1]");
  if (!(parked_car_probability >= 0 && parked_car_probability <= 1))
    return range("city.parked_car_probability", "[0, 1]");
  if (!(plain_block_probability >= 0 && plain_block_probability <= 1))
    return range("city.plain_block_probability", "[0, 1]");
  return Status::ok();
}

City generateCity(const CityOptions& o, std::uint64_t seed, const CityLook& look) {
  City city;
  city.options = o;
  city.pitch_m = o.block_size_m + o.street_width_m;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto uni = [&](double a, double b) { return a + (b - a) * U(rng); };
  Scene& sc = city.scene;
  sc.declarations = look.styled ? "" : kDeclarations;
  sc.ground_texture = look.styled ? "T_asphalt" : kAsphalt;
  const double P = city.pitch_m, hw = 0.5 * o.street_width_m, B = o.block_size_m;
  static constexpr std::array<std::array<double, 3>, 8> kWall = {{{0.62, 0.55, 0.46},
                                                                  {0.55, 0.55, 0.55},
                                                                  {0.70, 0.62, 0.50},
                                                                  {0.48, 0.30, 0.24},
                                                                  {0.75, 0.72, 0.66},
                                                                  {0.40, 0.42, 0.45},
                                                                  {0.66, 0.50, 0.38},
                                                                  {0.58, 0.60, 0.52}}};
  const char* kWin[3] = {"WinA", "WinB", "WinC"};
  for (int bi = 0; bi < o.blocks_x; ++bi) {
    for (int bj = 0; bj < o.blocks_y; ++bj) {
      const double x0 = bi * P + hw, y0 = bj * P + hw;  // block corner (incl. sidewalk)
      const double x1 = x0 + B, y1 = y0 + B;
      const bool plain = o.plain_block_probability > 0 && U(rng) < o.plain_block_probability;
      if (plain) {  // a low-texture stretch: plain block, bare half-streets around it
        if (sc.declarations.find(kPlainDeclarations) == std::string::npos)
          sc.declarations += kPlainDeclarations;
        sc.primitives.push_back(
            box({bi * P, bj * P, 0.001}, {(bi + 1) * P, (bj + 1) * P, 0.006}, "T_plain_road"));
        sc.primitives.push_back(box({x0, y0, 0.0}, {x1, y1, 0.15}, "T_plain_ground"));
        addBuildings(sc, o, x0, y0, x1, y1, uni, [] { return std::string("T_plain_wall"); });
        continue;
      }
      sc.primitives.push_back(
          box({x0, y0, 0.0}, {x1, y1, 0.15}, U(rng) < 0.5 ? "T_sidewalk" : "T_sidewalk2"));
      addBuildings(sc, o, x0, y0, x1, y1, uni, [&] {
        if (look.styled) return std::string("F").append(std::to_string(rng() % kStyleFacades));
        const auto& c = kWall[static_cast<std::size_t>(rng() % kWall.size())];
        const double s = uni(0.85, 1.1);
        char tex[512];
        std::snprintf(tex, sizeof tex,
                      "pigment { function { %s(x,y,z) } pigment_map { [0 granite scale %.2f "
                      "color_map { [0 %s] [1 %s] }] [1 rgb <%.3f,%.3f,%.3f>] } }",
                      kWin[rng() % 3], uni(0.3, 1.5),
                      rgb(c[0] * s * 0.8, c[1] * s * 0.8, c[2] * s * 0.8).c_str(),
                      rgb(c[0] * s, c[1] * s, c[2] * s).c_str(), uni(0.06, 0.14), uni(0.08, 0.16),
                      uni(0.10, 0.2));
        return std::string(tex);
      });
      // Street furniture along the four sidewalks: poles, trees (curb side), parked cars.
      for (int side = 0; side < 4; ++side) {
        // Curb line running from a to b, with the street on the outward side `out`.
        Eigen::Vector2d a, b, out;
        if (side == 0) {
          a = {x0, y0};
          b = {x1, y0};
          out = {0, -1};
        }
        if (side == 1) {
          a = {x1, y0};
          b = {x1, y1};
          out = {1, 0};
        }
        if (side == 2) {
          a = {x1, y1};
          b = {x0, y1};
          out = {0, 1};
        }
        if (side == 3) {
          a = {x0, y1};
          b = {x0, y0};
          out = {-1, 0};
        }
        const Eigen::Vector2d t = (b - a).normalized();
        const double L = (b - a).norm();
        for (double s = 0.5 * o.pole_spacing_m; s < L - 2.0; s += o.pole_spacing_m) {
          const Eigen::Vector2d p = a + t * (s + uni(-1.5, 1.5)) - out * 0.5;
          sc.primitives.push_back({Primitive::Kind::kCylinder,
                                   {p.x(), p.y(), 0.0},
                                   {p.x(), p.y(), 6.0},
                                   0.09,
                                   "T_pole"});
          const Eigen::Vector2d q = p + out * 1.2;
          sc.primitives.push_back(
              box({std::min(p.x(), q.x()) - 0.1, std::min(p.y(), q.y()) - 0.1, 5.9},
                  {std::max(p.x(), q.x()) + 0.1, std::max(p.y(), q.y()) + 0.1, 6.05}, "T_pole"));
        }
        for (double s = 6.0; s < L - 6.0; s += 12.0) {
          if (U(rng) >= o.tree_probability) continue;
          const Eigen::Vector2d p = a + t * (s + uni(-2.0, 2.0)) - out * 1.3;
          const double ht = uni(2.0, 3.2), rc = uni(1.3, 2.4);
          sc.primitives.push_back({Primitive::Kind::kCylinder,
                                   {p.x(), p.y(), 0.0},
                                   {p.x(), p.y(), ht + rc},
                                   0.14,
                                   "T_trunk"});
          if (look.styled) {
            addCrown(sc, look.tree, {p.x(), p.y(), ht + rc}, rc, uni);
          } else {
            sc.primitives.push_back(
                {Primitive::Kind::kSphere, {p.x(), p.y(), ht + rc}, {}, rc, "T_crown"});
          }
        }
        if (look.styled) addSidewalkExtras(sc, look, a, t, out, L, o.sidewalk_width_m, uni);
        // Parked cars on the curb lane, not within 12 m of an intersection.
        for (double s = 12.0; s < L - 12.0; s += 7.0) {
          if (U(rng) >= o.parked_car_probability) continue;
          const Eigen::Vector2d c = a + t * (s + uni(-0.5, 0.5)) + out * 1.1;
          if (look.styled) {
            addStyledCar(sc, look.car, c, t, rng);
            continue;
          }
          const auto col = rgb(uni(0.05, 0.8), uni(0.05, 0.8), uni(0.05, 0.8));
          addSedan(sc.primitives, c, t, "pigment { " + col + " } finish { specular 0.3 }",
                   "pigment { rgb 0.03 }");
        }
      }
    }
  }
  // Dashed centre lines on every street segment between intersections (3 m dash, 6 m gap).
  for (int i = 0; i <= o.blocks_x; ++i) {
    for (int j = 0; j <= o.blocks_y; ++j) {
      for (int dir = 0; dir < 2; ++dir) {
        if (dir == 0 && i == o.blocks_x) continue;
        if (dir == 1 && j == o.blocks_y) continue;
        for (double s = hw + 2.0; s + 3.0 < P - hw - 2.0; s += 9.0) {
          if (dir == 0) {
            sc.primitives.push_back(box({i * P + s, j * P - 0.07, -0.01},
                                        {i * P + s + 3.0, j * P + 0.07, 0.005}, "T_mark"));
          } else {
            sc.primitives.push_back(box({i * P - 0.07, j * P + s, -0.01},
                                        {i * P + 0.07, j * P + s + 3.0, 0.005}, "T_mark"));
          }
        }
      }
      // Stop/edge lines near the curbs.
    }
  }
  return city;
}

Status RouteOptions::validate() const {
  if (!(speed_min_mps >= 1 && speed_min_mps <= 40)) return range("route.speed_min_mps", "[1, 40]");
  if (!(speed_max_mps >= speed_min_mps && speed_max_mps <= 40))
    return range("route.speed_max_mps", "[speed_min_mps, 40]");
  if (!(max_lateral_accel_mps2 >= 0.5 && max_lateral_accel_mps2 <= 10))
    return range("route.max_lateral_accel_mps2", "[0.5, 10]");
  if (!(max_long_accel_mps2 >= 0.2 && max_long_accel_mps2 <= 10))
    return range("route.max_long_accel_mps2", "[0.2, 10]");
  if (!(turn_probability >= 0 && turn_probability <= 1))
    return range("route.turn_probability", "[0, 1]");
  if (!(turn_radius_m >= 3 && turn_radius_m <= 30)) return range("route.turn_radius_m", "[3, 30]");
  if (!(lane_offset_m >= 0 && lane_offset_m <= 10)) return range("route.lane_offset_m", "[0, 10]");
  if (!(rate_hz > 0 && rate_hz <= 100)) return range("route.rate_hz", "(0, 100]");
  if (!(pitch_amplitude_deg >= 0 && pitch_amplitude_deg <= 5))
    return range("route.pitch_amplitude_deg", "[0, 5]");
  if (!(roll_amplitude_deg >= 0 && roll_amplitude_deg <= 5))
    return range("route.roll_amplitude_deg", "[0, 5]");
  if (!(roll_per_lateral_accel_deg >= 0 && roll_per_lateral_accel_deg <= 3))
    return range("route.roll_per_lateral_accel_deg", "[0, 3]");
  if (!(pitch_per_long_accel_deg >= 0 && pitch_per_long_accel_deg <= 3))
    return range("route.pitch_per_long_accel_deg", "[0, 3]");
  return Status::ok();
}

Expected<std::vector<VehicleState>> generateRoute(const City& city, const RouteOptions& o,
                                                  int num_frames, std::uint64_t seed) {
  SUNVO_RETURN_IF_ERROR(o.validate());
  if (num_frames < 1) return invalidArgument("route: num_frames must be >= 1");
  const double P = city.pitch_m;
  if (o.turn_radius_m + o.lane_offset_m > 0.5 * P || o.lane_offset_m >= o.turn_radius_m) {
    return invalidArgument("route.turn_radius_m incompatible with the street pitch / lane offset");
  }
  const int nx = city.options.blocks_x, ny = city.options.blocks_y;
  // Interior intersections when there are any, so both sides of the street are built up.
  const int imin = nx >= 2 ? 1 : 0, imax = nx >= 2 ? nx - 1 : nx;
  const int jmin = ny >= 2 ? 1 : 0, jmax = ny >= 2 ? ny - 1 : ny;
  if (imax - imin < 1 && jmax - jmin < 1) return invalidArgument("route: city grid too small");
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  static constexpr int kDx[4] = {1, 0, -1, 0}, kDy[4] = {0, 1, 0, -1};
  auto valid = [&](int i, int j) { return i >= imin && i <= imax && j >= jmin && j <= jmax; };
  const double need = o.speed_max_mps * (num_frames + 2) / o.rate_hz + 2.0 * P;
  std::vector<Eigen::Vector2d> nodes;
  int ci = imin, cj = jmin, d = imax > imin ? 0 : 1;
  nodes.emplace_back(ci * P, cj * P);
  double len = 0.0;
  while (len < need) {
    int nd = d;
    if (U(rng) < o.turn_probability) nd = (d + (U(rng) < 0.5 ? 1 : 3)) % 4;
    if (!valid(ci + kDx[nd], cj + kDy[nd])) {
      std::array<int, 3> cand = {d, (d + 1) % 4, (d + 3) % 4};
      std::shuffle(cand.begin(), cand.end(), rng);
      nd = -1;
      for (int c : cand)
        if (valid(ci + kDx[c], cj + kDy[c])) {
          nd = c;
          break;
        }
      if (nd < 0) nd = (d + 2) % 4;  // dead end (1-wide grid): U-turn
    }
    d = nd;
    ci += kDx[d];
    cj += kDy[d];
    nodes.emplace_back(ci * P, cj * P);
    len += P;
  }
  // Dense centre line with fillets (radius R) at the corners; then offset to the right lane.
  const double R = o.turn_radius_m, ds = 0.05;
  std::vector<Eigen::Vector2d> centre;
  auto addLine = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    const double l = (q - p).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(l / ds)));
    for (int k = 0; k < n; ++k) centre.push_back(p + (q - p) * (static_cast<double>(k) / n));
  };
  Eigen::Vector2d cur = nodes.front();
  for (std::size_t k = 1; k + 1 < nodes.size(); ++k) {
    const Eigen::Vector2d uin = (nodes[k] - nodes[k - 1]).normalized();
    const Eigen::Vector2d uout = (nodes[k + 1] - nodes[k]).normalized();
    const double cross = uin.x() * uout.y() - uin.y() * uout.x();
    if (std::abs(cross) < 0.5) {
      if (uin.dot(uout) > 0) continue;  // straight on
      // U-turn: pass through the node.
      addLine(cur, nodes[k]);
      cur = nodes[k];
      continue;
    }
    const Eigen::Vector2d t0 = nodes[k] - R * uin;
    addLine(cur, t0);
    const Eigen::Vector2d nrm =
        cross > 0 ? Eigen::Vector2d(-uin.y(), uin.x()) : Eigen::Vector2d(uin.y(), -uin.x());
    const Eigen::Vector2d c = t0 + R * nrm;
    const int n = static_cast<int>(std::ceil(0.5 * kPi * R / ds));
    const Eigen::Vector2d r0 = t0 - c;
    for (int m = 0; m < n; ++m) {
      const double ang = (cross > 0 ? 1.0 : -1.0) * 0.5 * kPi * m / n;
      centre.push_back(c + Eigen::Rotation2Dd(ang) * r0);
    }
    cur = nodes[k] + R * uout;
  }
  addLine(cur, nodes.back());
  centre.push_back(nodes.back());
  // Offset to the right of the travel direction, then arc length, heading, curvature.
  const std::size_t N = centre.size();
  std::vector<Eigen::Vector2d> path(N);
  std::vector<double> S(N, 0.0), yaw(N), kappa(N, 0.0), v(N);
  for (std::size_t k = 0; k < N; ++k) {
    const Eigen::Vector2d tg =
        (centre[std::min(k + 1, N - 1)] - centre[k == 0 ? 0 : k - 1]).normalized();
    path[k] = centre[k] + o.lane_offset_m * Eigen::Vector2d(tg.y(), -tg.x());
    yaw[k] = std::atan2(tg.y(), tg.x());
  }
  for (std::size_t k = 1; k < N; ++k) S[k] = S[k - 1] + (path[k] - path[k - 1]).norm();
  for (std::size_t k = 1; k + 1 < N; ++k) {
    double dy = yaw[k + 1] - yaw[k - 1];
    dy = std::atan2(std::sin(dy), std::cos(dy));
    const double dl = S[k + 1] - S[k - 1];
    kappa[k] = dl > 1e-9 ? dy / dl : 0.0;
  }
  // Speed: a smooth cruise profile in [min, max], capped by v^2 |kappa| <= a_lat, then forward
  // and backward passes enforcing v dv/ds <= a_long (v_{k+1}^2 <= v_k^2 + 2 a ds).
  const double vmid = 0.5 * (o.speed_min_mps + o.speed_max_mps);
  const double vamp = 0.5 * (o.speed_max_mps - o.speed_min_mps);
  const double ph = 2.0 * kPi * U(rng);
  for (std::size_t k = 0; k < N; ++k) {
    double vc = vmid + vamp * std::sin(2.0 * kPi * S[k] / 350.0 + ph);
    // Curvature over a 3 m window so the fillet entry is anticipated by the passes below.
    if (std::abs(kappa[k]) > 1e-6)
      vc = std::min(vc, std::sqrt(o.max_lateral_accel_mps2 / std::abs(kappa[k])));
    v[k] = vc;
  }
  for (std::size_t k = 1; k < N; ++k)
    v[k] = std::min(
        v[k], std::sqrt(v[k - 1] * v[k - 1] + 2.0 * o.max_long_accel_mps2 * (S[k] - S[k - 1])));
  for (std::size_t k = N - 1; k-- > 0;)
    v[k] = std::min(
        v[k], std::sqrt(v[k + 1] * v[k + 1] + 2.0 * o.max_long_accel_mps2 * (S[k + 1] - S[k])));
  auto lookup = [&](double s) {
    const auto it = std::upper_bound(S.begin(), S.end(), s);
    const std::size_t k = std::min<std::size_t>(
        static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - S.begin(), 1)) - 1, N - 2);
    const double w = std::clamp((s - S[k]) / std::max(S[k + 1] - S[k], 1e-12), 0.0, 1.0);
    return std::make_pair(k, w);
  };
  std::vector<VehicleState> out;
  out.reserve(static_cast<std::size_t>(num_frames));
  const double ph_p1 = 2 * kPi * U(rng), ph_p2 = 2 * kPi * U(rng);
  const double ph_r1 = 2 * kPi * U(rng), ph_r2 = 2 * kPi * U(rng);
  double s = 0.0;
  const int sub = 20;
  const double dt = 1.0 / o.rate_hz / sub;
  for (int f = 0; f < num_frames; ++f) {
    if (f > 0) {
      for (int m = 0; m < sub; ++m) {  // midpoint integration of ds/dt = v(s)
        auto [k0, w0] = lookup(s);
        const double v0 = v[k0] * (1 - w0) + v[k0 + 1] * w0;
        auto [k1, w1] = lookup(s + 0.5 * dt * v0);
        s += dt * (v[k1] * (1 - w1) + v[k1 + 1] * w1);
      }
    }
    auto [k, w] = lookup(s);
    if (k + 2 >= N) return invalidArgument("route: path too short (internal)");
    VehicleState st;
    st.t_s = f / o.rate_hz;
    const Eigen::Vector2d p = path[k] * (1 - w) + path[k + 1] * w;
    double dyaw = std::atan2(std::sin(yaw[k + 1] - yaw[k]), std::cos(yaw[k + 1] - yaw[k]));
    st.yaw_rad = yaw[k] + w * dyaw;
    st.speed_mps = v[k] * (1 - w) + v[k + 1] * w;
    const double kap = kappa[k] * (1 - w) + kappa[k + 1] * w;
    const double a_lat = st.speed_mps * st.speed_mps * kap;  // to the left when > 0
    const double dvds = (v[k + 1] - v[k]) / std::max(S[k + 1] - S[k], 1e-9);
    const double a_long = st.speed_mps * dvds;
    const double deg = kPi / 180.0;
    // Suspension response: pitch nose-up under acceleration, roll outward in turns, plus two
    // incommensurate road-roughness oscillations over distance.
    st.pitch_rad = deg * (o.pitch_per_long_accel_deg * a_long +
                          o.pitch_amplitude_deg * (0.6 * std::sin(2 * kPi * s / 7.3 + ph_p1) +
                                                   0.4 * std::sin(2 * kPi * s / 2.9 + ph_p2)));
    st.roll_rad = deg * (o.roll_per_lateral_accel_deg * a_lat +
                         o.roll_amplitude_deg * (0.6 * std::sin(2 * kPi * s / 5.1 + ph_r1) +
                                                 0.4 * std::sin(2 * kPi * s / 2.3 + ph_r2)));
    const Eigen::Matrix3d C = (Eigen::AngleAxisd(st.yaw_rad, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-st.pitch_rad, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(st.roll_rad, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    st.T_enu_b = Isometry3::Identity();
    st.T_enu_b.linear() = C;
    st.T_enu_b.translation() = Eigen::Vector3d(p.x(), p.y(), 0.0);
    st.v_enu = st.speed_mps * Eigen::Vector3d(std::cos(st.yaw_rad), std::sin(st.yaw_rad), 0.0);
    out.push_back(st);
  }
  return out;
}

}  // namespace sunvo::render
