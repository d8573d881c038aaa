// LalondeOptions::validate(): every field against the range its comment gives.
#include <string>

#include "sunvo/sunvision/lalonde_estimator.hpp"

namespace sunvo::sunvision {
namespace {
Status outOfRange(const char* key, const char* range) {
  return invalidArgument(std::string("lalonde.") + key + " out of range " + range);
}

bool inRange(double v, double lo, double hi) {
  return v >= lo && v <= hi;
}
}  // namespace

Status LalondeOptions::validate() const {
  if (!inRange(azimuth_step_deg, 1.0, 15.0)) return outOfRange("azimuth_step_deg", "[1, 15]");
  if (!inRange(zenith_step_deg, 1.0, 15.0)) return outOfRange("zenith_step_deg", "[1, 15]");
  if (work_width_px < 160 || work_width_px > 4096) {
    return outOfRange("work_width_px", "[160, 4096]");
  }
  if (!inRange(sky_turbidity, 1.7, 10.0)) return outOfRange("sky_turbidity", "[1.7, 10]");
  if (!inRange(sky_min_gray, 0.0, 255.0)) return outOfRange("sky_min_gray", "[0, 255]");
  if (!inRange(sky_max_gradient, 0.5, 255.0)) return outOfRange("sky_max_gradient", "[0.5, 255]");
  if (!inRange(sky_min_relative_gray, 0.0, 1.0)) {
    return outOfRange("sky_min_relative_gray", "[0, 1]");
  }
  if (sky_texture_window_px < 0 || sky_texture_window_px > 64) {
    return outOfRange("sky_texture_window_px", "[0, 64]");
  }
  if (!inRange(sky_max_window_gradient, 0.1, 255.0)) {
    return outOfRange("sky_max_window_gradient", "[0.1, 255]");
  }
  if (!inRange(sky_max_red_over_blue, 0.5, 5.0)) {
    return outOfRange("sky_max_red_over_blue", "[0.5, 5]");
  }
  if (!inRange(sky_saturated_gray, 128.0, 255.0)) {
    return outOfRange("sky_saturated_gray", "[128, 255]");
  }
  if (sky_min_pixels < 10 || sky_min_pixels > 100000) {
    return outOfRange("sky_min_pixels", "[10, 100000]");
  }
  if (sky_max_fit_pixels < 50 || sky_max_fit_pixels > 100000) {
    return outOfRange("sky_max_fit_pixels", "[50, 100000]");
  }
  if (!(sky_residual_sigma > 0.0 && sky_residual_sigma <= 1.0)) {
    return outOfRange("sky_residual_sigma", "(0, 1]");
  }
  if (!inRange(camera_height_m, 0.2, 20.0)) return outOfRange("camera_height_m", "[0.2, 20]");
  if (!inRange(canny_low, 1.0, 1000.0)) return outOfRange("canny_low", "[1, 1000]");
  if (!inRange(canny_high, canny_low, 1000.0)) {
    return outOfRange("canny_high", "[canny_low, 1000]");
  }
  if (hough_threshold < 5 || hough_threshold > 1000) {
    return outOfRange("hough_threshold", "[5, 1000]");
  }
  if (!inRange(min_line_length_px, 5.0, 1000.0)) {
    return outOfRange("min_line_length_px", "[5, 1000]");
  }
  if (!inRange(max_ground_distance_m, 2.0, 200.0)) {
    return outOfRange("max_ground_distance_m", "[2, 200]");
  }
  if (!(min_shadow_contrast >= 0.0 && min_shadow_contrast < 1.0)) {
    return outOfRange("min_shadow_contrast", "[0, 1)");
  }
  if (!inRange(shadow_sigma_deg, 1.0, 45.0)) return outOfRange("shadow_sigma_deg", "[1, 45]");
  if (!(shadow_floor >= 0.01 && shadow_floor < 1.0)) {
    return outOfRange("shadow_floor", "[0.01, 1)");
  }
  if (!(min_shadow_weight > 0.0 && min_shadow_weight <= 1e6)) {
    return outOfRange("min_shadow_weight", "(0, 1e6]");
  }
  if (!inRange(along_track_deg, 0.0, 90.0)) return outOfRange("along_track_deg", "[0, 90]");
  if (!inRange(along_track_weight, 0.0, 1.0)) return outOfRange("along_track_weight", "[0, 1]");
  if (!(max_line_weight > 0.0 && max_line_weight <= 1000.0)) {
    return outOfRange("max_line_weight", "(0, 1000]");
  }
  if (!(wall_side_fraction > 0.0 && wall_side_fraction <= 0.5)) {
    return outOfRange("wall_side_fraction", "(0, 0.5]");
  }
  if (!inRange(wall_min_elevation_deg, 0.0, 45.0)) {
    return outOfRange("wall_min_elevation_deg", "[0, 45]");
  }
  if (!(wall_min_share > 0.0 && wall_min_share <= 1.0)) {
    return outOfRange("wall_min_share", "(0, 1]");
  }
  if (!(wall_log_ratio_scale > 0.0 && wall_log_ratio_scale <= 10.0)) {
    return outOfRange("wall_log_ratio_scale", "(0, 10]");
  }
  if (!(wall_max_weight >= 0.0 && wall_max_weight < 1.0)) {
    return outOfRange("wall_max_weight", "[0, 1)");
  }
  if (!(wall_side_band > 0.0 && wall_side_band <= 1.0)) {
    return outOfRange("wall_side_band", "(0, 1]");
  }
  if (!inRange(zenith_prior_mean_deg, 0.0, 90.0)) {
    return outOfRange("zenith_prior_mean_deg", "[0, 90]");
  }
  if (!(zenith_prior_sigma_deg > 0.0 && zenith_prior_sigma_deg <= 180.0)) {
    return outOfRange("zenith_prior_sigma_deg", "(0, 180]");
  }
  if (!(vo_sigma_azimuth_deg > 0.0 && vo_sigma_azimuth_deg <= 360.0)) {
    return outOfRange("vo_sigma_azimuth_deg", "(0, 360]");
  }
  if (!(vo_sigma_zenith_deg > 0.0 && vo_sigma_zenith_deg <= 180.0)) {
    return outOfRange("vo_sigma_zenith_deg", "(0, 180]");
  }
  if (!(min_sigma > 0.0 && min_sigma <= 2.0)) return outOfRange("min_sigma", "(0, 2]");
  if (!inRange(max_sigma, min_sigma, 2.0)) return outOfRange("max_sigma", "[min_sigma, 2]");
  if (!(confidence_radius_deg > 0.0 && confidence_radius_deg <= 180.0)) {
    return outOfRange("confidence_radius_deg", "(0, 180]");
  }
  return Status::ok();
}

}  // namespace sunvo::sunvision
