#include "sunvo/sunvision/lalonde_estimator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "sunvo/core/geometry.hpp"

namespace sunvo::sunvision {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// sRGB 8-bit -> linear [0, 1] (IEC 61966-2-1): the sky fit is done in linear light.
double srgbToLinear(double v8) {
  const double v = v8 / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// Mean of the gray image over the points p + offset * n, t in [0.15, 0.85] along the segment.
double sideMean(const cv::Mat& gray, const cv::Point2d& a, const cv::Point2d& b,
                const cv::Point2d& n, double offset, const cv::Mat& mask, bool* inside) {
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < 8; ++i) {
    const double t = 0.15 + 0.7 * i / 7.0;
    const cv::Point2d p = a + (b - a) * t + n * offset;
    const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
    if (x < 0 || y < 0 || x >= gray.cols || y >= gray.rows || mask.at<unsigned char>(y, x) == 0) {
      *inside = false;
      return 0.0;
    }
    sum += gray.at<unsigned char>(y, x);
    ++count;
  }
  return sum / count;
}

// Blue share b / (r + g + b) of the colour image around the same points.
double sideBlueShare(const cv::Mat& bgr, const cv::Point2d& a, const cv::Point2d& b,
                     const cv::Point2d& n, double offset) {
  double blue = 0.0, total = 0.0;
  for (int i = 0; i < 8; ++i) {
    const double t = 0.15 + 0.7 * i / 7.0;
    const cv::Point2d p = a + (b - a) * t + n * offset;
    const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, bgr.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, bgr.rows - 1);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
    blue += c[0];
    total += c[0] + c[1] + c[2];
  }
  return total > 0.0 ? blue / total : 1.0 / 3.0;
}
}  // namespace

LalondeEstimator::LalondeEstimator(const LalondeOptions& options) : options_(options) {}

const char* LalondeEstimator::name() const {
  return options_.prior == LalondePrior::kVisualOdometry ? "lalonde_vo" : "lalonde";
}

Status LalondeEstimator::init() {
  SUNVO_RETURN_IF_ERROR(options_.validate());
  n_az_ = static_cast<int>(std::lround(360.0 / options_.azimuth_step_deg));
  n_zen_ = static_cast<int>(std::lround(90.0 / options_.zenith_step_deg));
  perez_ = clearSkyLuminanceParameters(options_.sky_turbidity);
  scattering_.build(perez_);
  for (cv::Mat* m : {&cues_.sky_loglik, &cues_.shadow_loglik, &cues_.wall_loglik,
                     &cues_.prior_loglik, &cues_.posterior}) {
    m->create(n_zen_, n_az_, CV_64F);
    m->setTo(0.0);
  }
  cell_directions_.resize(static_cast<std::size_t>(n_az_ * n_zen_));
  shadow_azimuth_.resize(static_cast<std::size_t>(n_az_));
  sky_rays_.reserve(static_cast<std::size_t>(options_.sky_max_fit_pixels) + 1);
  sky_luminance_.reserve(sky_rays_.capacity());
  sky_gradation_.reserve(sky_rays_.capacity());
  hough_lines_.reserve(4096);
  cues_.shadow_lines.reserve(4096);
  initialised_ = true;
  return Status::ok();
}

double LalondeEstimator::azimuthOfColRad(int col) const {
  return (-180.0 + (col + 0.5) * 360.0 / n_az_) * kDeg;
}

double LalondeEstimator::zenithOfRowRad(int row) const {
  return ((row + 0.5) * 90.0 / n_zen_) * kDeg;
}

Eigen::Vector3d LalondeEstimator::rayAt(double u_full, double v_full) const {
  return Eigen::Vector3d((u_full - camera_.cu) / camera_.fu, (v_full - camera_.cv) / camera_.fv,
                         1.0)
      .normalized();
}

