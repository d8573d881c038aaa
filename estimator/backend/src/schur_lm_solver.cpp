#include "sunvo/backend/schur_lm_solver.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace sunvo::backend {
namespace {

constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

double clampDiagonal(double h) {
  return std::clamp(h, kMinDiagonal, kMaxDiagonal);
}

// The loss' contribution 0.5 rho(s) and the corrector of the header: r <- r_scale r,
// J <- sqrt_rho1 (J - alpha_sq_norm r (r^T J)) with the uncorrected r.
struct Corrector {
  double cost = 0.0;
  double r_scale = 1.0;
  double sqrt_rho1 = 1.0;
  double alpha_sq_norm = 0.0;
};

Corrector correct(const ceres::LossFunction* loss, double sq_norm) {
  Corrector c;
  if (loss == nullptr) {
    c.cost = 0.5 * sq_norm;
    return c;
  }
  double rho[3];
  loss->Evaluate(sq_norm, rho);
  c.cost = 0.5 * rho[0];
  c.sqrt_rho1 = std::sqrt(std::max(rho[1], 0.0));
  c.r_scale = c.sqrt_rho1;
  if (sq_norm > 0.0 && rho[2] > 0.0 && rho[1] > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
    c.r_scale = c.sqrt_rho1 / (1.0 - alpha);
    c.alpha_sq_norm = alpha / sq_norm;
  }
  return c;
}

// Applies the corrector to m residual rows and a row-major m x cols Jacobian.
template <class R, class J>
void applyCorrector(const Corrector& c, R& r, J& jac) {
  if (c.alpha_sq_norm != 0.0) {
    const auto rTJ = (r.transpose() * jac).eval();
    jac = c.sqrt_rho1 * (jac - c.alpha_sq_norm * r * rTJ);
  } else {
    jac *= c.sqrt_rho1;
  }
  r *= c.r_scale;
}

// The stereo residual of stereo_residual.hpp (Eq. 1) in closed form, with its Jacobians in the
// solver's local coordinates.
//   p_k = C_k_b p_b + t_k_b = (x, y, z),  r = S (fu x/z + cu - u, fv y/z + cv - v, fu l/z - d),
//   S = diag(1/su, 1/sv, 1/sd).
// Local update of the rotation (EigenQuaternionManifold): q <- [cos|d|, sin|d| d/|d|] (x) q, a
// rotation by the vector 2 d applied on the left, so C_k_b <- Exp(2 d) C_k_b and
//   dp_k/dd = -2 [C_k_b p_b]x,  dp_k/dt = I,  dp_k/dp_b = C_k_b;
//   dr/dp_k = S [[fu/z, 0, -fu x/z^2], [0, fv/z, -fv y/z^2], [0, 0, -fu l/z^2]].
// At or behind the camera (z <= kMinDepth) r is the constant kBehindCameraResidual with zero
// derivatives, as in the Ceres functor. J_pose may be null (only r and J_p are then written).
void stereoResidual(const StereoModel& m, const StereoMeasurement& y, const double* q_k_b,
                    const double* t_k_b, const double* p_b, Eigen::Vector3d* r,
                    Eigen::Matrix<double, 3, 6>* J_pose, Eigen::Matrix3d* J_p) {
  const Eigen::Map<const Eigen::Quaterniond> C_k_b(q_k_b);
  const Eigen::Vector3d Cp = C_k_b * Eigen::Map<const Eigen::Vector3d>(p_b);
  const Eigen::Vector3d p_k = Cp + Eigen::Map<const Eigen::Vector3d>(t_k_b);
  if (!(p_k.z() > StereoResidual::kMinDepth)) {
    r->setConstant(StereoResidual::kBehindCameraResidual);
    if (J_pose != nullptr) J_pose->setZero();
    if (J_p != nullptr) J_p->setZero();
    return;
  }
  const double inv_z = 1.0 / p_k.z();
  const double fl = m.fu * m.baseline_m;
  (*r)(0) = m.sqrt_info_u * (m.fu * p_k.x() * inv_z + m.cu - y.u);
  (*r)(1) = m.sqrt_info_v * (m.fv * p_k.y() * inv_z + m.cv - y.v);
  (*r)(2) = m.sqrt_info_d * (fl * inv_z - y.d);
  if (J_p == nullptr) return;
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P(0, 0) = m.sqrt_info_u * m.fu * inv_z;
  P(0, 2) = -m.sqrt_info_u * m.fu * p_k.x() * inv_z * inv_z;
  P(1, 1) = m.sqrt_info_v * m.fv * inv_z;
  P(1, 2) = -m.sqrt_info_v * m.fv * p_k.y() * inv_z * inv_z;
  P(2, 2) = -m.sqrt_info_d * fl * inv_z * inv_z;
  J_p->noalias() = P * C_k_b.toRotationMatrix();
  if (J_pose == nullptr) return;
  Eigen::Matrix3d minus_2_skew;
  minus_2_skew << 0.0, 2.0 * Cp.z(), -2.0 * Cp.y(), -2.0 * Cp.z(), 0.0, 2.0 * Cp.x(), 2.0 * Cp.y(),
      -2.0 * Cp.x(), 0.0;
  J_pose->leftCols<3>().noalias() = P * minus_2_skew;
  J_pose->rightCols<3>() = P;
}

using RowMat34 = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
using RowMat33 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using RowMat43 = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;

}  // namespace

