#pragma once
// Lalonde and Lalonde-VO: the sun direction from one outdoor colour image by weak cues combined
// over a grid of candidate sun positions (after J.-F. Lalonde, A. Efros, S. Narasimhan,
// "Estimating the natural illumination conditions from a single outdoor image", IJCV 2012, as used
// by Clement, Peretroukhin and Kelly, ISER 2016).
//
// Grid: azimuth phi x zenith theta in the horizon frame (sky_model.hpp); every cell gets a log
// likelihood per cue, the cues are added (independent evidence) and the best cell is the
// estimate:
//  - sky cue: the sky is segmented (above the horizon, bright, texture-free, bluish or neutral,
//    connected to the image top); a Perez clear-sky luminance G(theta_p) S(gamma_p) times an
//    unknown exposure k is fitted to the linearised sky pixels for each candidate sun, and the
//    relative residual r = sum (L - k m)^2 / sum L^2 gives log p = -r / (2 sigma_r^2), mixed
//    with a uniform chance that the fit misleads (horizon haze, bright facades);
//  - shadow cue: strong dark-to-bright edges on the ground (Canny + probabilistic Hough, both
//    sides on the ground, darker side a shadow: much darker and not less blue), projected to the
//    ground plane with the camera height and up vector. A shadow cast by a vertical object lies
//    along the sun's azimuth, away from the sun, so each line of ground orientation alpha adds
//    the two-peaked kernel exp(kappa (cos 2(phi - alpha) - 1)) (phi = alpha or alpha + 180 deg);
//    lines along the camera's forward axis (curbs, markings) are down-weighted;
//  - wall cue (Lalonde's vertical surfaces, reduced to a street canyon): the facades in the
//    left part of the image face right (normal +right_c), those in the right part face left. A sun
//    on the right (sin phi > 0) lights the left facades and leaves the right ones in shadow, so
//    the log ratio rho = log(median linear gray, left / right) of the non-sky pixels above the
//    horizon tells the side: q = sigmoid(rho / wall_log_ratio_scale) is the chance the sun is on
//    the right, w = wall_max_weight (2 q - 1), and log p(phi, theta) = log(1 + w g) with
//    g = clamp(sin phi sin theta / wall_side_band, -1, 1) (no evidence for a sun straight ahead or
//    behind, or overhead, where both sides are lit alike; flat elsewhere on each side). The sign of
//    rho does not depend on the tone curve (medians of a monotone response); its reliability was
//    measured on the held-out renders (docs/sun_estimators.md);
//  - prior: Lalonde's zenith prior, a Gaussian over theta (from sun statistics of daytime
//    photographs), or for Lalonde-VO a Gaussian around the sun predicted from the VO pose,
//    sigma_az = 60 deg, sigma_zen = 15 deg: the paper chooses them so that the 3-sigma bounds
//    (mean +- 3 sigma) span 360 deg in azimuth and 90 deg in zenith.
// The estimate's sigma (R_s = sigma^2 I) is the posterior's RMS angle to the best cell / sqrt(2)
// (two tangent components), clamped; valid = false when neither image cue is informative.
//
// Not thread-safe (scratch buffers are members); one estimator per thread.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "sunvo/sunfusion/image_sun_estimator.hpp"
#include "sunvo/sunvision/sky_model.hpp"

