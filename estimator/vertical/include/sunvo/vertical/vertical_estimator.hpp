#pragma once
// The camera's "up" from the vertical vanishing point of one gray image: a gravity (roll/pitch)
// cue from what city images show for free, the vertical edges of buildings, poles and windows.
//
// Model. A 3-D line with direction up_c (unit, camera frame) projects to an image segment whose
// interpretation plane (the plane through the camera centre and the segment) has the unit normal
//   n = K^T l / |K^T l|,   l = a_h x b_h   (a, b the segment's end points, homogeneous),
// and since the plane contains the line, n . up_c = 0. For many vertical segments up_c is the
// direction least out of all their planes: with weights w_i (segment length, px),
//   up_c = argmin_|u|=1  sum_i w_i (n_i . u)^2,
// the eigenvector of M = sum_i w_i n_i n_i^T with the smallest eigenvalue. With each segment's
// plane angle off by line_sigma_deg (independent), the covariance of u in its tangent plane is
// line_sigma^2 (P M1 P)^+, M1 = sum_i n_i n_i^T, P = I - u u^T: along the eigenvector of P M1 P
// with eigenvalue l_j it is line_sigma^2 / l_j. Both tangent directions are reported (the worse
// one's sigma, and the better one's with its axis), each floored at min_sigma_deg (real scenes
// lean a little): the segments' image angles fix the roll of a level camera several times better
// than their convergence fixes the pitch.
//
// Which segments are vertical is found by RANSAC: candidates are the segments whose plane is
// within max_tilt_deg of the prior up (the current attitude, or level); two candidates give
// u = n_i x n_j, and the hypothesis with the most length within inlier_angle_deg
// (|n . u| < sin(inlier_angle_deg)) wins and is refined by the eigenvector twice, re-selecting
// its inliers each time. One sun-like absolute direction per image: the caller puts it next to
// the sun as a residual on the attitude (the world's up is known exactly).
//
// Segments (`detector`): by default the cue's own detector of near-vertical straight edges
// (vertical_segments.hpp), which allocates nothing after init; or OpenCV's line segment detector
// (LSD), which allocates inside OpenCV on every call. Either runs on the image downscaled to at
// most max_width_px columns (a 1241-px KITTI image to 640 for LSD, 620 for the own detector's
// integer factor: 4x less CPU than full resolution, and on the full-resolution drives measured no
// less accurate; docs/vertical.md).

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <span>
#include <string_view>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/vertical/vertical_segments.hpp"

namespace sunvo::vertical {

enum class SegmentDetector {
  kEdgeChains,  // the cue's own near-vertical edge chains: no allocation per call
  kLsd,         // OpenCV's line segment detector: allocates per call
};
inline std::span<const std::string_view> enumNames(SegmentDetector) {
  static constexpr std::string_view kNames[] = {"edge_chains", "lsd"};
  return kNames;
}

struct VerticalOptions {
  double max_tilt_deg = 15.0;     // deg, (0, 60]: candidates' planes within this of the prior up
  double inlier_angle_deg = 0.5;  // deg, (0, 10]: |n . u| bound of an inlier
  // (0, 1]: segments shorter than this share of the image's rows are unused (0.1: 37.5 px of
  // a 375-row image). A share, not pixels, so the same scene content counts at any resolution;
  // short edges carried a pitch bias on the validation drives (docs/vertical.md).
  double min_segment_rows_share = 0.1;
  int min_inliers = 8;          // [3, 10000]: fewer inliers = invalid
  double max_sigma_deg = 3.0;   // deg, (0, 90]: a larger sigma = invalid
  double min_sigma_deg = 0.2;   // deg, (0, 10]: floor of the reported sigma
  double line_sigma_deg = 1.0;  // deg, (0, 10]: error of one segment's plane angle
  // Report the up's uncertainty per tangent direction (sigma_rad along the worse one,
  // sigma_strong_rad along the better one, each floored at min_sigma_deg); false = the worse
  // direction's sigma for both (isotropic, as before 2026-11-28).
  bool per_axis_sigma = true;
  int ransac_iterations = 300;  // [1, 100000]
  std::uint32_t seed = 1;       // RANSAC's sampler, reset per call: same image, same answer
  int max_width_px = 640;       // px, [64, 100000]: wider images are downscaled to it first
  SegmentDetector detector = SegmentDetector::kEdgeChains;  // edge_chains | lsd
  double min_gradient = 5.0;  // gray levels / px, (0, 255]: weakest edge (edge_chains only)
  int max_segments = 4096;    // [16, 100000]: segments kept per image (fixed memory)

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("max_tilt_deg", s.max_tilt_deg);
    v("inlier_angle_deg", s.inlier_angle_deg);
    v("min_segment_rows_share", s.min_segment_rows_share);
    v("min_inliers", s.min_inliers);
    v("max_sigma_deg", s.max_sigma_deg);
    v("min_sigma_deg", s.min_sigma_deg);
    v("line_sigma_deg", s.line_sigma_deg);
    v("per_axis_sigma", s.per_axis_sigma);
    v("ransac_iterations", s.ransac_iterations);
    v("seed", s.seed);
    v("max_width_px", s.max_width_px);
    v("detector", s.detector);
    v("min_gradient", s.min_gradient);
    v("max_segments", s.max_segments);
  }
};

