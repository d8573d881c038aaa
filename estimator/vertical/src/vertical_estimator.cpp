#include "sunvo/vertical/vertical_estimator.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace sunvo::vertical {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}  // namespace

Status VerticalOptions::validate() const {
  if (!(max_tilt_deg > 0.0 && max_tilt_deg <= 60.0)) {
    return invalidArgument("vertical.max_tilt_deg out of range (0, 60]");
  }
  if (!(inlier_angle_deg > 0.0 && inlier_angle_deg <= 10.0)) {
    return invalidArgument("vertical.inlier_angle_deg out of range (0, 10]");
  }
  if (!(min_segment_rows_share > 0.0 && min_segment_rows_share <= 1.0)) {
    return invalidArgument("vertical.min_segment_rows_share out of range (0, 1]");
  }
  if (min_inliers < 3 || min_inliers > 10000) {
    return invalidArgument("vertical.min_inliers out of range [3, 10000]");
  }
  if (!(min_sigma_deg > 0.0 && min_sigma_deg <= 10.0)) {
    return invalidArgument("vertical.min_sigma_deg out of range (0, 10]");
  }
  if (!(line_sigma_deg > 0.0 && line_sigma_deg <= 10.0)) {
    return invalidArgument("vertical.line_sigma_deg out of range (0, 10]");
  }
  if (!(max_sigma_deg > 0.0 && max_sigma_deg <= 90.0)) {
    return invalidArgument("vertical.max_sigma_deg out of range (0, 90]");
  }
  if (ransac_iterations < 1 || ransac_iterations > 100000) {
    return invalidArgument("vertical.ransac_iterations out of range [1, 100000]");
  }
  if (max_width_px < 64 || max_width_px > 100000) {
    return invalidArgument("vertical.max_width_px out of range [64, 100000]");
  }
  if (!(min_gradient > 0.0 && min_gradient <= 255.0)) {
    return invalidArgument("vertical.min_gradient out of range (0, 255]");
  }
  if (max_segments < 16 || max_segments > 100000) {
    return invalidArgument("vertical.max_segments out of range [16, 100000]");
  }
  return Status::ok();
}

Status VerticalEstimator::init(const VerticalOptions& options, const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  options_ = options;
  camera_ = camera;
  ready_ = false;
  if (options.detector == SegmentDetector::kLsd) {
    lsd_ = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
  } else {
    SUNVO_RETURN_IF_ERROR(chains_.init(camera.width, camera.height, options.max_width_px,
                                       options.min_gradient, options.max_segments));
  }
  segments_.reserve(static_cast<std::size_t>(options.max_segments));
  planes_.reserve(static_cast<std::size_t>(options.max_segments));
  ready_ = true;
  return Status::ok();
}

bool VerticalEstimator::refine(double bound, Eigen::Vector3d* up, int* inliers, double* sigma,
                               double* sigma_strong, Eigen::Vector3d* strong_axis) const {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();   // length-weighted: the estimate
  Eigen::Matrix3d M1 = Eigen::Matrix3d::Zero();  // one per segment: its information
  int count = 0;
  for (const Plane& p : planes_) {
    if (std::abs(p.n.dot(*up)) >= bound) continue;
    const Eigen::Matrix3d nn = p.n * p.n.transpose();
    M += p.w * nn;
    M1 += nn;
    ++count;
  }
  if (count < 3) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
  Eigen::Vector3d u = eig.eigenvectors().col(0);
  if (u.dot(*up) < 0.0) u = -u;
  u.normalize();
  // Information about u in its tangent plane, each segment's plane angle with std line_sigma:
  // the eigenvalues of P M1 P (P projects onto the plane normal to u): (0) is ~0, along u; (1)
  // the weakest tangent direction, (2) the strongest.
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> tangent(P * M1 * P);
  const double line_sigma = options_.line_sigma_deg * kDeg;
  const double worst = line_sigma * line_sigma / std::max(tangent.eigenvalues()(1), 1e-300);
  const double best = line_sigma * line_sigma / std::max(tangent.eigenvalues()(2), 1e-300);
  const Eigen::Vector3d axis = tangent.eigenvectors().col(2);
  if (!u.allFinite() || !std::isfinite(worst) || !std::isfinite(best) || !axis.allFinite()) {
    return false;
  }
  *up = u;
  *inliers = count;
  *sigma = std::sqrt(worst);
  *sigma_strong = std::sqrt(best);
  *strong_axis = axis.normalized();
  return true;
}