namespace sunvo::sunvision {

enum class LalondePrior {
  kZenith,          // "lalonde": Gaussian over the zenith only
  kVisualOdometry,  // "lalonde_vo": Gaussian around ImageSunInput.prior->sun_c (required)
};

struct LalondeOptions {
  LalondePrior prior = LalondePrior::kZenith;
  bool use_sky = true;      // the sky cue (off: for ablation)
  bool use_shadows = true;  // the shadow cue (off: for ablation)
  bool use_walls = false;   // the wall (lit facade side) cue; off: measured not to help on val
  // Grid.
  double azimuth_step_deg = 3.0;  // deg, [1, 15]; 360 / step cells
  double zenith_step_deg = 3.0;   // deg, [1, 15]; the grid covers zenith [0, 90] deg
  // Image pyramid level the cues work on.
  int work_width_px = 640;  // px, [160, 4096]: the image is area-downscaled to this width
  // Sky cue.
  double sky_turbidity = 2.5;  // Perez/Preetham turbidity of the fitted model, [1.7, 10]
  double sky_min_gray = 90.0;  // 8-bit gray a sky pixel must reach, [0, 255]
  // ... and this share of the image's own bright level (the 99th percentile of the gray above
  // the horizon): a threshold that follows the exposure and tone curve, [0, 1]
  double sky_min_relative_gray = 0.9;
  double sky_max_gradient =
      6.0;  // gradient magnitude per px (8-bit units) above = texture, [0.5, 255]
  // R / B above = not sky (brick, sunset excluded), [0.5, 5]; measured after a grey-world white
  // balance (each channel divided by its image mean) when sky_grey_world is set
  double sky_max_red_over_blue = 1.1;
  // Mean gradient over a window (window edges of facades), work px, [0, 64]; 0/1 = off (off:
  // a wash on val, docs/sun_estimators.md)
  int sky_texture_window_px = 0;
  double sky_max_window_gradient = 3.0;  // mean gradient per px there, 8-bit units, [0.1, 255]
  bool sky_grey_world = false;
  double sky_saturated_gray = 250.0;  // pixels at or above are segmented but not fitted, [128, 255]
  int sky_min_pixels = 150;           // fitted pixels needed for the cue to count, [10, 100000]
  int sky_max_fit_pixels = 400;       // fitted pixels kept (uniform subsample), [50, 100000]
  // Fit a free vignetting too: L = k1 m + k2 m cos^4(angle off axis), so that an unknown lens
  // fall-off (which brightens the image centre like a sun ahead) cannot pose as the sun
  bool sky_fit_vignetting = false;
  double sky_residual_sigma = 0.4;  // relative RMS fit residual worth one sigma, (0, 1]
  // Chance the sky fit misleads (haze, facades, vignetting), [0.001, 1). 0.5: the sky cue alone
  // is 60-80 % gross on the held-out renders (docs/sun_estimators.md); was 0.1.
  double sky_floor = 0.5;
  double sky_min_elevation_deg = 1.0;  // sky pixels lower than this are ignored, deg, [0, 30]
  // Shadow cue.
  double camera_height_m = 1.65;        // camera above the ground plane, m, [0.2, 20] (KITTI)
  double canny_low = 40.0;              // Canny thresholds, 8-bit units, [1, 1000]
  double canny_high = 100.0;            // [canny_low, 1000]
  int hough_threshold = 25;             // accumulator votes, [5, 1000]
  double min_line_length_px = 25.0;     // at the work width, px, [5, 1000]
  double max_ground_distance_m = 30.0;  // lines farther away are ignored, m, [2, 200]
  double min_shadow_contrast = 0.4;     // 1 - dark/bright across the edge, [0, 1)
  double shadow_sigma_deg = 10.0;       // angular spread of one line's peaks, deg, [1, 45]
  // Share of uniform azimuth mixed in, [0.01, 1). 0.9: the shadow cue alone is at chance on the
  // held-out renders (axial gross 53-62 % where 50 % is chance); was 0.3.
  double shadow_floor = 0.9;
  double min_shadow_weight = 2.0;  // sum of line weights (m x contrast) to count, (0, 1e6]
  double max_line_weight = 5.0;    // cap of one line's weight, m, (0, 1000]
  // Street-aligned lines (curbs, lane markings, facade feet, roof-edge shadows) run along the
  // camera's forward direction in city driving and would pull every estimate to 0/180 deg; a
  // line within along_track_deg of forward counts with this factor. 1 = Lalonde's plain cue.
  double along_track_deg = 10.0;     // deg, [0, 90]
  double along_track_weight = 0.25;  // [0, 1]
  // Wall cue.
  double wall_side_fraction = 0.35;     // left / right share of the image width used, (0, 0.5]
  double wall_min_elevation_deg = 2.0;  // facade pixels at least this above the horizon, [0, 45]
  double wall_min_share = 0.05;         // share of each side's pixels needed to count, (0, 1]
  double wall_log_ratio_scale = 0.2;    // rho giving q = sigmoid(1) = 0.73, (0, 10]
  double wall_max_weight = 0.25;        // |w| at most (the cue's reliability), [0, 1)
  double wall_side_band = 0.25;         // sin phi sin theta beyond which a side is flat, (0, 1]
  // Priors.
  double zenith_prior_mean_deg = 50.0;   // Lalonde prior, deg, [0, 90]
  double zenith_prior_sigma_deg = 20.0;  // deg, (0, 180]
  double vo_sigma_azimuth_deg = 60.0;    // Lalonde-VO, deg, (0, 360]
  double vo_sigma_zenith_deg = 15.0;     // deg, (0, 180]
  // Output.
  double min_sigma = 0.03;              // floor of SunMeasurement.sigma, (0, 2]
  double max_sigma = 1.0;               // ceiling, [min_sigma, 2]
  double confidence_radius_deg = 20.0;  // posterior mass within this of the best cell, (0, 180]

