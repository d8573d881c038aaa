#include "sunvo/motion/stereo_ransac.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

namespace sunvo::motion {
namespace {
constexpr double kMinDepth = 1e-6;  // m
}  // namespace

Status RansacOptions::validate() const {
  if (max_iterations < 1 || max_iterations > 100000) {
    return invalidArgument("ransac.max_iterations must be in [1, 100000]");
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    return invalidArgument("ransac.confidence must be in (0, 1)");
  }
  if (!(inlier_threshold_px > 0.0))
    return invalidArgument("ransac.inlier_threshold_px must be > 0");
  if (min_inliers < 3) return invalidArgument("ransac.min_inliers must be >= 3");
  if (refine_iterations < 0 || refine_iterations > 100) {
    return invalidArgument("ransac.refine_iterations must be in [0, 100]");
  }
  if (!(min_disparity_px > 0.0)) return invalidArgument("ransac.min_disparity_px must be > 0");
  if (max_observations < 3) return invalidArgument("ransac.max_observations must be >= 3");
  return Status::ok();
}

Status StereoRansac::init(const RansacOptions& options, const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  options_ = options;
  camera_ = camera;
  const auto n = static_cast<std::size_t>(options.max_observations);
  p_prev_.assign(n, Eigen::Vector3d::Zero());
  p_cur_.assign(n, Eigen::Vector3d::Zero());
  usable_.assign(n, 0);
  inlier_idx_.assign(n, 0);
  mask_.assign(n, 0);
  best_mask_.assign(n, 0);
  work_mask_.assign(n, 0);
  initialized_ = true;
  return Status::ok();
}

// Stereo reprojection of p_k = T_k_km1 p_km1 = (x, y, z):
//   u = fu x / z + cu,  v = fv y / z + cv,  u_right = fu (x - b) / z + cu,
// (the right camera sits at +b along x), error e = predicted - measured.
bool StereoRansac::reprojectionError(const Isometry3& T_k_km1, const Eigen::Vector3d& p_km1,
                                     const StereoMatch& m, Eigen::Vector3d& e) const {
  const Eigen::Vector3d p = T_k_km1 * p_km1;
  if (!(p.z() > kMinDepth)) return false;
  const double iz = 1.0 / p.z();
  e.x() = camera_.fu * p.x() * iz + camera_.cu - m.u_cur;
  e.y() = camera_.fv * p.y() * iz + camera_.cv - m.v_cur;
  e.z() = camera_.fu * (p.x() - camera_.baseline_m) * iz + camera_.cu - m.ur_cur;
  return true;
}

// Jacobian of the stereo projection h(p) = (fu x/z + cu, fv y/z + cv, fu (x-b)/z + cu) at p:
//   du/dp  = fu [1/z, 0, -x/z^2],  dv/dp = fv [0, 1/z, -y/z^2],
//   dur/dp = fu [1/z, 0, -(x-b)/z^2].
// Returns false when p is not in front of the camera.
static bool projectWithJacobian(const StereoCamera& c, const Eigen::Vector3d& p, Eigen::Vector3d& h,
                                Eigen::Matrix3d& Jh) {
  if (!(p.z() > kMinDepth)) return false;
  const double iz = 1.0 / p.z();
  const double iz2 = iz * iz;
  h << c.fu * p.x() * iz + c.cu, c.fv * p.y() * iz + c.cv,
      c.fu * (p.x() - c.baseline_m) * iz + c.cu;
  Jh << c.fu * iz, 0.0, -c.fu * p.x() * iz2,  //
      0.0, c.fv * iz, -c.fv * p.y() * iz2,    //
      c.fu * iz, 0.0, -c.fu * (p.x() - c.baseline_m) * iz2;
  return true;
}

static Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// Gauss-Newton on the symmetric ("circular") stereo reprojection error of the matches in idx:
//   forward   r_f = h(T p_prev) - y_cur,      backward  r_b = h(T^-1 p_cur) - y_prev,
// with p_prev, p_cur triangulated in their own frames. Using both directions removes most of
// the bias that the noisy depth of far points puts into a one-directional fit.
// Perturbation on the left: T <- (exp(phi), rho) T, so to first order
//   T p_prev      -> T p_prev + rho + phi x (T p_prev):  d/d(rho, phi) = [ I | -[T p_prev]_x ]
//   T^-1 p_cur    -> C^T (p_cur - rho - phi x p_cur - t): d/d(rho, phi) = [ -C^T | C^T [p_cur]_x ]
// Normal equations (J^T J) delta = -J^T r (6x6, fixed size, LDLT); update
//   C <- exp(phi) C,  t <- exp(phi) t + rho.
bool StereoRansac::refine(Isometry3& T, std::span<const int> idx, int iterations) const {
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::Matrix3d Ct = T.linear().transpose();
    const Isometry3 T_inv = T.inverse();
    for (int i : idx) {
      const auto ui = static_cast<std::size_t>(i);
      const StereoMatch& m = matches_[ui];
      Eigen::Vector3d h;
      Eigen::Matrix3d Jh;
      Eigen::Matrix<double, 3, 6> J;
      const Eigen::Vector3d pf = T * p_prev_[ui];
      if (projectWithJacobian(camera_, pf, h, Jh)) {
        const Eigen::Vector3d r = h - Eigen::Vector3d(m.u_cur, m.v_cur, m.ur_cur);
        J.leftCols<3>() = Jh;
        J.rightCols<3>() = -Jh * skew(pf);
        H.noalias() += J.transpose() * J;
        g.noalias() += J.transpose() * r;
      }
      const Eigen::Vector3d pb = T_inv * p_cur_[ui];
      if (projectWithJacobian(camera_, pb, h, Jh)) {
        const Eigen::Vector3d r = h - Eigen::Vector3d(m.u_prev, m.v_prev, m.ur_prev);
        J.leftCols<3>() = -Jh * Ct;
        J.rightCols<3>() = Jh * Ct * skew(p_cur_[ui]);
        H.noalias() += J.transpose() * J;
        g.noalias() += J.transpose() * r;
      }
    }
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(H);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 6, 1> delta = ldlt.solve(-g);
    if (!delta.allFinite()) return false;
    const Eigen::Matrix3d dC = expSO3(delta.tail<3>());
    T.linear() = orthonormalize(dC * T.linear());
    T.translation() = dC * T.translation() + delta.head<3>();
    if (delta.squaredNorm() < 1e-20) break;
  }
  return allFinite(T);
}