Status SchurLmSolver::init(int max_stereo, int max_landmarks, int max_generic) {
  if (max_stereo < 1 || max_landmarks < 1 || max_generic < 1) {
    return invalidArgument("SchurLmSolver: capacities must be >= 1");
  }
  max_stereo_ = max_stereo;
  max_landmarks_ = max_landmarks;
  max_generic_ = max_generic;
  const auto ns = static_cast<std::size_t>(max_stereo);
  const auto nl = static_cast<std::size_t>(max_landmarks);
  stereo_.assign(ns, Stereo{});
  lin_.assign(ns, StereoLin{});
  WV_.assign(ns, Mat6x3::Zero());
  landmarks_.assign(nl, Landmark{});
  p_cand_.assign(nl, Vec3::Zero());
  V_.assign(nl, Mat3::Zero());
  V_inv_.assign(nl, Mat3::Zero());
  g_l_.assign(nl, Vec3::Zero());
  dx_l_.assign(nl, Vec3::Zero());
  generic_.assign(static_cast<std::size_t>(max_generic), Generic{});
  n_poses_ = n_stereo_ = n_landmarks_ = n_generic_ = 0;
  return Status::ok();
}

Status SchurLmSolver::begin(int n_poses, std::span<double* const> q, std::span<double* const> t) {
  if (max_stereo_ == 0) return failedPrecondition("SchurLmSolver::begin before init");
  if (n_poses < 2 || n_poses > kMaxPoses || q.size() < static_cast<std::size_t>(n_poses) ||
      t.size() < static_cast<std::size_t>(n_poses)) {
    return invalidArgument("SchurLmSolver: " + std::to_string(n_poses) + " poses not in [2, " +
                           std::to_string(kMaxPoses) + "]");
  }
  n_poses_ = n_poses;
  for (int s = 0; s < n_poses; ++s) {
    q_[static_cast<std::size_t>(s)] = q[static_cast<std::size_t>(s)];
    t_[static_cast<std::size_t>(s)] = t[static_cast<std::size_t>(s)];
  }
  n_stereo_ = n_landmarks_ = n_generic_ = 0;
  n_extra_ = 0;
  extra_dim_ = 0;
  return Status::ok();
}

Status SchurLmSolver::addLandmark(double* p_b) {
  if (n_landmarks_ >= max_landmarks_) return invalidArgument("SchurLmSolver: too many landmarks");
  landmarks_[static_cast<std::size_t>(n_landmarks_++)] = Landmark{p_b, n_stereo_, n_stereo_};
  return Status::ok();
}

Status SchurLmSolver::addStereo(int slot, const StereoMeasurement* y,
                                const ceres::LossFunction* loss) {
  if (n_landmarks_ == 0) return failedPrecondition("SchurLmSolver: addStereo before addLandmark");
  if (model_ == nullptr) return failedPrecondition("SchurLmSolver: addStereo without a model");
  if (n_stereo_ >= max_stereo_) return invalidArgument("SchurLmSolver: too many stereo residuals");
  if (slot < 0 || slot >= n_poses_)
    return invalidArgument("SchurLmSolver: stereo slot out of range");
  stereo_[static_cast<std::size_t>(n_stereo_++)] = Stereo{y, loss, slot, n_landmarks_ - 1};
  landmarks_[static_cast<std::size_t>(n_landmarks_ - 1)].end = n_stereo_;
  return Status::ok();
}