Expected<VerticalMeasurement> VerticalEstimator::estimate(const cv::Mat& gray,
                                                          const Eigen::Vector3d& up_prior_c) {
  if (!ready_) return failedPrecondition("VerticalEstimator::estimate before init");
  if (gray.empty() || gray.type() != CV_8UC1) {
    return invalidArgument("vertical: image must be 8-bit single-channel (CV_8UC1), got type " +
                           std::to_string(gray.type()) + " with " +
                           std::to_string(gray.channels()) + " channels");
  }
  if (gray.cols != camera_.width || gray.rows != camera_.height) {
    return invalidArgument("vertical: image is " + std::to_string(gray.cols) + "x" +
                           std::to_string(gray.rows) + ", the camera " +
                           std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
  }
  if (!up_prior_c.allFinite() || up_prior_c.norm() < 1e-9) {
    return invalidArgument("vertical: the prior up direction is not a finite nonzero vector");
  }
  const Eigen::Vector3d prior = up_prior_c.normalized();
  VerticalMeasurement out;
  out.up_c = prior;

  const double min_segment_px = options_.min_segment_rows_share * camera_.height;
  // Scale of the detector's image per axis (its size is rounded, so sx and sy differ slightly).
  // The edge chains come in full-resolution pixels already: sx = sy = 1.
  double sx = 1.0, sy = 1.0;
  if (options_.detector == SegmentDetector::kEdgeChains) {
    SUNVO_RETURN_IF_ERROR(chains_.detect(gray, min_segment_px, &segments_));
  } else if (gray.cols > options_.max_width_px) {
    const double s = static_cast<double>(options_.max_width_px) / gray.cols;
    cv::resize(gray, small_, cv::Size(), s, s, cv::INTER_AREA);
    sx = static_cast<double>(small_.cols) / gray.cols;
    sy = static_cast<double>(small_.rows) / gray.rows;
    lsd_->detect(small_, segments_);
  } else {
    lsd_->detect(gray, segments_);
  }
  // Interpretation-plane normals of the segments near the prior's vertical.
  planes_.clear();
  const double tilt_bound = std::sin(options_.max_tilt_deg * kDeg);
  // Detector pixel (x, y) -> full-resolution pixel (pixel centres map onto each other).
  const auto full = [&](double x, double y) {
    return Eigen::Vector2d((x + 0.5) / sx - 0.5, (y + 0.5) / sy - 0.5);
  };
  const auto ray = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector3d((p.x() - camera_.cu) / camera_.fu, (p.y() - camera_.cv) / camera_.fv,
                           1.0);
  };
  for (const cv::Vec4f& seg : segments_) {
    if (planes_.size() == planes_.capacity()) break;  // fixed memory: max_segments planes
    const Eigen::Vector2d a = full(seg[0], seg[1]), b = full(seg[2], seg[3]);
    const double len = (b - a).norm();
    if (!(len >= min_segment_px)) continue;
    const Eigen::Vector3d n = ray(a).cross(ray(b));
    const double norm = n.norm();
    if (!(norm > 0.0) || !n.allFinite()) continue;
    const Eigen::Vector3d nu = n / norm;
    if (std::abs(nu.dot(prior)) >= tilt_bound) continue;
    planes_.push_back({nu, len, a, b});
  }
  out.candidates = static_cast<int>(planes_.size());
  if (out.candidates < options_.min_inliers) {
    out.reason = "too few near-vertical segments";
    return out;
  }

  // RANSAC over pairs of candidate planes: u = n_i x n_j, scored by inlier length.
  const double inlier_bound = std::sin(options_.inlier_angle_deg * kDeg);
  const double cos_tilt = std::cos(options_.max_tilt_deg * kDeg);
  std::mt19937 rng(options_.seed);
  std::uniform_int_distribution<std::size_t> pick(0, planes_.size() - 1);
  Eigen::Vector3d best = prior;
  double best_score = -1.0;
  for (int it = 0; it < options_.ransac_iterations; ++it) {
    const std::size_t i = pick(rng), j = pick(rng);
    if (i == j) continue;
    Eigen::Vector3d u = planes_[i].n.cross(planes_[j].n);
    const double norm = u.norm();
    if (!(norm > 1e-6)) continue;
    u /= norm;
    if (u.dot(prior) < 0.0) u = -u;
    if (u.dot(prior) < cos_tilt) continue;
    double score = 0.0;
    for (const Plane& p : planes_) {
      if (std::abs(p.n.dot(u)) < inlier_bound) score += p.w;
    }
    if (score > best_score) {
      best_score = score;
      best = u;
    }
  }
  if (best_score < 0.0) {
    out.reason = "no vanishing point within max_tilt_deg of the prior";
    return out;
  }
  double sigma = 0.0, sigma_strong = 0.0;
  Eigen::Vector3d strong_axis = Eigen::Vector3d::UnitX();
  int inliers = 0;
  for (int pass = 0; pass < 3; ++pass) {
    if (!refine(inlier_bound, &best, &inliers, &sigma, &sigma_strong, &strong_axis)) {
      out.reason = "too few inliers to refine";
      return out;
    }
  }
  out.up_c = best;
  out.inliers = inliers;
  out.sigma_rad = std::max(sigma, options_.min_sigma_deg * kDeg);
  out.sigma_strong_rad = options_.per_axis_sigma
                             ? std::max(sigma_strong, options_.min_sigma_deg * kDeg)
                             : out.sigma_rad;
  out.strong_axis_c = strong_axis;
  if (inliers < options_.min_inliers) {
    out.reason = "too few inliers";
  } else if (out.sigma_rad > options_.max_sigma_deg * kDeg) {
    out.reason = "sigma above max_sigma_deg";
  } else if (best.dot(prior) < cos_tilt) {
    out.reason = "refined up beyond max_tilt_deg of the prior";
  } else {
    out.valid = true;
  }
  return out;
}

}  // namespace sunvo::vertical
