#include "sunvo/render/style.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace sunvo::render {
namespace {

// SplitMix64 finaliser: decorrelates the seeds of neighbouring look periods.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Draw {
 public:
  Draw(const StyleOptions& s, std::uint64_t stream)
      : rng_(mix(mix(s.seed) ^ mix(stream) ^ (s.set == "heldout" ? 0x5bd1e995ULL : 0ULL))),
        heldout_(s.set == "heldout") {}
  double uni(double a, double b) { return a + (b - a) * U_(rng_); }
  bool chance(double p) { return U_(rng_) < p; }
  int below(int n) { return static_cast<int>(rng_() % static_cast<std::uint64_t>(n)); }
  // One of the kinds [0, n_train) for the training set, [n_train, n_train + n_heldout) else.
  int kind(int n_train, int n_heldout) {
    return heldout_ ? n_train + below(n_heldout) : below(n_train);
  }

 private:
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> U_{0.0, 1.0};
  bool heldout_;
};

std::string rgb(const Eigen::Vector3d& c) {
  char b[96];
  std::snprintf(b, sizeof b, "rgb <%.3f,%.3f,%.3f>", c.x(), c.y(), c.z());
  return b;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

// HSV (hue in degrees) to linear RGB.
Eigen::Vector3d hsv(double h, double s, double v) {
  const double c = v * s, hp = std::fmod(h, 360.0) / 60.0;
  const double x = c * (1.0 - std::abs(std::fmod(hp, 2.0) - 1.0));
  Eigen::Vector3d r;
  if (hp < 1)
    r = {c, x, 0};
  else if (hp < 2)
    r = {x, c, 0};
  else if (hp < 3)
    r = {0, c, x};
  else if (hp < 4)
    r = {0, x, c};
  else if (hp < 5)
    r = {x, 0, c};
  else
    r = {c, 0, x};
  return r + Eigen::Vector3d::Constant(v - c);
}

Eigen::Vector3d wallColour(Draw& d) {
  return hsv(d.uni(0, 360), std::pow(d.uni(0, 1), 1.5) * 0.6, d.uni(0.25, 0.85));
}

// Window function W<i>(x, y, z): 1 on glass, 0 on the wall (POV axes: x + z runs along either
// facade orientation, y up).
std::string windowFunction(Draw& d, int i) {
  const double P = d.uni(1.8, 4.5), Q = d.uni(2.8, 3.8), sill = d.uni(0.8, 4.0);
  const double wf = d.uni(0.3, 0.75), hf = d.uni(0.35, 0.7);
  const double u0 = 0.5 * (1 - wf) * P, u1 = P - u0, v0 = d.uni(0.1, 0.9 - hf) * Q,
               v1 = v0 + hf * Q;
  char b[512];
  const std::string h = "mod(abs(x+z)," + num(P) + ")", v = "mod(abs(y)," + num(Q) + ")";
  switch (d.kind(1, 2)) {
    case 0:  // punched windows on a grid (one in ten walls blank)
      if (d.chance(0.1)) {
        std::snprintf(b, sizeof b, "#declare W%d = function(x,y,z) { 0 }\n", i);
      } else {
        std::snprintf(b, sizeof b,
                      "#declare W%d = function(x,y,z) { (%s > %.3f) & (%s < %.3f) & (%s > %.3f) & "
                      "(%s < %.3f) & (y > %.3f) }\n",
                      i, h.c_str(), u0, h.c_str(), u1, v.c_str(), v0, v.c_str(), v1, sill);
      }
      break;
    case 1:  // ribbon windows: continuous horizontal bands
      std::snprintf(b, sizeof b,
                    "#declare W%d = function(x,y,z) { (%s > %.3f) & (%s < %.3f) & (y > %.3f) }\n",
                    i, v.c_str(), v0, v.c_str(), v1, sill);
      break;
    default:  // curtain wall: glass between thin mullions and spandrels
      std::snprintf(b, sizeof b,
                    "#declare W%d = function(x,y,z) { (mod(abs(x+z),%.3f) > 0.12) & (%s > 0.35) & "
                    "(y > %.3f) }\n",
                    i, 0.5 * P, v.c_str(), sill);
      break;
  }
  return b;
}

std::string wallPigment(Draw& d) {
  const Eigen::Vector3d c = wallColour(d);
  switch (d.kind(4, 2)) {
    case 0:
      return "granite scale " + num(d.uni(0.3, 1.5)) + " color_map { [0 " + rgb(0.8 * c) + "] [1 " +
             rgb(c) + "] }";
    case 1: {
      const double k = d.uni(0.8, 1.6);
      return "brick color " + rgb(d.uni(0.5, 0.9) * Eigen::Vector3d::Ones()) + " color " + rgb(c) +
             " brick_size <" + num(0.25 * k) + "," + num(0.08 * k) + "," + num(0.25 * k) +
             "> mortar " + num(0.012 * k);
    }
    case 2:
      return "bozo scale " + num(d.uni(0.2, 2.0)) + " color_map { [0 " + rgb(0.9 * c) + "] [1 " +
             rgb(1.05 * c) + "] }";
    case 3: {
      const Eigen::Vector3d c2 = d.chance(0.5) ? wallColour(d) : Eigen::Vector3d(0.75 * c);
      return "gradient y color_map { [0 " + rgb(c) + "] [0.5 " + rgb(c) + "] [0.5 " + rgb(c2) +
             "] [1 " + rgb(c2) + "] } scale " + num(d.uni(0.4, 3.2));
    }
    case 4: {
      const double p = d.uni(1.0, 3.0);
      return "checker color " + rgb(c) + " color " + rgb(d.uni(0.75, 0.95) * c) + " scale <" +
             num(p) + "," + num(d.uni(0.8, 3.5)) + "," + num(p) + ">";
    }
    default:
      return "marble turbulence " + num(d.uni(0.4, 1.2)) + " color_map { [0 " + rgb(c) + "] [0.7 " +
             rgb(0.9 * c) + "] [1 " + rgb(0.6 * c) + "] } scale " + num(d.uni(0.5, 3.0));
  }
}

std::string greenery(Draw& d, double scale) {
  // Summer greens mostly, autumn yellows and reds sometimes.
  const double h = d.chance(0.8) ? d.uni(70, 140) : d.uni(15, 60);
  const Eigen::Vector3d c = hsv(h, d.uni(0.45, 0.85), d.uni(0.2, 0.45));
  return "pigment { granite scale " + num(scale) + " color_map { [0 " + rgb(0.35 * c) + "] [0.6 " +
         rgb(0.75 * c) + "] [1 " + rgb(c) + "] } } normal { bumps " + num(d.uni(0.4, 1.0)) +
         " scale " + num(0.7 * scale) + " }";
}

std::string materials(Draw& d, double fog_level, const Eigen::Vector3d& sky_tint) {
  std::string m;
  for (int i = 0; i < kStyleFacades; ++i) {
    m += windowFunction(d, i);
    const Eigen::Vector3d glass =
        d.uni(0.05, 0.3) * Eigen::Vector3d(d.uni(0.8, 1.0), d.uni(0.9, 1.05), d.uni(1.0, 1.3));
    m += "#declare F" + std::to_string(i) + " = texture { pigment { function { W" +
         std::to_string(i) + "(x,y,z) } pigment_map { [0 " + wallPigment(d) + "] [1 " + rgb(glass) +
         "] } } }\n";
  }
  const double a = d.uni(0.08, 0.3);
  const Eigen::Vector3d road = a * Eigen::Vector3d(1.0, d.uni(0.95, 1.05), d.uni(0.95, 1.1));
  if (d.kind(1, 1) == 0) {
    m += "#declare T_asphalt = texture { pigment { granite scale " + num(d.uni(0.08, 0.4)) +
         " color_map { [0 " + rgb(0.6 * road) + "] [0.5 " + rgb(road) + "] [1 " + rgb(1.35 * road) +
         "] } } normal { granite " + num(d.uni(0.05, 0.25)) + " scale 0.03 } }\n";
  } else {  // concrete slabs
    const Eigen::Vector3d slab = d.uni(0.3, 0.55) * Eigen::Vector3d::Ones();
    m += "#declare T_asphalt = texture { pigment { brick color " + rgb(0.55 * slab) + " color " +
         rgb(slab) + " brick_size <" + num(d.uni(3, 6)) + ",1," + num(d.uni(2.5, 4)) +
         "> mortar 0.04 } }\n";
  }
  const Eigen::Vector3d pave = wallColour(d), pave2 = d.uni(0.3, 0.6) * Eigen::Vector3d::Ones();
  if (d.kind(1, 1) == 0) {
    const double k = d.uni(0.6, 1.6);
    m += "#declare T_sidewalk = texture { pigment { brick color " + rgb(0.75 * pave) + " color " +
         rgb(pave) + " brick_size <" + num(0.6 * k) + ",0.3," + num(0.3 * k) +
         "> mortar 0.02 } }\n";
    m += "#declare T_sidewalk2 = texture { pigment { granite scale 0.4 color_map { [0 " +
         rgb(0.85 * pave2) + "] [1 " + rgb(1.1 * pave2) + "] } } }\n";
  } else {  // hexagon tiles
    for (const char* name : {"T_sidewalk", "T_sidewalk2"}) {
      m += std::string("#declare ") + name + " = texture { pigment { hexagon color " + rgb(pave) +
           " color " + rgb(0.8 * pave) + " color " + rgb(pave2) + " scale " +
           num(d.uni(0.15, 0.4)) + " } }\n";
    }
  }
  const Eigen::Vector3d mark =
      d.chance(0.7) ? Eigen::Vector3d::Constant(d.uni(0.6, 0.9)) : Eigen::Vector3d(0.8, 0.62, 0.1);
  m += "#declare T_mark = texture { pigment { " + rgb(mark) + " } }\n";
  m += "#declare T_pole = texture { pigment { " +
       rgb(hsv(d.uni(0, 360), d.uni(0, 0.4), d.uni(0.05, 0.4))) + " } }\n";
  m += "#declare T_trunk = texture { pigment { " +
       rgb(hsv(d.uni(20, 40), d.uni(0.3, 0.6), d.uni(0.12, 0.35))) + " } }\n";
  m += "#declare T_crown = texture { " + greenery(d, d.uni(0.2, 0.5)) + " }\n";
  m += "#declare T_hedge = texture { " + greenery(d, d.uni(0.1, 0.25)) + " }\n";
  m += "#declare T_glass = texture { pigment { " +
       rgb(d.uni(0.03, 0.2) * Eigen::Vector3d(0.9, 1.0, 1.2)) + " } }\n";
  m += "#declare T_tyre = texture { pigment { rgb 0.03 } }\n";
  m += "#declare T_clutter = texture { pigment { " +
       rgb(hsv(d.uni(0, 360), d.uni(0, 0.7), d.uni(0.1, 0.6))) + " } }\n";
  for (int i = 0; i < kStyleCars; ++i) {
    const Eigen::Vector3d paint = hsv(d.uni(0, 360), d.uni(0, 0.9), d.uni(0.05, 0.85));
    m += "#declare T_car" + std::to_string(i) + " = texture { pigment { " + rgb(paint) +
         " } finish { specular " + num(d.uni(0.1, 0.6)) + " } }\n";
  }
  // Haze: exponential fog toward the horizon sky's level (about twice a sunlit albedo-0.25
  // patch after the auto-exposure), in half of the looks.
  if (fog_level > 0.0) {
    m += "fog { fog_type 1 distance " + num(d.uni(150, 1500)) + " color " +
         rgb(fog_level * sky_tint.cwiseProduct(Eigen::Vector3d(0.92, 0.96, 1.0))) + " }\n";
  }
  return m;
}

}  // namespace