int StereoRansac::score(const Isometry3& T, std::vector<std::uint8_t>& mask, double& sq_sum) const {
  const double thr2 = options_.inlier_threshold_px * options_.inlier_threshold_px;
  int count = 0;
  sq_sum = 0.0;
  const Isometry3 T_inv = T.inverse();
  std::fill(mask.begin(), mask.begin() + static_cast<std::ptrdiff_t>(matches_.size()), 0);
  for (int k = 0; k < n_usable_; ++k) {
    const int i = usable_[static_cast<std::size_t>(k)];
    const auto ui = static_cast<std::size_t>(i);
    Eigen::Vector3d e;
    if (!reprojectionError(T, p_prev_[ui], matches_[ui], e)) continue;
    const double e2 = e.squaredNorm();
    // Backward check: p_cur moved into k-1 against the k-1 measurement.
    const Eigen::Vector3d pb = T_inv * p_cur_[ui];
    if (!(pb.z() > kMinDepth)) continue;
    const StereoMatch& m = matches_[ui];
    const Eigen::Vector3d hb = camera_.project(pb);
    const Eigen::Vector3d eb(hb.x() - m.u_prev, hb.y() - m.v_prev, hb.x() - hb.z() - m.ur_prev);
    if (e2 <= thr2 && eb.squaredNorm() <= thr2) {
      mask[ui] = 1;
      ++count;
      sq_sum += e2;
    }
  }
  return count;
}

