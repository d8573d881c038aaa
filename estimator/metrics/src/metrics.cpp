#include "sunvo/metrics/metrics.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace sunvo::metrics {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

// The angle between two rotations, rotationAngle(A^T B), with the product written out so that
// its coefficient (i, j) = Σ_k A(k,i) B(k,j) is summed in the same order as (j, i). When A and B
// are bitwise equal, A^T A is then exactly symmetric, vee(M - M^T) = 0 and the angle is exactly
// 0; Eigen's vectorised product does not promise that symmetry (it left 1e-19 rad residues).
double angleBetween(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  Eigen::Matrix3d M;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      M(i, j) = A(0, i) * B(0, j) + A(1, i) * B(1, j) + A(2, i) * B(2, j);
    }
  }
  return rotationAngle(M);
}

// The relative motion error of one pair (i, j):
//   E = (T_gt,i^-1 T_gt,j)^-1 (T_est,i^-1 T_est,j) = D_gt^-1 D_est,
//   D = [R_D | t_D]:  E = [R_gt^T R_est | R_gt^T (t_est - t_gt)],
// so |translation(E)| = |t_est - t_gt| and angle(E) = angleBetween(R_gt, R_est).
struct PairError {
  double translation_m = 0.0;
  double angle_rad = 0.0;
};
PairError relativeError(const Isometry3& gt_i, const Isometry3& gt_j, const Isometry3& est_i,
                        const Isometry3& est_j) {
  const Isometry3 d_gt = gt_i.inverse(Eigen::Isometry) * gt_j;
  const Isometry3 d_est = est_i.inverse(Eigen::Isometry) * est_j;
  return {(d_est.translation() - d_gt.translation()).norm(),
          angleBetween(d_gt.linear(), d_est.linear())};
}

}  // namespace

const char* planeName(HorizontalPlane plane) {
  return plane == HorizontalPlane::kEastNorth ? "EN-plane" : "x-z plane";
}

const char* planeKey(HorizontalPlane plane) {
  return plane == HorizontalPlane::kEastNorth ? "en" : "xz";
}

std::pair<int, int> planeAxes(HorizontalPlane plane) {
  return plane == HorizontalPlane::kEastNorth ? std::pair{0, 1} : std::pair{0, 2};
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double clamped = std::clamp(q, 0.0, 1.0);
  return values[static_cast<std::size_t>(
      std::lround(clamped * static_cast<double>(values.size() - 1)))];
}

ErrorStats summarize(std::vector<double> errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) {
    s.rmse = s.mean = s.median = s.max = kNaN;
    return s;
  }
  double sum = 0.0;
  double sum_sq = 0.0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  std::sort(errors.begin(), errors.end());
  s.max = errors.back();
  const std::size_t mid = errors.size() / 2;
  s.median = errors.size() % 2 == 1 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  return s;
}

Status validateTrajectories(const std::vector<Isometry3>& T_w_c_gt,
                            const std::vector<Isometry3>& T_w_c_est) {
  if (T_w_c_gt.size() != T_w_c_est.size()) {
    return invalidArgument("trajectories differ in length: ground truth has " +
                           std::to_string(T_w_c_gt.size()) + " poses, estimate " +
                           std::to_string(T_w_c_est.size()));
  }
  if (T_w_c_gt.size() < 2) {
    return invalidArgument("trajectories need at least 2 poses, got " +
                           std::to_string(T_w_c_gt.size()));
  }
  for (std::size_t k = 0; k < T_w_c_gt.size(); ++k) {
    if (!allFinite(T_w_c_gt[k])) {
      return invalidArgument("ground-truth pose " + std::to_string(k) + " is not finite");
    }
    if (!allFinite(T_w_c_est[k])) {
      return invalidArgument("estimated pose " + std::to_string(k) + " is not finite");
    }
  }
  return Status::ok();
}

std::vector<double> cumulativeDistances(const std::vector<Isometry3>& T_w_c) {
  std::vector<double> dist(T_w_c.size(), 0.0);
  for (std::size_t k = 1; k < T_w_c.size(); ++k) {
    dist[k] = dist[k - 1] + (T_w_c[k].translation() - T_w_c[k - 1].translation()).norm();
  }
  return dist;
}