Status StyleOptions::validate() const {
  if (set != "train" && set != "heldout")
    return invalidArgument("style.set: '" + set + "' is not one of train, heldout");
  if (!(frames_per_look >= 0 && frames_per_look <= 100000))
    return invalidArgument("style.frames_per_look out of range [0, 100000]");
  return Status::ok();
}

DriveLook drawDriveLook(const StyleOptions& style, const CityOptions& base) {
  DriveLook out{CityLook{}, base};
  if (style.seed == 0) return out;
  Draw d(style, 0xC17ULL);
  CityLook& L = out.city_look;
  L.styled = true;
  L.tree = static_cast<CityLook::Tree>(d.kind(2, 2));
  L.car = static_cast<CityLook::Car>(d.kind(1, 1));
  L.clutter = static_cast<CityLook::Clutter>(d.kind(1, 1));
  L.hedge_probability = d.uni(0.0, 0.5);
  L.clutter_probability = d.uni(0.0, 0.6);
  CityOptions& c = out.city;
  c.min_height_m = d.uni(4.0, 12.0);
  c.max_height_m = c.min_height_m + d.uni(4.0, 40.0);
  c.street_width_m = d.uni(9.0, 22.0);
  c.tree_probability = d.uni(0.1, 0.8);
  c.parked_car_probability = d.uni(0.1, 0.7);
  return out;
}