Expected<MotionEstimate> StereoRansac::estimate(std::span<const StereoMatch> matches,
                                                std::uint64_t seed) {
  if (!initialized_) return failedPrecondition("StereoRansac::estimate before init");
  if (matches.size() > static_cast<std::size_t>(options_.max_observations)) {
    return invalidArgument(
        "ransac: " + std::to_string(matches.size()) +
        " matches exceed ransac.max_observations = " + std::to_string(options_.max_observations));
  }
  matches_ = matches;
  MotionEstimate out;
  std::fill(mask_.begin(), mask_.end(), 0);
  out.inlier_mask = std::span<const std::uint8_t>(mask_.data(), matches.size());

  // Triangulate usable matches in both frames (Eq. 1 inverted: z = fu b / d).
  int n_usable = 0;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const StereoMatch& m = matches[i];
    const double d_prev = m.u_prev - m.ur_prev;
    const double d_cur = m.u_cur - m.ur_cur;
    if (!(d_prev >= options_.min_disparity_px) || !(d_cur >= options_.min_disparity_px)) continue;
    p_prev_[i] = camera_.triangulate(m.u_prev, m.v_prev, d_prev);
    p_cur_[i] = camera_.triangulate(m.u_cur, m.v_cur, d_cur);
    usable_[static_cast<std::size_t>(n_usable++)] = static_cast<int>(i);
  }
  n_usable_ = n_usable;
  out.num_usable = n_usable;
  if (n_usable < std::max(3, options_.min_inliers)) {
    return failedPrecondition(
        "ransac: only " + std::to_string(n_usable) +
        " usable matches (min_inliers = " + std::to_string(options_.min_inliers) + ")");
  }

  rng_.seed(seed);
  std::uniform_int_distribution<int> pick(0, n_usable - 1);
  int best_count = -1;
  double best_sq = 0.0;
  Isometry3 best_T = Isometry3::Identity();
  int needed = options_.max_iterations;
  int it = 0;
  for (; it < needed; ++it) {
    int s[3];
    s[0] = pick(rng_);
    do {
      s[1] = pick(rng_);
    } while (s[1] == s[0]);
    do {
      s[2] = pick(rng_);
    } while (s[2] == s[0] || s[2] == s[1]);
    Eigen::Matrix3d src;
    Eigen::Matrix3d dst;
    for (int j = 0; j < 3; ++j) {
      s[j] = usable_[static_cast<std::size_t>(s[j])];
      src.col(j) = p_prev_[static_cast<std::size_t>(s[j])];
      dst.col(j) = p_cur_[static_cast<std::size_t>(s[j])];
    }
    // Degenerate (near-collinear) samples give no unique rotation.
    const Eigen::Vector3d a = src.col(1) - src.col(0);
    const Eigen::Vector3d b = src.col(2) - src.col(0);
    if (a.cross(b).norm() <= 1e-3 * a.norm() * b.norm()) continue;
    // Closed-form hypothesis: Umeyama/Horn least-squares rigid fit p_cur = T p_prev on the three
    // triangulated pairs, then Gauss-Newton on the three points' stereo reprojection error, which
    // weights the far points' large depth errors correctly.
    Isometry3 T = Isometry3::Identity();
    T.matrix() = Eigen::umeyama(src, dst, false);
    if (!allFinite(T)) continue;
    if (!refine(T, std::span<const int>(s, 3), 3)) continue;
    double sq = 0.0;
    const int count = score(T, work_mask_, sq);
    if (count > best_count || (count == best_count && sq < best_sq)) {
      best_count = count;
      best_sq = sq;
      best_T = T;
      // Adaptive stop: N = log(1 - p) / log(1 - w^3) with w the best inlier ratio so far.
      const double w = static_cast<double>(count) / n_usable;
      const double w3 = w * w * w;
      if (w3 >= 1.0 - 1e-12) {
        needed = std::min(needed, it + 1);
      } else if (w3 > 1e-12) {
        const double n = std::log(1.0 - options_.confidence) / std::log(1.0 - w3);
        if (n < static_cast<double>(needed))
          needed = std::max(it + 1, static_cast<int>(std::ceil(n)));
      }
    }
  }
  out.hypotheses = it;
  if (best_count < options_.min_inliers) {
    return failedPrecondition("ransac: best hypothesis has " +
                              std::to_string(std::max(best_count, 0)) +
                              " inliers < min_inliers = " + std::to_string(options_.min_inliers));
  }

  // Refine on all inliers, re-select inliers with the refined pose, refine once more.
  Isometry3 T = best_T;
  score(T, best_mask_, best_sq);
  for (int round = 0; round < 2; ++round) {
    int n_in = 0;
    for (std::size_t i = 0; i < matches.size(); ++i) {
      if (best_mask_[i] != 0) inlier_idx_[static_cast<std::size_t>(n_in++)] = static_cast<int>(i);
    }
    Isometry3 T_ref = T;
    if (!refine(T_ref, std::span<const int>(inlier_idx_.data(), static_cast<std::size_t>(n_in)),
                options_.refine_iterations)) {
      break;
    }
    double sq = 0.0;
    const int count = score(T_ref, work_mask_, sq);
    if (count < options_.min_inliers) break;
    T = T_ref;
    std::swap(best_mask_, work_mask_);
    best_count = count;
    best_sq = sq;
  }
  if (!allFinite(T)) return failedPrecondition("ransac: non-finite pose");
  std::copy(best_mask_.begin(), best_mask_.begin() + static_cast<std::ptrdiff_t>(matches.size()),
            mask_.begin());
  out.T_k_km1 = T;
  out.num_inliers = best_count;
  out.inlier_rms_px = std::sqrt(best_sq / std::max(best_count, 1));
  return out;
}

}  // namespace sunvo::motion