Expected<Table1Metrics> computeTable1(const std::vector<Isometry3>& T_w_c_gt,
                                      const std::vector<Isometry3>& T_w_c_est,
                                      HorizontalPlane plane) {
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  const std::size_t n = T_w_c_gt.size();
  const auto [ia, ib] = planeAxes(plane);
  // Computed in the equivalent relative form of the header (each trajectory in its own first
  // frame, the difference rotated back into the world by C_gt,0):
  //   Δp_k = C_gt,0 (C_est,0^T (p_est,k - p_est,0) - C_gt,0^T (p_gt,k - p_gt,0)),
  //   θ_k  = angle(X_est X_gt^T) = angle(X_gt^T X_est),  X = C_0^T C_k  (the angle is invariant
  //          under conjugation by X_gt). Bitwise-equal rotations give exactly θ_k = 0.
  const Eigen::Matrix3d C_gt0 = T_w_c_gt.front().linear();
  const Eigen::Matrix3d C_est0 = T_w_c_est.front().linear();
  const Eigen::Vector3d p_gt0 = T_w_c_gt.front().translation();
  const Eigen::Vector3d p_est0 = T_w_c_est.front().translation();

  Table1Metrics m;
  m.plane = plane;
  m.num_poses = n;
  double sum_t = 0.0;
  double sum_plane = 0.0;
  double sum_r = 0.0;
  Eigen::Vector3d dp_last = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d rel_est = C_est0.transpose() * (T_w_c_est[k].translation() - p_est0);
    const Eigen::Vector3d rel_gt = C_gt0.transpose() * (T_w_c_gt[k].translation() - p_gt0);
    const Eigen::Vector3d dp = C_gt0 * (rel_est - rel_gt);
    const Eigen::Matrix3d X_est = C_est0.transpose() * T_w_c_est[k].linear();
    const Eigen::Matrix3d X_gt = C_gt0.transpose() * T_w_c_gt[k].linear();
    sum_t += std::sqrt(dp.squaredNorm() / 3.0);
    sum_plane += std::sqrt((dp(ia) * dp(ia) + dp(ib) * dp(ib)) / 2.0);
    sum_r += angleBetween(X_gt, X_est) / std::sqrt(3.0);  // angle(X_est X_gt^T), conjugated
    dp_last = dp;
  }
  const double nd = static_cast<double>(n);
  m.trans_armse_m = sum_t / nd;
  m.trans_armse_plane_m = sum_plane / nd;
  m.rot_armse_rad = sum_r / nd;
  m.gt_path_length_m = cumulativeDistances(T_w_c_gt).back();
  m.final_drift_m = dp_last.norm();
  m.final_drift_plane_m = std::hypot(dp_last(ia), dp_last(ib));
  const double L = m.gt_path_length_m;
  m.final_drift_pct = L > 0.0 ? 100.0 * m.final_drift_m / L : kNaN;
  m.final_drift_plane_pct = L > 0.0 ? 100.0 * m.final_drift_plane_m / L : kNaN;
  return m;
}

Status KittiSegmentOptions::validate() const {
  if (lengths_m.empty()) return invalidArgument("kitti.lengths_m: needs at least one length");
  for (double len : lengths_m) {
    if (!(len > 0.0) || !std::isfinite(len)) {
      return invalidArgument("kitti.lengths_m: every length must be finite and > 0 m");
    }
  }
  if (step_frames < 1) return invalidArgument("kitti.step_frames: must be >= 1");
  return Status::ok();
}