int SchurLmSolver::extraIndex(const double* block) const {
  for (int i = 0; i < n_extra_; ++i) {
    if (extra_[static_cast<std::size_t>(i)] == block) return i;
  }
  return -1;
}

Status SchurLmSolver::addGeneric(const ceres::CostFunction* cost, const ceres::LossFunction* loss,
                                 std::span<const BlockRef> blocks) {
  if (n_generic_ >= max_generic_) return invalidArgument("SchurLmSolver: too many residuals");
  const auto& sizes = cost->parameter_block_sizes();
  if (blocks.empty() || blocks.size() > kMaxGenericBlocks || sizes.size() != blocks.size() ||
      cost->num_residuals() < 1 || cost->num_residuals() > kMaxGenericRows) {
    return invalidArgument("SchurLmSolver: residual blocks do not match its cost function");
  }
  Generic g{cost, loss, static_cast<int>(blocks.size()), {}};
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const BlockRef& b = blocks[i];
    const int want = b.kind == BlockRef::Kind::kRotation      ? 4
                     : b.kind == BlockRef::Kind::kTranslation ? 3
                                                              : sizes[i];
    if (sizes[i] != want) return invalidArgument("SchurLmSolver: block size mismatch");
    if (b.kind != BlockRef::Kind::kExtra && (b.slot < 0 || b.slot >= n_poses_)) {
      return invalidArgument("SchurLmSolver: residual slot out of range");
    }
    if (b.kind == BlockRef::Kind::kExtra) {
      if (b.extra == nullptr) return invalidArgument("SchurLmSolver: null extra block");
      if (extraIndex(b.extra) < 0) {
        if (n_extra_ >= kMaxExtraBlocks || extra_dim_ + sizes[i] > kMaxExtraDim) {
          return invalidArgument("SchurLmSolver: too many extra parameters");
        }
        const auto e = static_cast<std::size_t>(n_extra_++);
        extra_[e] = b.extra;
        extra_size_[e] = sizes[i];
        extra_offset_[e] = extra_dim_;
        extra_dim_ += sizes[i];
      }
    }
    g.blocks[i] = b;
  }
  generic_[static_cast<std::size_t>(n_generic_++)] = g;
  return Status::ok();
}

const double* SchurLmSolver::blockValue(const BlockRef& b, bool candidate) const {
  const auto s = static_cast<std::size_t>(b.slot);
  switch (b.kind) {
    case BlockRef::Kind::kRotation:
      return candidate && b.slot > 0 ? q_cand_[s].data() : q_[s];
    case BlockRef::Kind::kTranslation:
      return candidate && b.slot > 0 ? t_cand_[s].data() : t_[s];
    case BlockRef::Kind::kExtra:
      break;
  }
  const int e = extraIndex(b.extra);
  return candidate ? extra_cand_[static_cast<std::size_t>(e)].data() : b.extra;
}

int SchurLmSolver::blockOffset(const BlockRef& b) const {
  switch (b.kind) {
    case BlockRef::Kind::kRotation:
      return b.slot > 0 ? 6 * (b.slot - 1) : -1;
    case BlockRef::Kind::kTranslation:
      return b.slot > 0 ? 6 * (b.slot - 1) + 3 : -1;
    case BlockRef::Kind::kExtra:
      break;
  }
  return 6 * (n_poses_ - 1) + extra_offset_[static_cast<std::size_t>(extraIndex(b.extra))];
}

int SchurLmSolver::blockLocalSize(const BlockRef& b) const {
  if (b.kind != BlockRef::Kind::kExtra) return 3;
  return extra_size_[static_cast<std::size_t>(extraIndex(b.extra))];
}

bool SchurLmSolver::evaluateCost(bool candidate, double* cost) const {
  double sum = 0.0;
  for (int i = 0; i < n_stereo_; ++i) {
    const Stereo& st = stereo_[static_cast<std::size_t>(i)];
    const auto s = static_cast<std::size_t>(st.slot);
    const bool moved = candidate && st.slot > 0;
    const double* p_b = candidate ? p_cand_[static_cast<std::size_t>(st.landmark)].data()
                                  : landmarks_[static_cast<std::size_t>(st.landmark)].p;
    Vec3 r;
    stereoResidual(*model_, *st.y, moved ? q_cand_[s].data() : q_[s],
                   moved ? t_cand_[s].data() : t_[s], p_b, &r, nullptr, nullptr);
    sum += correct(st.loss, r.squaredNorm()).cost;
  }
  for (int i = 0; i < n_generic_; ++i) {
    const Generic& g = generic_[static_cast<std::size_t>(i)];
    std::array<const double*, kMaxGenericBlocks> params{};
    for (int b = 0; b < g.n_blocks; ++b) {
      params[static_cast<std::size_t>(b)] =
          blockValue(g.blocks[static_cast<std::size_t>(b)], candidate);
    }
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxGenericRows, 1> r(g.cost->num_residuals());
    if (!g.cost->Evaluate(params.data(), r.data(), nullptr)) return false;
    sum += correct(g.loss, r.squaredNorm()).cost;
  }
  *cost = sum;
  return std::isfinite(sum);
}

