#pragma once
// Scene content for the renderer: generic primitives in local ENU (x east, y north, z up,
// metres), a Manhattan-grid city generator and a vehicle route through its streets.
// Everything is deterministic for a seed (std::mt19937_64, no global state).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::render {

struct Primitive {
  enum class Kind { kBox, kCylinder, kSphere, kCone, kEllipsoid };
  Kind kind = Kind::kBox;
  // box: min corner; cylinder, cone: base centre; sphere, ellipsoid: centre
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  // box: max corner; cylinder: top centre; cone: apex; ellipsoid: semi-axes along e, n, u
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;  // cylinder, sphere; cone: base radius
  std::string texture;  // POV-Ray texture body (inside texture { }) or a declared name
};

struct Scene {
  std::string declarations;  // POV-Ray #declare lines written before the primitives
  std::string ground_texture = "pigment { rgb 0.2 }";  // texture of the plane z = 0
  std::vector<Primitive> primitives;
};

struct CityOptions {
  int blocks_x = 6;                      // blocks along east, [1, 60]
  int blocks_y = 6;                      // blocks along north, [1, 60]
  double block_size_m = 60.0;            // side of a block incl. sidewalks, m, [20, 300]
  double street_width_m = 14.0;          // curb to curb, m, [8, 40]
  double sidewalk_width_m = 3.0;         // m, [1, 10]
  double min_height_m = 6.0;             // building height range, m, [3, 200]
  double max_height_m = 30.0;            // m, [min_height_m, 300]
  double min_lot_m = 10.0;               // building frontage range, m, [4, 100]
  double max_lot_m = 24.0;               // m, [min_lot_m, 200]
  double pole_spacing_m = 25.0;          // street lamps along each sidewalk, m, [5, 200]
  double tree_probability = 0.5;         // chance of a tree per 12 m sidewalk slot, [0, 1]
  double parked_car_probability = 0.35;  // chance per 7 m curb slot, [0, 1]
  // Low-texture stretches: the share of blocks built of plain, untextured surfaces (walls without
  // windows, bare sidewalks, no street furniture) whose surrounding half-streets are bare road
  // without marks, [0, 1]. 0 (the default) draws nothing from the seed for it.
  double plain_block_probability = 0.0;
  Status validate() const;
};

struct City {
  CityOptions options;
  Scene scene;
  double pitch_m = 0.0;  // distance between street centre lines = block + street width
  // Street centre lines: x = i * pitch_m (i = 0..blocks_x), y = j * pitch_m (j = 0..blocks_y).
};

// What a style (style.hpp) changes in the city's geometry. styled = false: the classic city,
// whose fixed materials are in Scene::declarations. styled = true: every primitive names a
// texture that each frame declares (style.hpp, FrameLook::materials): F0..F7 (facades with
// their windows), T_asphalt, T_sidewalk, T_sidewalk2, T_mark, T_pole, T_trunk, T_crown, T_hedge,
// T_glass, T_car0..T_car5, T_tyre, T_clutter.
struct CityLook {
  bool styled = false;
  enum class Tree { kSphere, kEllipsoid, kCone, kCluster } tree = Tree::kSphere;
  enum class Car { kSedan, kVan } car = Car::kSedan;
  enum class Clutter { kBins, kBollards } clutter = Clutter::kBins;
  double hedge_probability = 0.0;    // hedge along a facade per 12 m sidewalk slot, [0, 1]
  double clutter_probability = 0.0;  // bins / bollards per 12 m sidewalk slot, [0, 1]
};
inline constexpr int kStyleFacades = 8;  // F0..F7
inline constexpr int kStyleCars = 6;     // T_car0..T_car5

City generateCity(const CityOptions& options, std::uint64_t seed, const CityLook& look = {});

// A sedan, 4.2 m long and 1.8 m wide, centred at c on the ground with its length along the unit
// street axis `along`: a body from 0.25 to 0.95 m in `paint`, a cabin to 1.45 m in T_glass and a
// tyre band below in `tyre`. The parked cars (generateCity) and the moving ones (traffic.hpp).
void addSedan(std::vector<Primitive>& out, const Eigen::Vector2d& c, const Eigen::Vector2d& along,
              const std::string& paint, const std::string& tyre);

struct RouteOptions {
  double speed_min_mps = 8.0;               // cruise speed range, m/s, [1, 40]
  double speed_max_mps = 12.0;              // m/s, [speed_min_mps, 40]
  double max_lateral_accel_mps2 = 3.0;      // limits speed in turns, m/s^2, [0.5, 10]
  double max_long_accel_mps2 = 1.5;         // braking/acceleration limit, m/s^2, [0.2, 10]
  double turn_probability = 0.4;            // chance to turn at an intersection, [0, 1]
  double turn_radius_m = 10.0;              // centre-line fillet radius, m, [3, 30]
  double lane_offset_m = 1.75;              // right of the centre line, m, [0, 10]
  double rate_hz = 10.0;                    // frame rate, Hz, (0, 100]
  double pitch_amplitude_deg = 0.3;         // road-induced pitch oscillation, deg, [0, 5]
  double roll_amplitude_deg = 0.3;          // road-induced roll oscillation, deg, [0, 5]
  double roll_per_lateral_accel_deg = 0.4;  // body roll per m/s^2 lateral acceleration, [0, 3]
  double pitch_per_long_accel_deg = 0.3;    // body pitch per m/s^2 longitudinal accel, [0, 3]
  Status validate() const;
};

// Vehicle body frame b: x forward, y left, z up, origin on the ground below the IMU.
// R_enu_b = Rz(yaw) Ry(-pitch) Rx(roll): yaw from east counter-clockwise, pitch nose-up positive,
// roll right-side-down positive. "enu" here is the city's own frame: renderDrive turns it into
// true ENU by place.grid_heading_deg (the same when that is 0).
struct VehicleState {
  double t_s = 0.0;                                 // since the first frame
  Isometry3 T_enu_b;                                // pose
  Eigen::Vector3d v_enu = Eigen::Vector3d::Zero();  // m/s
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;
  double speed_mps = 0.0;
};

// num_frames states at rate_hz along a random walk over the city's intersections (start at the
// south-west corner heading east), driving on the right. Fails when the grid is too small.
Expected<std::vector<VehicleState>> generateRoute(const City& city, const RouteOptions& options,
                                                  int num_frames, std::uint64_t seed);

}  // namespace sunvo::render