Expected<KittiSegmentMetrics> computeKittiSegments(const std::vector<Isometry3>& T_w_c_gt,
                                                   const std::vector<Isometry3>& T_w_c_est,
                                                   const KittiSegmentOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  const std::vector<double> dist = cumulativeDistances(T_w_c_gt);
  const std::size_t n = T_w_c_gt.size();

  KittiSegmentMetrics m;
  std::vector<double> sum_t(options.lengths_m.size(), 0.0);
  std::vector<double> sum_r(options.lengths_m.size(), 0.0);
  std::vector<std::size_t> count(options.lengths_m.size(), 0);
  const std::size_t step = static_cast<std::size_t>(options.step_frames);
  for (std::size_t first = 0; first < n; first += step) {
    for (std::size_t li = 0; li < options.lengths_m.size(); ++li) {
      const double len = options.lengths_m[li];
      // First frame whose cumulative distance exceeds dist[first] + len (dist is
      // non-decreasing, so a binary search finds the devkit's linear-scan answer).
      const auto it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first),
                                       dist.end(), dist[first] + len);
      if (it == dist.end()) continue;
      const std::size_t last = static_cast<std::size_t>(it - dist.begin());
      const PairError e =
          relativeError(T_w_c_gt[first], T_w_c_gt[last], T_w_c_est[first], T_w_c_est[last]);
      sum_t[li] += e.translation_m / len;
      sum_r[li] += e.angle_rad / len;
      ++count[li];
    }
  }
  double total_t = 0.0;
  double total_r = 0.0;
  for (std::size_t li = 0; li < options.lengths_m.size(); ++li) {
    KittiSegmentLengthError e;
    e.length_m = options.lengths_m[li];
    e.num_segments = count[li];
    const double c = static_cast<double>(count[li]);
    e.t_err_pct = count[li] > 0 ? 100.0 * sum_t[li] / c : kNaN;
    e.r_err_deg_per_m = count[li] > 0 ? kRadToDeg * sum_r[li] / c : kNaN;
    m.per_length.push_back(e);
    m.num_segments += count[li];
    total_t += sum_t[li];
    total_r += sum_r[li];
  }
  const double total = static_cast<double>(m.num_segments);
  m.t_err_pct = m.num_segments > 0 ? 100.0 * total_t / total : kNaN;
  m.r_err_deg_per_m = m.num_segments > 0 ? kRadToDeg * total_r / total : kNaN;
  return m;
}

Expected<UmeyamaResult> umeyama(const std::vector<Eigen::Vector3d>& source,
                                const std::vector<Eigen::Vector3d>& target, bool with_scale) {
  if (source.size() != target.size()) {
    return invalidArgument("umeyama: " + std::to_string(source.size()) + " source points but " +
                           std::to_string(target.size()) + " target points");
  }
  if (source.size() < 2) return invalidArgument("umeyama: needs at least 2 point pairs");
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d mu_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d mu_y = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    if (!source[i].allFinite() || !target[i].allFinite()) {
      return invalidArgument("umeyama: point pair " + std::to_string(i) + " is not finite");
    }
    mu_x += source[i];
    mu_y += target[i];
  }
  mu_x /= n;
  mu_y /= n;
  double var_x = 0.0;
  Eigen::Matrix3d sigma_xy = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d dx = source[i] - mu_x;
    var_x += dx.squaredNorm();
    sigma_xy += (target[i] - mu_y) * dx.transpose();
  }
  var_x /= n;
  sigma_xy /= n;
  if (!(var_x > 0.0)) return invalidArgument("umeyama: the source points all coincide");

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma_xy, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  const Eigen::Vector3d& D = svd.singularValues();
  Eigen::Vector3d S(1.0, 1.0, 1.0);
  if (U.determinant() * V.determinant() < 0.0) S(2) = -1.0;

  UmeyamaResult r;
  r.R = U * S.asDiagonal() * V.transpose();
  r.scale = with_scale ? D.dot(S) / var_x : 1.0;
  r.t = mu_y - r.scale * r.R * mu_x;
  r.well_conditioned = D(1) > 1e-12 * D(0);
  return r;
}