bool SchurLmSolver::linearize(double* cost) {
  dim_ = 6 * (n_poses_ - 1) + extra_dim_;
  H_cc_.setZero(dim_, dim_);
  g_c_.setZero(dim_);
  double sum = 0.0;
  RowMat43 plus_jac[kMaxPoses];
  for (int s = 1; s < n_poses_; ++s) {
    manifold_.PlusJacobian(q_[static_cast<std::size_t>(s)], plus_jac[s].data());
  }
  for (int l = 0; l < n_landmarks_; ++l) {
    const Landmark& lm = landmarks_[static_cast<std::size_t>(l)];
    Mat3 V = Mat3::Zero();
    Vec3 g = Vec3::Zero();
    for (int i = lm.first; i < lm.end; ++i) {
      const Stereo& st = stereo_[static_cast<std::size_t>(i)];
      StereoLin& lin = lin_[static_cast<std::size_t>(i)];
      const auto s = static_cast<std::size_t>(st.slot);
      Eigen::Matrix<double, 3, 9> J;
      Eigen::Matrix<double, 3, 6> J_pose;
      Mat3 J_p;
      stereoResidual(*model_, *st.y, q_[s], t_[s], lm.p, &lin.r, st.slot > 0 ? &J_pose : nullptr,
                     &J_p);
      if (st.slot > 0) {
        J.leftCols<6>() = J_pose;
      } else {
        J.leftCols<6>().setZero();
      }
      J.rightCols<3>() = J_p;
      const Corrector c = correct(st.loss, lin.r.squaredNorm());
      sum += c.cost;
      applyCorrector(c, lin.r, J);
      lin.J_pose = J.leftCols<6>();
      lin.J_p = J.rightCols<3>();
      V.noalias() += lin.J_p.transpose() * lin.J_p;
      g.noalias() += lin.J_p.transpose() * lin.r;
      if (st.slot > 0) {
        const int o = 6 * (st.slot - 1);
        H_cc_.block<6, 6>(o, o).noalias() += lin.J_pose.transpose() * lin.J_pose;
        g_c_.segment<6>(o).noalias() += lin.J_pose.transpose() * lin.r;
        lin.W = lin.J_pose.transpose() * lin.J_p;
      }
    }
    V_[static_cast<std::size_t>(l)] = V;
    g_l_[static_cast<std::size_t>(l)] = g;
  }
  for (int i = 0; i < n_generic_; ++i) {
    const Generic& gen = generic_[static_cast<std::size_t>(i)];
    const int m = gen.cost->num_residuals();
    std::array<const double*, kMaxGenericBlocks> params{};
    // Row-major global Jacobian of each block: m x (4 or extra size), at most 6 x 12.
    std::array<Eigen::Matrix<double, kMaxGenericRows, kMaxExtraDim, Eigen::RowMajor>,
               kMaxGenericBlocks>
        J_block;
    std::array<double*, kMaxGenericBlocks> jac{};
    for (int b = 0; b < gen.n_blocks; ++b) {
      const auto ub = static_cast<std::size_t>(b);
      params[ub] = blockValue(gen.blocks[ub], false);
      jac[ub] = blockOffset(gen.blocks[ub]) >= 0 ? J_block[ub].data() : nullptr;
    }
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxGenericRows, 1> r(m);
    if (!gen.cost->Evaluate(params.data(), r.data(), jac.data())) return false;
    // Dense local Jacobian over x_c.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxGenericRows, kMaxReducedDim> J;
    J.setZero(m, dim_);
    for (int b = 0; b < gen.n_blocks; ++b) {
      const auto ub = static_cast<std::size_t>(b);
      const BlockRef& ref = gen.blocks[ub];
      const int o = blockOffset(ref);
      if (o < 0) continue;
      const int global = static_cast<int>(gen.cost->parameter_block_sizes()[ub]);
      // The callee wrote an m x global row-major matrix at the start of the buffer; copied into
      // bounded storage so that no product below needs a heap temporary.
      const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, kMaxGenericRows,
                          kMaxExtraDim>
          Jg = Eigen::Map<
              const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
              J_block[ub].data(), m, global);
      if (ref.kind == BlockRef::Kind::kRotation) {
        J.middleCols(o, 3).noalias() = Jg * plus_jac[ref.slot];
      } else {
        J.middleCols(o, blockLocalSize(ref)) = Jg;
      }
    }
    const Corrector c = correct(gen.loss, r.squaredNorm());
    sum += c.cost;
    applyCorrector(c, r, J);
    H_cc_.noalias() += J.transpose() * J;
    g_c_.noalias() += J.transpose() * r;
  }
  *cost = sum;
  return std::isfinite(sum) && H_cc_.allFinite() && g_c_.allFinite();
}