FrameLook drawFrameLook(const StyleOptions& style, int period, const SkyOptions& base_sky,
                        const SensorOptions& base_sensor) {
  FrameLook f;
  f.sky = base_sky;
  f.sensor = base_sensor;
  if (style.seed == 0) return f;
  Draw d(style, 0x100000ULL + static_cast<std::uint64_t>(period));
  f.sky.turbidity = d.uni(2.0, 6.5);
  f.sun_tint = {1.0, d.uni(0.9, 1.05), d.uni(0.8, 1.05)};
  f.sky_tint = {d.uni(0.85, 1.05), 1.0, d.uni(0.9, 1.15)};
  f.ambient_scale = d.uni(0.6, 1.3);
  SensorOptions& s = f.sensor;
  static const char* kResponses[] = {"srgb", "gamma", "scurve", "filmic"};
  s.response = kResponses[d.kind(3, 1)];
  s.gamma = d.uni(1.6, 2.6);
  s.contrast = d.uni(0.1, 0.7);
  s.white_balance_r = d.uni(0.75, 1.3);
  s.white_balance_b = d.uni(0.75, 1.3);
  s.exposure_target = d.uni(0.18, 0.5);
  s.vignetting = d.uni(0.0, 0.6);
  s.full_well_e = d.uni(2000, 20000);
  s.read_noise_e = d.uni(2, 30);
  s.motion_blur_px = d.chance(0.5) ? 0.0 : d.uni(1.0, 3.0);
  s.defocus_sigma_px = d.chance(0.5) ? 0.0 : d.uni(0.3, 1.2);
  const double sky_draw = d.uni(0, 1);
  if (sky_draw < 0.2) {
    f.sky_kind = FrameLook::Sky::kAzimuthFree;
  } else if (sky_draw < 0.4) {
    f.sky_kind = FrameLook::Sky::kClouds;
    f.cloud_cover = d.uni(0.15, 0.7);
    f.cloud_seed = static_cast<std::uint64_t>(d.uni(0, 1) * 4294967296.0);
  }
  if (d.chance(0.7)) {
    f.glow_level = d.uni(0.5, 4.0);
    f.glow_width_deg = d.uni(1.5, 8.0);
  }
  const double fog_level = d.chance(0.5) ? s.exposure_target * d.uni(1.5, 3.0) : 0.0;
  f.materials = materials(d, fog_level, f.sky_tint);
  return f;
}