Expected<ApeMetrics> computeApe(const std::vector<Isometry3>& T_w_c_gt,
                                const std::vector<Isometry3>& T_w_c_est, const Isometry3& A) {
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  std::vector<double> e_t;
  std::vector<double> e_r;
  e_t.reserve(T_w_c_gt.size());
  e_r.reserve(T_w_c_gt.size());
  for (std::size_t k = 0; k < T_w_c_gt.size(); ++k) {
    const Isometry3 est = A * T_w_c_est[k];
    e_t.push_back((T_w_c_gt[k].translation() - est.translation()).norm());
    e_r.push_back(angleBetween(T_w_c_gt[k].linear(), est.linear()));
  }
  return ApeMetrics{summarize(std::move(e_t)), summarize(std::move(e_r))};
}

Expected<RpeMetrics> computeRpePerFrame(const std::vector<Isometry3>& T_w_c_gt,
                                        const std::vector<Isometry3>& T_w_c_est) {
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  std::vector<double> e_t;
  std::vector<double> e_r;
  for (std::size_t i = 0; i + 1 < T_w_c_gt.size(); ++i) {
    const PairError e = relativeError(T_w_c_gt[i], T_w_c_gt[i + 1], T_w_c_est[i], T_w_c_est[i + 1]);
    e_t.push_back(e.translation_m);
    e_r.push_back(e.angle_rad);
  }
  return RpeMetrics{0.0, summarize(std::move(e_t)), summarize(std::move(e_r))};
}

Expected<RpeMetrics> computeRpePerDistance(const std::vector<Isometry3>& T_w_c_gt,
                                           const std::vector<Isometry3>& T_w_c_est,
                                           double distance_m) {
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) {
    return invalidArgument("rpe_distance_m: must be finite and > 0 m");
  }
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  const std::vector<double> dist = cumulativeDistances(T_w_c_gt);
  std::vector<double> e_t;
  std::vector<double> e_r;
  for (std::size_t i = 0; i < dist.size(); ++i) {
    const auto it = std::lower_bound(dist.begin() + static_cast<std::ptrdiff_t>(i), dist.end(),
                                     dist[i] + distance_m);
    if (it == dist.end()) break;  // later starts have even less distance left
    const std::size_t j = static_cast<std::size_t>(it - dist.begin());
    const PairError e = relativeError(T_w_c_gt[i], T_w_c_gt[j], T_w_c_est[i], T_w_c_est[j]);
    e_t.push_back(e.translation_m);
    e_r.push_back(e.angle_rad);
  }
  return RpeMetrics{distance_m, summarize(std::move(e_t)), summarize(std::move(e_r))};
}

Expected<RpeMetricsEvo> computeRpeEvo(const std::vector<Isometry3>& T_w_c_gt,
                                      const std::vector<Isometry3>& T_w_c_est, double delta_m,
                                      RpePathOf path_of) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m)) {
    return invalidArgument("rpe delta_m: must be finite and > 0 m");
  }
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  const std::vector<Isometry3>& path = path_of == RpePathOf::kEstimate ? T_w_c_est : T_w_c_gt;
  std::vector<std::size_t> chosen;
  double since_last = 0.0;
  for (std::size_t k = 1; k < path.size(); ++k) {
    since_last += (path[k].translation() - path[k - 1].translation()).norm();
    if (since_last >= delta_m) {
      chosen.push_back(k);
      since_last = 0.0;
    }
  }
  std::vector<double> e_t;
  std::vector<double> e_r;
  for (std::size_t n = 1; n < chosen.size(); ++n) {
    const std::size_t i = chosen[n - 1], j = chosen[n];
    const PairError e = relativeError(T_w_c_gt[i], T_w_c_gt[j], T_w_c_est[i], T_w_c_est[j]);
    e_t.push_back(e.translation_m);
    e_r.push_back(e.angle_rad);
  }
  return RpeMetricsEvo{delta_m, path_of, summarize(std::move(e_t)), summarize(std::move(e_r))};
}

Status EvaluationOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(kitti.validate());
  if (!(rpe_distance_m > 0.0) || !std::isfinite(rpe_distance_m)) {
    return invalidArgument("rpe_distance_m: must be finite and > 0 m");
  }
  return Status::ok();
}