bool SchurLmSolver::solveStep(double lambda, double* predicted) {
  // Reduced system S dx_c = b (header), built from the undamped H and the damping lambda D.
  S_ = H_cc_;
  for (int i = 0; i < dim_; ++i) S_(i, i) += lambda * clampDiagonal(H_cc_(i, i));
  VecR b = -g_c_;
  for (int l = 0; l < n_landmarks_; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    const Landmark& lm = landmarks_[ul];
    Mat3 Vd = V_[ul];
    for (int k = 0; k < 3; ++k) Vd(k, k) += lambda * clampDiagonal(V_[ul](k, k));
    bool invertible = false;
    double det = 0.0;
    Vd.computeInverseAndDetWithCheck(V_inv_[ul], det, invertible, 0.0);
    if (!invertible || !V_inv_[ul].allFinite()) return false;
    for (int i = lm.first; i < lm.end; ++i) {
      const Stereo& st = stereo_[static_cast<std::size_t>(i)];
      if (st.slot == 0) continue;
      Mat6x3& WV = WV_[static_cast<std::size_t>(i)];
      WV.noalias() = lin_[static_cast<std::size_t>(i)].W * V_inv_[ul];
      const int oi = 6 * (st.slot - 1);
      b.segment<6>(oi).noalias() += WV * g_l_[ul];
      for (int j = lm.first; j < lm.end; ++j) {
        const Stereo& sj = stereo_[static_cast<std::size_t>(j)];
        if (sj.slot == 0) continue;
        const int oj = 6 * (sj.slot - 1);
        S_.block<6, 6>(oi, oj).noalias() -= WV * lin_[static_cast<std::size_t>(j)].W.transpose();
      }
    }
  }
  ldlt_.compute(S_);
  if (ldlt_.info() != Eigen::Success) return false;
  dx_c_ = ldlt_.solve(b);
  if (!dx_c_.allFinite()) return false;

  // Back substitution and the predicted decrease 0.5 (-g^T dx + lambda dx^T D dx).
  double g_dx = g_c_.dot(dx_c_);
  double dDd = 0.0;
  for (int i = 0; i < dim_; ++i) dDd += clampDiagonal(H_cc_(i, i)) * dx_c_(i) * dx_c_(i);
  for (int l = 0; l < n_landmarks_; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    const Landmark& lm = landmarks_[ul];
    Vec3 rhs = -g_l_[ul];
    for (int i = lm.first; i < lm.end; ++i) {
      const Stereo& st = stereo_[static_cast<std::size_t>(i)];
      if (st.slot == 0) continue;
      rhs.noalias() -=
          lin_[static_cast<std::size_t>(i)].W.transpose() * dx_c_.segment<6>(6 * (st.slot - 1));
    }
    dx_l_[ul].noalias() = V_inv_[ul] * rhs;
    g_dx += g_l_[ul].dot(dx_l_[ul]);
    for (int k = 0; k < 3; ++k) {
      dDd += clampDiagonal(V_[ul](k, k)) * dx_l_[ul](k) * dx_l_[ul](k);
    }
  }
  *predicted = 0.5 * (-g_dx + lambda * dDd);
  return std::isfinite(*predicted);
}