Expected<sunfusion::ImageSunEstimate> LalondeEstimator::estimate(
    const sunfusion::ImageSunInput& input) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!initialised_) return failedPrecondition(std::string(name()) + ": init() not called");
  if (input.color.empty() || (input.color.type() != CV_8UC3 && input.color.type() != CV_8UC1)) {
    return invalidArgument(std::string(name()) + ": image must be CV_8UC3 (BGR) or CV_8UC1");
  }
  // Only the intrinsics matter here (a mono camera may carry no baseline).
  const StereoCamera& cam = input.camera;
  if (!(cam.fu > 0.0 && cam.fv > 0.0 && std::isfinite(cam.fu) && std::isfinite(cam.fv) &&
        std::isfinite(cam.cu) && std::isfinite(cam.cv))) {
    return invalidArgument(std::string(name()) + ": camera fu, fv must be finite and > 0 px");
  }
  if (input.camera.width != input.color.cols || input.camera.height != input.color.rows) {
    return invalidArgument(std::string(name()) + ": image size " +
                           std::to_string(input.color.cols) + "x" +
                           std::to_string(input.color.rows) + " differs from camera.width/height");
  }
  if (options_.prior == LalondePrior::kVisualOdometry &&
      (!input.prior || !input.prior->sun_c.allFinite() || input.prior->sun_c.norm() < 1e-9)) {
    return invalidArgument("lalonde_vo: ImageSunInput.prior with a finite sun_c is required");
  }
  const Eigen::Vector3d up_c = input.prior ? input.prior->up_c : Eigen::Vector3d(0.0, -1.0, 0.0);
  Expected<HorizonFrame> horizon = HorizonFrame::fromUp(up_c);
  if (!horizon) return horizon.status();
  cues_.horizon = *horizon;
  camera_ = input.camera;

  // Work image: area-downscaled; a gray input (KITTI's cameras 0/1) has no colour cues.
  const bool colour = input.color.type() == CV_8UC3;
  const int work_w = std::min(options_.work_width_px, input.color.cols);
  const int work_h =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(input.color.rows) * work_w /
                                               input.color.cols)));
  const double scale = static_cast<double>(input.color.cols) / work_w;  // full px per work px
  if (colour) {
    cv::resize(input.color, work_bgr_, cv::Size(work_w, work_h), 0, 0, cv::INTER_AREA);
    cv::cvtColor(work_bgr_, work_gray_, cv::COLOR_BGR2GRAY);
  } else {
    cv::resize(input.color, work_gray_, cv::Size(work_w, work_h), 0, 0, cv::INTER_AREA);
    cv::cvtColor(work_gray_, work_bgr_, cv::COLOR_GRAY2BGR);
  }

  // Candidate sun directions for every cell.
  for (int r = 0; r < n_zen_; ++r) {
    for (int c = 0; c < n_az_; ++c) {
      cell_directions_[static_cast<std::size_t>(r * n_az_ + c)] =
          cues_.horizon.direction(azimuthOfColRad(c), zenithOfRowRad(r));
    }
  }

  skyCue(work_bgr_, work_gray_, colour, scale);
  if (!options_.use_sky) {
    cues_.sky_loglik.setTo(0.0);
    cues_.sky_informative = false;
  }
  shadowCue(work_bgr_, work_gray_, colour, scale);
  if (!options_.use_shadows) {
    cues_.shadow_loglik.setTo(0.0);
    cues_.shadow_informative = false;
    cues_.shadow_lines.clear();
  }
  wallCue(work_gray_, scale);
  if (!options_.use_walls) {
    cues_.wall_loglik.setTo(0.0);
    cues_.wall_informative = false;
  }
  priorCue(input);

  // Posterior: sum of the log likelihoods, exponentiated relative to its maximum.
  cv::Mat& post = cues_.posterior;
  cv::add(cues_.sky_loglik, cues_.shadow_loglik, post);
  cv::add(post, cues_.wall_loglik, post);
  cv::add(post, cues_.prior_loglik, post);
  double max_log = 0.0;
  cv::Point best;
  cv::minMaxLoc(post, nullptr, &max_log, nullptr, &best);
  cv::subtract(post, cv::Scalar(max_log), post);
  cv::exp(post, post);
  const double total = cv::sum(post)[0];
  post /= total;
  cues_.best_row = best.y;
  cues_.best_col = best.x;

  const Eigen::Vector3d sun_c = cell_directions_[static_cast<std::size_t>(best.y * n_az_ + best.x)];
  double spread2 = 0.0, near_mass = 0.0;
  for (int r = 0; r < n_zen_; ++r) {
    const double* p = post.ptr<double>(r);
    for (int c = 0; c < n_az_; ++c) {
      const double a =
          angleBetween(cell_directions_[static_cast<std::size_t>(r * n_az_ + c)], sun_c);
      spread2 += p[c] * a * a;
      if (a <= options_.confidence_radius_deg * kDeg) near_mass += p[c];
    }
  }

  sunfusion::ImageSunEstimate out;
  out.valid = cues_.sky_informative || cues_.shadow_informative || cues_.wall_informative;
  out.measurement.kind = sunfusion::SunMeasurementKind::kFull3d;
  out.measurement.sun_c = sun_c;
  out.measurement.sigma =
      std::clamp(std::sqrt(spread2 / 2.0), options_.min_sigma, options_.max_sigma);
  out.azimuth_deg = std::atan2(sun_c.x(), sun_c.z()) / kDeg;
  out.zenith_deg = cues_.horizon.zenithRad(sun_c) / kDeg;
  out.confidence = std::clamp(near_mass, 0.0, 1.0);
  out.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void LalondeEstimator::skyCue(const cv::Mat& work_bgr, const cv::Mat& work_gray, bool colour,
                              double scale) {
  cues_.sky_loglik.setTo(0.0);
  cues_.sky_informative = false;
  cues_.sky_pixels_fitted = 0;
  cues_.sky_pixels_segmented = 0;
  const int w = work_gray.cols, h = work_gray.rows;

  // Texture: gradient magnitude per pixel. The 3x3 Sobel response is 8x the per-pixel slope
  // (central difference over 2 px, smoothing weights 1-2-1), hence the scale 1/8.
  cv::Sobel(work_gray, gradient_x_, CV_32F, 1, 0, 3, 0.125);
  cv::Sobel(work_gray, gradient_y_, CV_32F, 0, 1, 3, 0.125);
  cues_.sky_mask.create(h, w, CV_8U);
  cues_.sky_mask.setTo(0);
  const double min_up = std::sin(options_.sky_min_elevation_deg * kDeg);
  // The image's own levels: grey-world channel means (white balance) and the 99th percentile of
  // the gray above the horizon (exposure and tone curve).
  double red_gain = 1.0;  // multiplies R / B
  if (colour && options_.sky_grey_world) {
    const cv::Scalar mean_bgr = cv::mean(work_bgr);
    red_gain = std::max(mean_bgr[0], 1.0) / std::max(mean_bgr[2], 1.0);
  }
  double min_gray = options_.sky_min_gray;
  if (options_.sky_min_relative_gray > 0.0) {
    std::array<int, 256> hist{};
    int n_above = 0;
    for (int y = 0; y < h; ++y) {
      const unsigned char* g = work_gray.ptr<unsigned char>(y);
      const Eigen::Vector3d d = rayAt((0.5 * w) * scale - 0.5, (y + 0.5) * scale - 0.5);
      if (d.dot(cues_.horizon.up_c) < min_up) continue;
      for (int x = 0; x < w; ++x) ++hist[g[x]];
      n_above += w;
    }
    int acc = 0, p99 = 255;
    for (int v = 255; v >= 0; --v) {
      acc += hist[static_cast<std::size_t>(v)];
      if (acc >= n_above / 100 + 1) {
        p99 = v;
        break;
      }
    }
    min_gray = std::max(min_gray, options_.sky_min_relative_gray * p99);
  }
  const float max_grad2 = static_cast<float>(options_.sky_max_gradient * options_.sky_max_gradient);
  // Texture at a larger scale: the mean gradient magnitude over a window (a facade's window
  // edges lie within it even where the wall between them is flat).
  const bool windowed = options_.sky_texture_window_px > 1;
  if (windowed) {
    cv::magnitude(gradient_x_, gradient_y_, blurred_);
    cv::blur(blurred_, blurred_,
             cv::Size(options_.sky_texture_window_px, options_.sky_texture_window_px));
  }
  for (int y = 0; y < h; ++y) {
    const unsigned char* g = work_gray.ptr<unsigned char>(y);
    const cv::Vec3b* bgr = work_bgr.ptr<cv::Vec3b>(y);
    const float* gx = gradient_x_.ptr<float>(y);
    const float* gy = gradient_y_.ptr<float>(y);
    unsigned char* m = cues_.sky_mask.ptr<unsigned char>(y);
    for (int x = 0; x < w; ++x) {
      if (g[x] < min_gray) continue;
      if (gx[x] * gx[x] + gy[x] * gy[x] > max_grad2) continue;
      if (windowed &&
          static_cast<double>(blurred_.at<float>(y, x)) > options_.sky_max_window_gradient) {
        continue;
      }
      if (colour &&
          red_gain * bgr[x][2] > options_.sky_max_red_over_blue * std::max<int>(bgr[x][0], 1)) {
        continue;
      }
      const Eigen::Vector3d d = rayAt((x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5);
      if (d.dot(cues_.horizon.up_c) < min_up) continue;
      m[x] = 255;
    }
  }
  // Keep the candidate regions that touch the top of the image (the sky is not an island).
  const int n_labels = cv::connectedComponents(cues_.sky_mask, labels_, 4, CV_32S);
  top_labels_.assign(static_cast<std::size_t>(n_labels), 0);
  const int* top = labels_.ptr<int>(0);
  for (int x = 0; x < w; ++x) {
    if (top[x] > 0) top_labels_[static_cast<std::size_t>(top[x])] = 1;
  }
  int fit_count = 0;
  cues_.sky_pixels_segmented = 0;
  for (int y = 0; y < h; ++y) {
    const int* l = labels_.ptr<int>(y);
    unsigned char* m = cues_.sky_mask.ptr<unsigned char>(y);
    const unsigned char* g = work_gray.ptr<unsigned char>(y);
    for (int x = 0; x < w; ++x) {
      if (m[x] == 0) continue;
      if (top_labels_[static_cast<std::size_t>(l[x])] == 0) {
        m[x] = 0;
        continue;
      }
      ++cues_.sky_pixels_segmented;
      if (g[x] < options_.sky_saturated_gray) ++fit_count;
    }
  }
  if (fit_count < options_.sky_min_pixels) return;

  // Uniform subsample of the unsaturated sky pixels: rays, linear luminance, gradation.
  sky_rays_.clear();
  sky_luminance_.clear();
  sky_gradation_.clear();
  sky_cos4_.clear();
  const int stride =
      std::max(1, (fit_count + options_.sky_max_fit_pixels - 1) / options_.sky_max_fit_pixels);
  int k = 0;
  for (int y = 0; y < h; ++y) {
    const unsigned char* m = cues_.sky_mask.ptr<unsigned char>(y);
    const unsigned char* g = work_gray.ptr<unsigned char>(y);
    for (int x = 0; x < w; ++x) {
      if (m[x] == 0 || g[x] >= options_.sky_saturated_gray) continue;
      if (k++ % stride != 0) continue;
      const Eigen::Vector3d d = rayAt((x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5);
      sky_rays_.push_back(d);
      sky_luminance_.push_back(srgbToLinear(g[x]));
      sky_gradation_.push_back(perezGradation(perez_, d.dot(cues_.horizon.up_c)));
      sky_cos4_.push_back(d.z() * d.z() * d.z() * d.z());
    }
  }
  cues_.sky_pixels_fitted = static_cast<int>(sky_rays_.size());
  double sum_l2 = 0.0;
  for (double l : sky_luminance_) sum_l2 += l * l;
  if (sum_l2 <= 0.0) return;
  cues_.sky_informative = true;

  // For each candidate sun s: model m_p = G(theta_p) S(gamma_p), best scale k = sum L m / sum m^2,
  // residual sum (L - k m)^2 = sum L^2 - k sum L m; r = that / sum L^2 in [0, 1].
  const double inv_two_sigma2 =
      1.0 / (2.0 * options_.sky_residual_sigma * options_.sky_residual_sigma);
  const std::size_t n = sky_rays_.size();
  for (int r = 0; r < n_zen_; ++r) {
    double* out = cues_.sky_loglik.ptr<double>(r);
    for (int c = 0; c < n_az_; ++c) {
      const Eigen::Vector3d& s = cell_directions_[static_cast<std::size_t>(r * n_az_ + c)];
      double slm = 0.0, smm = 0.0, slv = 0.0, smv = 0.0, svv = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double m = sky_gradation_[i] * scattering_(sky_rays_[i].dot(s));
        slm += sky_luminance_[i] * m;
        smm += m * m;
        if (options_.sky_fit_vignetting) {
          const double mv = m * sky_cos4_[i];
          slv += sky_luminance_[i] * mv;
          smv += m * mv;
          svv += mv * mv;
        }
      }
      double rel = 1.0;
      if (smm > 0.0 && slm > 0.0) rel = std::clamp((sum_l2 - slm * slm / smm) / sum_l2, 0.0, 1.0);
      // Two-basis least squares [m, m c4]: explained energy b' A^-1 b with A the 2x2 Gram matrix.
      const double det = smm * svv - smv * smv;
      if (options_.sky_fit_vignetting && smm > 0.0 && det > 1e-12 * smm * svv) {
        const double explained = (svv * slm * slm - 2.0 * smv * slm * slv + smm * slv * slv) / det;
        rel = std::clamp((sum_l2 - explained) / sum_l2, 0.0, 1.0);
      }
      out[c] = -rel * inv_two_sigma2;
    }
  }
  // Relative to its best cell, mixed with a uniform chance that the fit misleads:
  // p = (1 - floor) exp(l - l_max) + floor, so a confidently wrong sky cannot veto a cell.
  double max_v = 0.0;
  cv::minMaxLoc(cues_.sky_loglik, nullptr, &max_v);
  for (int r = 0; r < n_zen_; ++r) {
    double* out = cues_.sky_loglik.ptr<double>(r);
    for (int c = 0; c < n_az_; ++c) {
      out[c] = std::log((1.0 - options_.sky_floor) * std::exp(out[c] - max_v) + options_.sky_floor);
    }
  }
}

void LalondeEstimator::shadowCue(const cv::Mat& work_bgr, const cv::Mat& work_gray, bool colour,
                                 double scale) {
  cues_.shadow_loglik.setTo(0.0);
  cues_.shadow_informative = false;
  cues_.shadow_lines.clear();
  cues_.shadow_weight = 0.0;
  const int w = work_gray.cols, h = work_gray.rows;
  const Eigen::Vector3d& up = cues_.horizon.up_c;
  const double H = options_.camera_height_m;

  // Ground: rays at least 2 deg below the horizon that meet the ground within range.
  ground_mask_.create(h, w, CV_8U);
  const double max_down = -std::sin(2.0 * kDeg);
  for (int y = 0; y < h; ++y) {
    unsigned char* m = ground_mask_.ptr<unsigned char>(y);
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d d = rayAt((x + 0.5) * scale - 0.5, (y + 0.5) * scale - 0.5);
      const double du = d.dot(up);
      bool ground = false;
      if (du < max_down) {
        const double range = H / -du * std::sqrt(std::max(0.0, 1.0 - du * du));
        ground = range <= options_.max_ground_distance_m;
      }
      m[x] = ground ? 255 : 0;
    }
  }
  cv::GaussianBlur(work_gray, blurred_, cv::Size(3, 3), 0.0);
  cv::Canny(blurred_, edges_, options_.canny_low, options_.canny_high, 3, true);
  edges_.setTo(0, ground_mask_ == 0);
  hough_lines_.clear();
  cv::HoughLinesP(edges_, hough_lines_, 1.0, kPi / 180.0, options_.hough_threshold,
                  options_.min_line_length_px, 3.0);

  std::fill(shadow_azimuth_.begin(), shadow_azimuth_.end(), 0.0);
  const double sigma2 = 2.0 * options_.shadow_sigma_deg * kDeg;  // spread of 2 phi
  const double kappa = 1.0 / (sigma2 * sigma2);
  for (const cv::Vec4i& l : hough_lines_) {
    const cv::Point2d a(l[0], l[1]), b(l[2], l[3]);
    const cv::Point2d dir = b - a;
    const double len = std::hypot(dir.x, dir.y);
    if (len < 1.0) continue;
    const cv::Point2d n(-dir.y / len, dir.x / len);
    bool inside = true;
    const double m1 = sideMean(work_gray, a, b, n, 2.5, ground_mask_, &inside);
    const double m2 = sideMean(work_gray, a, b, n, -2.5, ground_mask_, &inside);
    if (!inside) continue;
    const double dark = std::min(m1, m2), bright = std::max(m1, m2);
    if (bright < 1.0) continue;
    const double contrast = 1.0 - dark / bright;
    if (contrast < options_.min_shadow_contrast) continue;
    if (colour) {
      // A shadow is lit by the blue sky only: its blue share is not below the sunlit side's.
      const double off_dark = m1 < m2 ? 2.5 : -2.5;
      if (sideBlueShare(work_bgr, a, b, n, off_dark) + 0.01 <
          sideBlueShare(work_bgr, a, b, n, -off_dark)) {
        continue;
      }
    }
    // Project both ends onto the ground plane up . p = -H.
    const Eigen::Vector3d d0 = rayAt((a.x + 0.5) * scale - 0.5, (a.y + 0.5) * scale - 0.5);
    const Eigen::Vector3d d1 = rayAt((b.x + 0.5) * scale - 0.5, (b.y + 0.5) * scale - 0.5);
    const double u0 = d0.dot(up), u1 = d1.dot(up);
    if (u0 >= max_down || u1 >= max_down) continue;
    const Eigen::Vector3d g0 = d0 * (H / -u0), g1 = d1 * (H / -u1);
    const Eigen::Vector3d dg = g1 - g0;
    const double df = dg.dot(cues_.horizon.forward_c), dr = dg.dot(cues_.horizon.right_c);
    const double len_m = std::hypot(df, dr);
    if (len_m < 0.1) continue;
    const double alpha = std::atan2(dr, df);
    // Orientation mod 180 deg: angle to the forward axis in [0, 90] deg.
    const double to_forward = std::abs(std::remainder(alpha, kPi));
    const double track_factor =
        to_forward <= options_.along_track_deg * kDeg ? options_.along_track_weight : 1.0;
    const double weight = std::min(len_m, options_.max_line_weight) * contrast * track_factor;
    if (weight <= 0.0) continue;
    for (int c = 0; c < n_az_; ++c) {
      shadow_azimuth_[static_cast<std::size_t>(c)] +=
          weight * std::exp(kappa * (std::cos(2.0 * (azimuthOfColRad(c) - alpha)) - 1.0));
    }
    cues_.shadow_weight += weight;
    if (cues_.shadow_lines.size() < cues_.shadow_lines.capacity()) {
      ShadowLine sl;
      sl.p0_px = Eigen::Vector2f(static_cast<float>((a.x + 0.5) * scale - 0.5),
                                 static_cast<float>((a.y + 0.5) * scale - 0.5));
      sl.p1_px = Eigen::Vector2f(static_cast<float>((b.x + 0.5) * scale - 0.5),
                                 static_cast<float>((b.y + 0.5) * scale - 0.5));
      sl.ground_azimuth_rad = alpha;
      sl.weight = weight;
      cues_.shadow_lines.push_back(sl);
    }
  }
  if (cues_.shadow_weight < options_.min_shadow_weight) return;
  cues_.shadow_informative = true;
  double sum = 0.0;
  for (double v : shadow_azimuth_) sum += v;
  // p(phi) = (1 - floor) A(phi) / sum A + floor / n; stored relative to uniform (log(p n)).
  for (int c = 0; c < n_az_; ++c) {
    const double p =
        (1.0 - options_.shadow_floor) * shadow_azimuth_[static_cast<std::size_t>(c)] / sum +
        options_.shadow_floor / n_az_;
    const double v = std::log(p * n_az_);
    for (int r = 0; r < n_zen_; ++r) cues_.shadow_loglik.at<double>(r, c) = v;
  }
}

