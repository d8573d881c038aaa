#pragma once
// Domain randomisation of rendered drives ("styles"). A style draws, from a seed, the look of a
// drive: facade materials and colours, window layouts, road and sidewalk surfaces, vegetation
// (tree shapes, hedges), parked-car shapes and paints, street clutter, building heights and
// street widths, sky turbidity, ground albedo (ambient level), sun and sky colour, haze, and
// the camera: response curve, white balance, exposure, vignetting, noise, motion and defocus
// blur. An image estimator trained on many styles sees one geometry of sun and shadow under
// many looks, so it cannot lean on the renderer's one look.
//
// Two sets of looks. Every categorical choice has kinds that only the held-out set draws:
//   facade material   train: two-tone granite, brick, plaster (bozo), horizontal bands
//                     held-out: large panels (checker), veined stone (marble)
//   windows           train: punched grid (random period and size)
//                     held-out: ribbon windows (horizontal bands), curtain-wall mullions
//   road / sidewalk   train: asphalt (granite grain) / pavers, granite slabs
//                     held-out: concrete slabs / hexagon tiles
//   trees             train: sphere, ellipsoid crowns      held-out: cones, three-sphere clusters
//   parked cars       train: sedans                        held-out: vans
//   clutter           train: bins                          held-out: bollards and benches
//   response curve    train: srgb, gamma, scurve           held-out: filmic
// Continuous draws (colours, heights, noise, exposure, haze, ...) share their ranges. A model
// validated on "heldout" is therefore validated on looks it never saw in training.
//
// Geometry (CityLook, city sizes) is drawn once per drive; materials, light and camera
// (FrameLook) every style.frames_per_look frames, so one drive shows many looks.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/render/perez_sky.hpp"
#include "sunvo/render/scene.hpp"
#include "sunvo/render/sensor.hpp"

namespace sunvo::render {

struct StyleOptions {
  std::uint64_t seed = 0;     // 0 = the classic fixed look (no randomisation); else the seed
  std::string set = "train";  // train | heldout: which kinds of each choice may be drawn
  int frames_per_look = 0;    // a new FrameLook every N frames, [0, 100000]; 0 = one per drive
  Status validate() const;    // names the key ("style.set ...")
};

// The look of the frames of one look period.
struct FrameLook {
  std::string materials;  // POV text: #declare of every texture CityLook names, and the fog
  SkyOptions sky;         // turbidity
  SensorOptions sensor;   // response curve, white balance, exposure, noise, blur
  Eigen::Vector3d sun_tint = Eigen::Vector3d::Ones();  // multiplies the sun's colour (R, G, B)
  Eigen::Vector3d sky_tint = Eigen::Vector3d::Ones();  // multiplies sky image and ambient
  double ambient_scale = 1.0;  // ground albedo: scales the ambient (sky + bounce) light
  // The sun seen in the sky image: a saturating disc and an aureole (forward scattering and
  // lens glare), level relative to the exposure target, exp(-angle / width) fall-off.
  double glow_level = 0.0;  // 0 = no disc, no aureole
  double glow_width_deg = 3.0;
  // The sky image: the Perez sky as computed, or an azimuth-free one (each row its mean: the
  // sky's brightness then says nothing of the sun's azimuth), or the Perez sky under clouds.
  enum class Sky { kPerez, kAzimuthFree, kClouds } sky_kind = Sky::kPerez;
  double cloud_cover = 0.0;      // kClouds: share of the sky under cloud, [0, 1]
  std::uint64_t cloud_seed = 0;  // kClouds: the cloud pattern
};

// The drive's geometry look and its city sizes (heights, street width) for style seed.
// With seed 0 returns the classic look and `base` unchanged.
struct DriveLook {
  CityLook city_look;
  CityOptions city;
};
DriveLook drawDriveLook(const StyleOptions& style, const CityOptions& base);

// The look of look period `period` (frame / frames_per_look). With seed 0: empty materials,
// the base sky and sensor and unit tints. Deterministic for (seed, set, period).
FrameLook drawFrameLook(const StyleOptions& style, int period, const SkyOptions& base_sky,
                        const SensorOptions& base_sensor);

// Applies the look's sky kind to an equirectangular sky image (BGR, CV_32FC3): azimuth-free
// rows or clouds (grey, about as bright as the sky's mean, smooth random shapes).
void styleSky(cv::Mat& sky_bgr, const FrameLook& look);

// Adds the look's sun disc and aureole to an equirectangular sky image (BGR, CV_32FC3, the
// layout of PerezSky::equirectangular) for the sun direction sun_enu; `exposure_target` is
// the linear level of a sunlit albedo-0.25 patch. No-op when look.glow_level is 0.
void addSunGlow(cv::Mat& sky_bgr, const Eigen::Vector3d& sun_enu, const FrameLook& look,
                double exposure_target);

}  // namespace sunvo::render