struct VerticalMeasurement {
  bool valid = false;
  Eigen::Vector3d up_c = Eigen::Vector3d(0.0, -1.0, 0.0);  // unit, camera frame (x right, y down)
  double sigma_rad = 0.0;  // 1-sigma angle of up_c along its worse tangent direction
  // 1-sigma angle along the better tangent direction strong_axis_c (unit, normal to up_c): for a
  // level camera the roll, which the segments' image angles give directly, while the pitch
  // (how the segments converge) is the worse one. Equal to sigma_rad with per_axis_sigma off.
  double sigma_strong_rad = 0.0;
  Eigen::Vector3d strong_axis_c = Eigen::Vector3d(1.0, 0.0, 0.0);
  int candidates = 0;       // segments near the prior's vertical
  int inliers = 0;          // segments of the winning vanishing point
  const char* reason = "";  // why invalid ("" when valid)
};

class VerticalEstimator {
 public:
  Status init(const VerticalOptions& options, const StereoCamera& camera);
  // gray: CV_8UC1 of the camera's size. up_prior_c: unit, where "up" is expected (level camera:
  // (0, -1, 0)). Errors only for bad input; "no vertical found" is a measurement with
  // valid = false and a reason. Never NaN.
  Expected<VerticalMeasurement> estimate(const cv::Mat& gray, const Eigen::Vector3d& up_prior_c);

  // A candidate segment of the last estimate(): the unit normal of its interpretation plane
  // (camera frame), its length (the weight, full-resolution px) and its end points (full
  // resolution px). For diagnosis (sunvo_vertical_eval --segments-csv).
  struct Plane {
    Eigen::Vector3d n;
    double w;
    Eigen::Vector2d a, b;
  };
  const std::vector<Plane>& candidates() const { return planes_; }

 private:
  // up = the smallest eigenvector of the weighted scatter of the planes with |n . up| < bound;
  // returns false when fewer than 3 planes qualify.
  // sigma: the worse tangent direction's 1-sigma angle; sigma_strong and strong_axis: the better
  // one's, and its direction.
  bool refine(double bound, Eigen::Vector3d* up, int* inliers, double* sigma, double* sigma_strong,
              Eigen::Vector3d* strong_axis) const;

  VerticalOptions options_;
  StereoCamera camera_;
  bool ready_ = false;
  VerticalSegmentDetector chains_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;
  cv::Mat small_;
  std::vector<cv::Vec4f> segments_;
  std::vector<Plane> planes_;
};

}  // namespace sunvo::vertical
