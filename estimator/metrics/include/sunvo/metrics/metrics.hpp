#pragma once
// Trajectory error metrics: the paper's Table 1, the KITTI odometry benchmark's segment errors,
// absolute pose error (APE, raw and after SE(3) Umeyama alignment) and relative pose error (RPE).
// Pure computation, no I/O.
//
// Inputs are two pose sequences T_w_c_gt[k], T_w_c_est[k] (k = 0..N-1), associated by index:
// same length N >= 2, every entry finite; otherwise kInvalidArgument. Positions p_k are the
// translations of T_w_c[k]; rotations C_k their linear parts. Every angle comes from core's
// rotationAngle (the atan2 form), never from a bare arccos. Lower is better for every number.
//
// A quantity that is undefined for the given input (a percentage of a zero path length, a
// segment average with no complete segment) is NaN, and its count field says why.

#include <string_view>
#include <utility>
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::metrics {

// The horizontal plane (a, b) used by the "in-plane" rows of Table 1 and by top-view plots.
enum class HorizontalPlane {
  kEastNorth,  // (a, b) = world (x, y) = (East, North) of an ENU world frame
  kCameraXZ,   // (a, b) = world (x, z): KITTI poses relative to camera 0 (x right, z forward)
};

// "EN-plane" or "x-z plane": how the plane is named in tables.
const char* planeName(HorizontalPlane plane);
// "en" or "xz": the command-line spelling.
const char* planeKey(HorizontalPlane plane);
// Indices of a and b in a 3-vector: (0, 1) for East-North, (0, 2) for camera x-z.
std::pair<int, int> planeAxes(HorizontalPlane plane);

// Summary of a set of non-negative errors e_i (i = 1..n).
struct ErrorStats {
  double rmse = 0.0;      // sqrt(sum e_i^2 / n)
  double mean = 0.0;      // sum e_i / n
  double median = 0.0;    // middle value (mean of the two middle values when n is even)
  double max = 0.0;       // largest e_i
  std::size_t count = 0;  // n; when 0 every other field is NaN
};
ErrorStats summarize(std::vector<double> errors);

// The q-quantile (q in [0, 1]) of `values` as the sorted element at index round(q (n - 1)), no
// interpolation (q = 0.5 of an even count takes the upper middle); 0 when empty. Used for timing
// summaries (median, p99).
double percentile(std::vector<double> values, double q);

// Paper Table 1. Both trajectories are taken relative to their own first pose, with no
// alignment, and the estimate is re-anchored on the ground truth's first pose so that the
// horizontal plane keeps its meaning in the world frame:
//   T'_est,k = T_gt,0 T_est,0^-1 T_est,k,   Δp_k = p'_est,k - p_gt,k,   ΔC_k = C'_est,k C_gt,k^T.
// (Δp_k = C_gt,0 (p_est,0→k - p_gt,0→k) and ΔC_k = C_gt,0 (C_est,0→k C_gt,0→k^T) C_gt,0^T, so
// the 3-D numbers equal those of the two trajectories expressed each in its own first frame;
// for KITTI files T_gt,0 = I and nothing changes at all.) With (Δa_k, Δb_k) the plane
// components of Δp_k and θ_k = rotationAngle(ΔC_k), over all poses k = 0..N-1 (k = 0 included;
// its error is 0 by construction):
//   trans_armse_m        = (1/N) Σ_k sqrt(|Δp_k|^2 / 3)       (RMS over the 3 axes, averaged)
//   trans_armse_plane_m  = (1/N) Σ_k sqrt((Δa_k^2 + Δb_k^2) / 2)
//   rot_armse_rad        = (1/N) Σ_k θ_k / sqrt(3)            (RMS of the 3 axis-angle components
//                                                               |θ_k u_k| / sqrt(3); the paper
//                                                               prints it ×10^-3, i.e. in mrad)
//   gt_path_length_m     = L = Σ_{k<N-1} |p_gt,k+1 - p_gt,k|  (3-D path length of the truth)
//   final_drift_m        = |Δp_{N-1}|,              final_drift_pct       = 100 |Δp_{N-1}| / L
//   final_drift_plane_m  = |(Δa, Δb)_{N-1}|,        final_drift_plane_pct = 100 |(Δa,Δb)_{N-1}| / L
// Both percentages use the 3-D path length L (the paper's Table 1 rows imply one common
// denominator); they are NaN when L = 0.
struct Table1Metrics {
  HorizontalPlane plane = HorizontalPlane::kCameraXZ;
  std::size_t num_poses = 0;
  double trans_armse_m = 0.0;
  double trans_armse_plane_m = 0.0;
  double rot_armse_rad = 0.0;
  double gt_path_length_m = 0.0;
  double final_drift_m = 0.0;
  double final_drift_pct = 0.0;
  double final_drift_plane_m = 0.0;
  double final_drift_plane_pct = 0.0;
};
Expected<Table1Metrics> computeTable1(const std::vector<Isometry3>& T_w_c_gt,
                                      const std::vector<Isometry3>& T_w_c_est,
                                      HorizontalPlane plane);

// KITTI odometry benchmark segment errors, as the devkit (evaluate_odometry.cpp) defines them:
//   dist[0] = 0, dist[k] = dist[k-1] + |p_gt,k - p_gt,k-1|.
//   For each first frame f = 0, step, 2 step, ... and each length len in lengths_m:
//     l = the first frame >= f with dist[l] > dist[f] + len (no such frame: segment skipped);
//     E = (T_gt,f^-1 T_gt,l)^-1 (T_est,f^-1 T_est,l);
//     t_err = |translation(E)| / len,   r_err = rotationAngle(E) / len.
//   The averages run over all such segments (every length pooled, as the devkit's total).
// (The devkit writes E the other way round, inv(Δest) Δgt; that is E^-1, whose translation has
// the same norm and whose angle is the same.)
struct KittiSegmentOptions {
  // Segment lengths [m], each > 0. Default: the benchmark's 100, 200, ..., 800 m.
  std::vector<double> lengths_m = {100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0};
  // Frames between segment starts [frames], >= 1. Default: the devkit's 10.
  int step_frames = 10;
  Status validate() const;
};
struct KittiSegmentLengthError {
  double length_m = 0.0;
  std::size_t num_segments = 0;
  double t_err_pct = 0.0;        // mean t_err × 100 over this length's segments (NaN if none)
  double r_err_deg_per_m = 0.0;  // mean r_err in degrees per metre (NaN if none)
};
struct KittiSegmentMetrics {
  std::size_t num_segments = 0;  // all lengths; 0 when the ground truth is shorter than 100 m
  double t_err_pct = 0.0;        // mean t_err × 100 [%] (NaN if no segment)
  double r_err_deg_per_m = 0.0;  // mean r_err [deg/m] (NaN if no segment)
  std::vector<KittiSegmentLengthError> per_length;
};
Expected<KittiSegmentMetrics> computeKittiSegments(const std::vector<Isometry3>& T_w_c_gt,
                                                   const std::vector<Isometry3>& T_w_c_est,
                                                   const KittiSegmentOptions& options = {});

// Umeyama's closed-form least-squares similarity (Umeyama 1991, "Least-squares estimation of
// transformation parameters between two point patterns"): finds s, R, t minimising
//   (1/n) Σ_i |y_i - (s R x_i + t)|^2     (x = source points, y = target points).
// With μ_x, μ_y the means, σ_x^2 = (1/n) Σ |x_i - μ_x|^2 and Σ_xy = (1/n) Σ (y_i - μ_y)(x_i -
// μ_x)^T = U D V^T (SVD), S = diag(1, 1, det(U) det(V) < 0 ? -1 : 1):
//   R = U S V^T,   s = tr(D S) / σ_x^2 (or 1 when with_scale is false),   t = μ_y - s R μ_x.
struct UmeyamaResult {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // False when the points are (near) collinear (second singular value of Σ_xy below 1e-12 of
  // the first): the rotation about the line is then not determined by the data.
  bool well_conditioned = true;
};
// Needs n >= 2 points in each set, same count, all finite, source not all at one point.
Expected<UmeyamaResult> umeyama(const std::vector<Eigen::Vector3d>& source,
                                const std::vector<Eigen::Vector3d>& target, bool with_scale);

// Absolute pose error. Per pose k, with T_est,k possibly pre-multiplied by an alignment A:
//   e_t,k = |p_gt,k - p_A,k|,  e_r,k = rotationAngle(C_gt,k^T C_A,k)   (T_A,k = A T_est,k)
// raw:     A = I (the poses exactly as given, both in the same world frame).
// se3:     A = [R | t] from umeyama(p_est, p_gt, with_scale = false) (no scale).
struct ApeMetrics {
  ErrorStats translation_m;
  ErrorStats rotation_rad;
};
// Relative pose error over pairs (i, j):
//   E_ij = (T_gt,i^-1 T_gt,j)^-1 (T_est,i^-1 T_est,j),  e_t = |translation(E_ij)|,
//   e_r = rotationAngle(E_ij).
// per frame:     j = i + 1, every i = 0..N-2.
// per distance:  for every i, j = the first frame with dist[j] - dist[i] >= distance_m (dist as in
//                the KITTI metric); starts with no such j are skipped (count may be 0).
struct RpeMetrics {
  double delta_m = 0.0;  // 0 for per-frame RPE, else the travelled distance of each pair [m]
  ErrorStats translation_m;
  ErrorStats rotation_rad;
};

// The same relative error with the pairs that evo chooses (evo_rpe --delta D --delta_unit m,
// consecutive pairs, metrics.RPE + filters.filter_pairs_by_path): walking the trajectory from
// frame 0 and summing the straight-line steps |p_k - p_k-1|, every frame where the sum since the
// last chosen frame first reaches D is chosen (frame 0 is not, unless D <= 0); pairs are
// consecutive chosen frames (i, j). evo measures the path on the estimate by default and on the
// reference with --pairs_from_reference. tests/metrics checks it against evo's own code.
enum class RpePathOf { kEstimate, kReference };
struct RpeMetricsEvo {
  double delta_m = 0.0;
  RpePathOf path_of = RpePathOf::kEstimate;
  ErrorStats translation_m;  // |translation(E_ij)| (evo: -r trans_part)
  ErrorStats rotation_rad;   // rotationAngle(E_ij) (evo: -r angle_rad)
};
Expected<RpeMetricsEvo> computeRpeEvo(const std::vector<Isometry3>& T_w_c_gt,
                                      const std::vector<Isometry3>& T_w_c_est, double delta_m,
                                      RpePathOf path_of = RpePathOf::kEstimate);

// Everything above for one estimate.
struct EvaluationOptions {
  HorizontalPlane plane = HorizontalPlane::kCameraXZ;  // plane of Table 1's in-plane rows
  KittiSegmentOptions kitti;                           // KITTI benchmark segments
  double rpe_distance_m = 100.0;  // travelled distance of distance-based RPE pairs [m], > 0
  Status validate() const;
};
struct Evaluation {
  Table1Metrics table1;
  KittiSegmentMetrics kitti;
  UmeyamaResult se3_alignment;  // the A of ape_se3
  ApeMetrics ape_raw;
  ApeMetrics ape_se3;
  RpeMetrics rpe_frame;
  RpeMetrics rpe_distance;
  RpeMetricsEvo rpe_evo;  // evo's definition, rpe_distance_m, path of the estimate
};

// Checks the common input contract (same length >= 2, all finite); names the first bad pose.
Status validateTrajectories(const std::vector<Isometry3>& T_w_c_gt,
                            const std::vector<Isometry3>& T_w_c_est);

Expected<ApeMetrics> computeApe(const std::vector<Isometry3>& T_w_c_gt,
                                const std::vector<Isometry3>& T_w_c_est,
                                const Isometry3& A = Isometry3::Identity());
Expected<RpeMetrics> computeRpePerFrame(const std::vector<Isometry3>& T_w_c_gt,
                                        const std::vector<Isometry3>& T_w_c_est);
Expected<RpeMetrics> computeRpePerDistance(const std::vector<Isometry3>& T_w_c_gt,
                                           const std::vector<Isometry3>& T_w_c_est,
                                           double distance_m);
Expected<Evaluation> evaluate(const std::vector<Isometry3>& T_w_c_gt,
                              const std::vector<Isometry3>& T_w_c_est,
                              const EvaluationOptions& options = {});

// The attitude error split by gravity: e_k = logSO3(C_gt,k C_est,k^T) (world frame,
// C_gt = Exp(e) C_est), its tilt (roll/pitch) part |e_k - (e_k . up_w) up_w| and its heading part
// |e_k . up_w|; RMS over all poses and at the last one, rad. up_w: unit, the world's up.
struct TiltMetrics {
  double tilt_rms_rad = 0.0;
  double tilt_final_rad = 0.0;
  double heading_rms_rad = 0.0;
  double heading_final_rad = 0.0;
};
Expected<TiltMetrics> computeTilt(const std::vector<Isometry3>& T_w_c_gt,
                                  const std::vector<Isometry3>& T_w_c_est,
                                  const Eigen::Vector3d& up_w);

// Cumulative ground-truth distance dist[k] (see the KITTI metric) [m].
std::vector<double> cumulativeDistances(const std::vector<Isometry3>& T_w_c);

}  // namespace sunvo::metrics