void SchurLmSolver::makeCandidate() {
  for (int s = 1; s < n_poses_; ++s) {
    const auto us = static_cast<std::size_t>(s);
    const int o = 6 * (s - 1);
    manifold_.Plus(q_[us], dx_c_.data() + o, q_cand_[us].data());
    for (int k = 0; k < 3; ++k)
      t_cand_[us][static_cast<std::size_t>(k)] = t_[us][k] + dx_c_(o + 3 + k);
  }
  for (int e = 0; e < n_extra_; ++e) {
    const auto ue = static_cast<std::size_t>(e);
    const int o = 6 * (n_poses_ - 1) + extra_offset_[ue];
    for (int k = 0; k < extra_size_[ue]; ++k) {
      extra_cand_[ue][static_cast<std::size_t>(k)] = extra_[ue][k] + dx_c_(o + k);
    }
  }
  for (int l = 0; l < n_landmarks_; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    p_cand_[ul] = Eigen::Map<const Vec3>(landmarks_[ul].p) + dx_l_[ul];
  }
}

void SchurLmSolver::acceptCandidate() {
  for (int s = 1; s < n_poses_; ++s) {
    const auto us = static_cast<std::size_t>(s);
    std::copy(q_cand_[us].begin(), q_cand_[us].end(), q_[us]);
    std::copy(t_cand_[us].begin(), t_cand_[us].end(), t_[us]);
  }
  for (int e = 0; e < n_extra_; ++e) {
    const auto ue = static_cast<std::size_t>(e);
    std::copy_n(extra_cand_[ue].begin(), extra_size_[ue], extra_[ue]);
  }
  for (int l = 0; l < n_landmarks_; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    Eigen::Map<Vec3>(landmarks_[ul].p) = p_cand_[ul];
  }
}

Expected<SchurLmSummary> SchurLmSolver::solve(const Options& options) {
  if (n_poses_ < 2) return failedPrecondition("SchurLmSolver::solve before begin");
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  SchurLmSummary out;
  double cost = 0.0;
  if (!linearize(&cost)) return failedPrecondition("SchurLmSolver: non-finite initial cost");
  out.initial_cost = cost;
  double radius = kInitialRadius;
  double decrease_factor = 2.0;
  bool relinearize = false;
  while (out.iterations < options.max_iterations && elapsed() < options.max_time_s) {
    if (relinearize) {
      if (!linearize(&cost)) break;  // keep the last accepted state
      relinearize = false;
    }
    double g_max = g_c_.size() > 0 ? g_c_.cwiseAbs().maxCoeff() : 0.0;
    for (int l = 0; l < n_landmarks_; ++l) {
      g_max = std::max(g_max, g_l_[static_cast<std::size_t>(l)].cwiseAbs().maxCoeff());
    }
    if (g_max <= kGradientTolerance) {
      out.converged = true;
      break;
    }
    ++out.iterations;
    double predicted = 0.0;
    double new_cost = 0.0;
    const bool stepped = solveStep(1.0 / radius, &predicted);
    if (stepped) makeCandidate();
    if (stepped && predicted > 0.0 && evaluateCost(true, &new_cost)) {
      // Step size test relative to the parameters (x: the current poses, extras and landmarks).
      double x_sq = 0.0;
      for (int s = 1; s < n_poses_; ++s) {
        x_sq +=
            Eigen::Map<const Eigen::Vector3d>(t_[static_cast<std::size_t>(s)]).squaredNorm() + 1.0;
      }
      for (int l = 0; l < n_landmarks_; ++l) {
        x_sq += Eigen::Map<const Vec3>(landmarks_[static_cast<std::size_t>(l)].p).squaredNorm();
      }
      double dx_sq = dx_c_.squaredNorm();
      for (int l = 0; l < n_landmarks_; ++l)
        dx_sq += dx_l_[static_cast<std::size_t>(l)].squaredNorm();
      if (std::sqrt(dx_sq) <= kParameterTolerance * (std::sqrt(x_sq) + kParameterTolerance)) {
        out.converged = true;
        break;
      }
      // A step, taken or not, that changes the cost by less than the tolerance ends the solve
      // at the current state (as Ceres does).
      if (std::abs(cost - new_cost) <= kFunctionTolerance * cost) {
        out.converged = true;
        break;
      }
      const double rho = (cost - new_cost) / predicted;
      if (rho > kMinRelativeDecrease) {
        acceptCandidate();
        ++out.accepted;
        cost = new_cost;
        radius =
            std::min(kMaxRadius, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3)));
        decrease_factor = 2.0;
        relinearize = true;
        continue;
      }
    }
    radius /= decrease_factor;
    decrease_factor *= 2.0;
    if (radius < kMinRadius) break;
  }
  out.final_cost = cost;
  out.time_s = elapsed();
  return out;
}

}  // namespace sunvo::backend