void styleSky(cv::Mat& sky_bgr, const FrameLook& look) {
  if (look.sky_kind == FrameLook::Sky::kAzimuthFree) {
    for (int i = 0; i < sky_bgr.rows; ++i) {
      const cv::Scalar m = cv::mean(sky_bgr.row(i));
      sky_bgr.row(i).setTo(m);
    }
  } else if (look.sky_kind == FrameLook::Sky::kClouds) {
    // Smooth noise: a coarse uniform random grid, bicubically enlarged; cloud where it falls
    // below the cover quantile, with soft edges.
    cv::Mat coarse(8, 16, CV_32F);
    cv::RNG rng(look.cloud_seed);
    rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat field;
    cv::resize(coarse, field, sky_bgr.size(), 0, 0, cv::INTER_CUBIC);
    const cv::Scalar mean = cv::mean(sky_bgr(cv::Rect(0, 0, sky_bgr.cols, sky_bgr.rows / 2)));
    const float grey = static_cast<float>(0.9 * (mean[0] + mean[1] + mean[2]) / 3.0);
    const float cover = static_cast<float>(look.cloud_cover);
    for (int i = 0; i < sky_bgr.rows / 2; ++i)
      for (int j = 0; j < sky_bgr.cols; ++j) {
        const float a = std::clamp((cover - field.at<float>(i, j)) / 0.1f + 0.5f, 0.0f, 1.0f);
        cv::Vec3f& p = sky_bgr.at<cv::Vec3f>(i, j);
        for (int c = 0; c < 3; ++c) p[c] = (1.0f - a) * p[c] + a * grey;
      }
  }
}

void addSunGlow(cv::Mat& sky_bgr, const Eigen::Vector3d& sun_enu, const FrameLook& look,
                double exposure_target) {
  if (look.glow_level <= 0.0 || sun_enu.z() <= 0.0) return;
  constexpr double kPi = 3.14159265358979323846;
  const Eigen::Vector3d s = sun_enu.normalized();
  const int H = sky_bgr.rows, W = sky_bgr.cols;
  const double pixel_rad = 2.0 * kPi / W, width_rad = look.glow_width_deg * kPi / 180.0;
  for (int i = 0; i < H / 2; ++i) {  // the upper half: elevation >= 0
    const double el = 0.5 * kPi - kPi * (i + 0.5) / H;
    for (int j = 0; j < W; ++j) {
      const double th = 2.0 * kPi * (j + 0.5) / W;
      const Eigen::Vector3d d(std::cos(el) * std::cos(th), std::cos(el) * std::sin(th),
                              std::sin(el));
      const double ang = std::acos(std::clamp(d.dot(s), -1.0, 1.0));
      // The disc (0.27 deg radius) fills less than a pixel: the pixel nearest the sun is set
      // far above saturation, its neighbours follow the aureole.
      double v = exposure_target * look.glow_level * std::exp(-ang / width_rad);
      if (ang < 0.75 * pixel_rad) v += 50.0 * exposure_target;
      cv::Vec3f& p = sky_bgr.at<cv::Vec3f>(i, j);
      for (int c = 0; c < 3; ++c) p[c] += static_cast<float>(v);
    }
  }
}

}  // namespace sunvo::render