Expected<TiltMetrics> computeTilt(const std::vector<Isometry3>& T_w_c_gt,
                                  const std::vector<Isometry3>& T_w_c_est,
                                  const Eigen::Vector3d& up_w) {
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  if (!up_w.allFinite() || std::abs(up_w.norm() - 1.0) > 1e-6) {
    return invalidArgument("computeTilt: up_w must be a unit vector");
  }
  TiltMetrics out;
  double tilt2 = 0.0, heading2 = 0.0;
  for (std::size_t k = 0; k < T_w_c_gt.size(); ++k) {
    const Eigen::Vector3d e = logSO3(T_w_c_gt[k].linear() * T_w_c_est[k].linear().transpose());
    const double heading = std::abs(e.dot(up_w));
    const double tilt = (e - e.dot(up_w) * up_w).norm();
    tilt2 += tilt * tilt;
    heading2 += heading * heading;
    out.tilt_final_rad = tilt;
    out.heading_final_rad = heading;
  }
  const double n = static_cast<double>(T_w_c_gt.size());
  out.tilt_rms_rad = std::sqrt(tilt2 / n);
  out.heading_rms_rad = std::sqrt(heading2 / n);
  return out;
}

Expected<Evaluation> evaluate(const std::vector<Isometry3>& T_w_c_gt,
                              const std::vector<Isometry3>& T_w_c_est,
                              const EvaluationOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(validateTrajectories(T_w_c_gt, T_w_c_est));
  Evaluation ev;
  auto table1 = computeTable1(T_w_c_gt, T_w_c_est, options.plane);
  if (!table1) return table1.status();
  ev.table1 = *table1;
  auto kitti = computeKittiSegments(T_w_c_gt, T_w_c_est, options.kitti);
  if (!kitti) return kitti.status();
  ev.kitti = std::move(*kitti);

  std::vector<Eigen::Vector3d> p_est;
  std::vector<Eigen::Vector3d> p_gt;
  p_est.reserve(T_w_c_gt.size());
  p_gt.reserve(T_w_c_gt.size());
  for (std::size_t k = 0; k < T_w_c_gt.size(); ++k) {
    p_est.push_back(T_w_c_est[k].translation());
    p_gt.push_back(T_w_c_gt[k].translation());
  }
  auto ape_raw = computeApe(T_w_c_gt, T_w_c_est);
  if (!ape_raw) return ape_raw.status();
  ev.ape_raw = *ape_raw;
  auto align = umeyama(p_est, p_gt, /*with_scale=*/false);
  if (align) {
    ev.se3_alignment = *align;
  } else {
    // All estimated positions coincide (no motion): the best rigid alignment is then a pure
    // translation onto the ground truth's centroid, with R = I.
    Eigen::Vector3d mu_gt = Eigen::Vector3d::Zero();
    for (const auto& p : p_gt) mu_gt += p;
    mu_gt /= static_cast<double>(p_gt.size());
    ev.se3_alignment.t = mu_gt - p_est.front();
    ev.se3_alignment.well_conditioned = false;
  }
  Isometry3 A = Isometry3::Identity();
  A.linear() = ev.se3_alignment.R;
  A.translation() = ev.se3_alignment.t;
  auto ape_se3 = computeApe(T_w_c_gt, T_w_c_est, A);
  if (!ape_se3) return ape_se3.status();
  ev.ape_se3 = *ape_se3;

  auto rpe_frame = computeRpePerFrame(T_w_c_gt, T_w_c_est);
  if (!rpe_frame) return rpe_frame.status();
  ev.rpe_frame = *rpe_frame;
  auto rpe_dist = computeRpePerDistance(T_w_c_gt, T_w_c_est, options.rpe_distance_m);
  if (!rpe_dist) return rpe_dist.status();
  ev.rpe_distance = *rpe_dist;
  auto rpe_evo = computeRpeEvo(T_w_c_gt, T_w_c_est, options.rpe_distance_m);
  if (!rpe_evo) return rpe_evo.status();
  ev.rpe_evo = *rpe_evo;
  return ev;
}

}  // namespace sunvo::metrics