void LalondeEstimator::priorCue(const sunfusion::ImageSunInput& input) {
  if (options_.prior == LalondePrior::kZenith) {
    const double mu = options_.zenith_prior_mean_deg * kDeg;
    const double s = options_.zenith_prior_sigma_deg * kDeg;
    for (int r = 0; r < n_zen_; ++r) {
      const double z = (zenithOfRowRad(r) - mu) / s;
      cues_.prior_loglik.row(r).setTo(-0.5 * z * z);
    }
    return;
  }
  // Lalonde-VO: Gaussian in (azimuth, zenith) around the predicted sun, azimuth difference
  // wrapped to (-180, 180] deg.
  const Eigen::Vector3d& sun_pred_c = input.prior->sun_c;
  const double az_p = cues_.horizon.azimuthRad(sun_pred_c);
  const double zen_p = cues_.horizon.zenithRad(sun_pred_c);
  const double sa = options_.vo_sigma_azimuth_deg * kDeg, sz = options_.vo_sigma_zenith_deg * kDeg;
  for (int r = 0; r < n_zen_; ++r) {
    double* out = cues_.prior_loglik.ptr<double>(r);
    const double dz = (zenithOfRowRad(r) - zen_p) / sz;
    for (int c = 0; c < n_az_; ++c) {
      const double da = wrapPi(azimuthOfColRad(c) - az_p) / sa;
      out[c] = -0.5 * (da * da + dz * dz);
    }
  }
}

}  // namespace sunvo::sunvision
