#pragma once
// Frame-to-frame stereo motion: 3-point RANSAC on stereo observations of the same landmarks in
// frames k-1 and k, scored by the stereo reprojection error in frame k, refined by Gauss-Newton on
// all inliers. Deterministic for a given seed. No allocation per call after init().

#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::motion {

struct RansacOptions {
  int max_iterations = 200;   // count, [1, 100000]: hypotheses at most (adaptive stop earlier)
  double confidence = 0.999;  // (0, 1): stop when P(an all-inlier sample was drawn) >= this
  double inlier_threshold_px = 2.0;  // px, > 0: max norm of the (u, v, u_right) reprojection error
  int min_inliers = 8;               // count, >= 3: fewer inliers -> failure (kFailedPrecondition)
  int refine_iterations = 10;        // count, [0, 100]: Gauss-Newton steps on all inliers
  double min_disparity_px = 1.0;     // px, > 0: observations with smaller disparity (either frame)
                                     // are not used (cannot be triangulated reliably)
  int max_observations = 2000;       // count, >= 3: buffer size; more matches than this -> error

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("max_iterations", s.max_iterations);
    v("confidence", s.confidence);
    v("inlier_threshold_px", s.inlier_threshold_px);
    v("min_inliers", s.min_inliers);
    v("refine_iterations", s.refine_iterations);
    v("min_disparity_px", s.min_disparity_px);
    v("max_observations", s.max_observations);
  }
};

// One landmark seen in both frames: left (u, v) and right u in frame k-1 and in frame k.
struct StereoMatch {
  double u_prev = 0.0, v_prev = 0.0, ur_prev = 0.0;  // px, frame k-1
  double u_cur = 0.0, v_cur = 0.0, ur_cur = 0.0;     // px, frame k
};

struct MotionEstimate {
  Isometry3 T_k_km1 = Isometry3::Identity();  // maps points of frame k-1 into frame k
  int num_inliers = 0;
  int num_usable = 0;          // matches with disparity >= min_disparity_px in both frames
  int hypotheses = 0;          // RANSAC iterations run
  double inlier_rms_px = 0.0;  // RMS of the 3-vector reprojection error over inliers, px
  std::span<const std::uint8_t> inlier_mask;  // one per input match; valid until the next call
};

class StereoRansac {
 public:
  Status init(const RansacOptions& options, const StereoCamera& camera);

  // Estimates T_k_km1. Fails (kFailedPrecondition) with too few usable matches or inliers, or
  // when no finite pose is found; kInvalidArgument when matches exceed max_observations.
  Expected<MotionEstimate> estimate(std::span<const StereoMatch> matches, std::uint64_t seed);

  // Stereo reprojection error (u, v, u_right) of p_km1 moved by T_k_km1 against match m (frame k).
  // Returns false when the point lands behind the camera (z <= 1e-6 m).
  bool reprojectionError(const Isometry3& T_k_km1, const Eigen::Vector3d& p_km1,
                         const StereoMatch& m, Eigen::Vector3d& e) const;

 private:
  // Gauss-Newton on the stereo reprojection error of the matches listed in idx; T updated in place.
  bool refine(Isometry3& T, std::span<const int> idx, int iterations) const;
  int score(const Isometry3& T, std::vector<std::uint8_t>& mask, double& sq_sum) const;

  RansacOptions options_;
  StereoCamera camera_;
  bool initialized_ = false;
  std::mt19937_64 rng_;
  // Buffers sized once by max_observations.
  std::vector<Eigen::Vector3d> p_prev_;  // triangulated in k-1
  std::vector<Eigen::Vector3d> p_cur_;   // triangulated in k
  std::vector<int> usable_;              // indices into the input of usable matches
  int n_usable_ = 0;
  std::vector<int> inlier_idx_;
  std::vector<std::uint8_t> mask_;       // per input match (output)
  std::vector<std::uint8_t> best_mask_;  // per input match (work)
  std::vector<std::uint8_t> work_mask_;
  std::span<const StereoMatch> matches_;
};

}  // namespace sunvo::motion