  Status validate() const;
};

// One accepted shadow line, for the debug output.
struct ShadowLine {
  Eigen::Vector2f p0_px = Eigen::Vector2f::Zero(), p1_px = Eigen::Vector2f::Zero();  // full res
  double ground_azimuth_rad = 0.0;  // orientation on the ground (mod pi), horizon frame
  double weight = 0.0;
};

// What the last call saw: per-cue log likelihoods on the grid (rows = zenith bins from 0,
// cols = azimuth bins from -180 deg; CV_64F; 0 everywhere for a cue that was not informative),
// the sky mask at the work resolution and the accepted shadow lines.
struct LalondeCues {
  cv::Mat sky_loglik, shadow_loglik, wall_loglik, prior_loglik,
      posterior;     // posterior: probabilities, sum 1
  cv::Mat sky_mask;  // CV_8U, 255 = sky
  std::vector<ShadowLine> shadow_lines;
  int sky_pixels_segmented = 0;  // at the work resolution
  int sky_pixels_fitted = 0;
  double shadow_weight = 0.0;
  double wall_log_ratio = 0.0;  // rho, log(left / right); > 0: the sun on the right
  bool sky_informative = false, shadow_informative = false, wall_informative = false;
  HorizonFrame horizon;
  int best_row = 0, best_col = 0;
};

class LalondeEstimator final : public sunfusion::ImageSunEstimator {
 public:
  explicit LalondeEstimator(const LalondeOptions& options = {});

  // Validates the options and allocates the grid. Must succeed before estimate().
  Status init();

  const char* name() const override;
  bool acceptsGray() const override { return true; }  // the colour tests are skipped
  Expected<sunfusion::ImageSunEstimate> estimate(const sunfusion::ImageSunInput& input) override;

  const LalondeOptions& options() const { return options_; }
  // Cue maps of the last successful estimate() call.
  const LalondeCues& lastCues() const { return cues_; }

  // Grid geometry.
  int azimuthBins() const { return n_az_; }
  int zenithBins() const { return n_zen_; }
  double azimuthOfColRad(int col) const;
  double zenithOfRowRad(int row) const;

 private:
  void skyCue(const cv::Mat& work_bgr, const cv::Mat& work_gray, bool colour, double scale);
  void shadowCue(const cv::Mat& work_bgr, const cv::Mat& work_gray, bool colour, double scale);
  void wallCue(const cv::Mat& work_gray, double scale);  // lalonde_walls.cpp
  void priorCue(const sunfusion::ImageSunInput& input);
  Eigen::Vector3d rayAt(double u_full, double v_full) const;

  LalondeOptions options_;
  bool initialised_ = false;
  int n_az_ = 0, n_zen_ = 0;
  StereoCamera camera_;
  PerezParameters perez_;
  ScatteringTable scattering_;
  LalondeCues cues_;
  // Scratch, reused between calls.
  cv::Mat work_bgr_, work_gray_, gradient_x_, gradient_y_, blurred_, edges_, ground_mask_, labels_;
  std::vector<cv::Vec4i> hough_lines_;
  std::vector<Eigen::Vector3d> sky_rays_;
  std::vector<double> sky_luminance_, sky_gradation_, sky_cos4_;
  std::vector<Eigen::Vector3d> cell_directions_;
  std::vector<double> shadow_azimuth_;
  std::vector<unsigned char> top_labels_;
  std::vector<float> wall_left_, wall_right_;
};

}  // namespace sunvo::sunvision
