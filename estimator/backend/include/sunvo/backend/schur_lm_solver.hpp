#pragma once
// A fixed-memory Levenberg-Marquardt solver for the bundle window, with the landmarks eliminated
// by the Schur complement.
//
// Why not ceres::Solve: Ceres builds its program, evaluator and linear solver on every call
// (≈ 15 500 heap allocations per frame of the image pipeline, docs/benchmarks.md) and its
// general sparse machinery costs more than the two-frame problem itself. This solver keeps every
// buffer from init() and allocates nothing per solve. It evaluates the stereo residuals (most of
// the work) in closed form, with the same formula as the Ceres functor, and every other residual
// (motion prior, the sun's) through its ceres::CostFunction; losses are ceres::LossFunction and
// the rotation update is EigenQuaternionManifold's, so both solvers minimise the same cost.
//
// Unknowns. Pose slot s >= 1 (slot 0 is the gauge, constant): q_k_b (4, local update
// q <- [cos|d|, sin|d| d/|d|] (x) q as EigenQuaternionManifold, a rotation by 2 d) and t_k_b (3);
// caller blocks ("extra", e.g. the sun's base-attitude correction, Euclidean); landmarks p_b (3
// each). The reduced ("camera") vector x_c = [dtheta_1 dt_1 ... dtheta_{n-1} dt_{n-1} extra...] has
// at most kMaxReducedDim rows.
//
// One iteration, at the current linearisation (J, r whitened and robustified):
//   H = J^T J, g = J^T r, D = clamp(diag H, 1e-6, 1e32), lambda = 1 / radius;
//   per landmark l: V_l = H_ll + lambda D_ll (3x3), W_l = H_cl;
//   S = H_cc + lambda D_cc - sum_l W_l V_l^-1 W_l^T,   b = -g_c + sum_l W_l V_l^-1 g_l;
//   S dx_c = b (LDLT),  dx_l = V_l^-1 (-g_l - W_l^T dx_c).
// Predicted decrease of the model 0.5 |r + J dx|^2, using (H + lambda D) dx = -g:
//   m(0) - m(dx) = -g^T dx - 0.5 dx^T H dx = 0.5 (-g^T dx + lambda dx^T D dx).
// Gain ratio rho = (cost - cost(x [+] dx)) / predicted. rho > 1e-3: accept, radius /=
// max(1/3, 1 - (2 rho - 1)^3), v = 2; else radius /= v, v *= 2 (Nielsen's rule, as Ceres).
// Robust loss rho(s), s = |r|^2: r and J are scaled as Ceres' corrector does (Triggs et al.):
//   sqrt(rho') when rho'' <= 0, else with alpha = 1 - sqrt(1 + 2 s rho'' / rho'):
//   r <- sqrt(rho') / (1 - alpha) r,  J <- sqrt(rho') (I - alpha r r^T / s) J.
// Cost = 0.5 sum rho(|r_i|^2) (Ceres' convention). Stops after max_iterations (accepted and
// rejected steps both count, as in Ceres), at the time limit, or when a step's relative cost change
// (< 1e-6), the gradient (max-norm < 1e-10) or the step (< 1e-8 relative) is small.

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sunvo/backend/stereo_residual.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::backend {

struct SchurLmSummary {
  int iterations = 0;  // linear solves (accepted + rejected steps)
  int accepted = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double time_s = 0.0;
  bool converged = false;  // a tolerance was met (else iteration or time limit)
};

class SchurLmSolver {
 public:
  static constexpr int kMaxPoses = 8;          // window slots, slot 0 constant
  static constexpr int kMaxExtraBlocks = 4;    // distinct caller blocks per solve
  static constexpr int kMaxExtraDim = 12;      // their summed sizes
  static constexpr int kMaxGenericRows = 8;    // rows of one non-stereo residual
  static constexpr int kMaxGenericBlocks = 5;  // parameter blocks of one non-stereo residual
  static constexpr int kMaxReducedDim = 6 * (kMaxPoses - 1) + kMaxExtraDim;

  // Where a non-stereo residual's parameter block lives.
  struct BlockRef {
    enum class Kind { kRotation, kTranslation, kExtra };
    Kind kind = Kind::kRotation;
    int slot = 0;             // kRotation / kTranslation
    double* extra = nullptr;  // kExtra: caller-owned, Euclidean
  };

  // Capacities: stereo residuals, landmarks and non-stereo residuals per solve.
  Status init(int max_stereo, int max_landmarks, int max_generic);

  // Starts a problem over n_poses pose slots (q: 4 doubles x y z w, t: 3), slot 0 constant.
  // Landmarks and residuals added afterwards must stay valid until solve() returns.
  Status begin(int n_poses, std::span<double* const> q, std::span<double* const> t);
  // A landmark p_b (3 doubles, updated in place); its stereo residuals follow it (addStereo).
  Status addLandmark(double* p_b);
  // The stereo model (intrinsics, baseline, measurement weights) of every stereo residual; it
  // must outlive the solves.
  void setStereoModel(const StereoModel* model) { model_ = model; }
  // The stereo residual of stereo_residual.hpp (Eq. 1, evaluated here in closed form) of
  // measurement *y (valid until solve() returns) over (q_slot, t_slot, p_b) of the landmark added
  // last.
  Status addStereo(int slot, const StereoMeasurement* y, const ceres::LossFunction* loss);
  // Any other residual: blocks in the cost function's order (rows <= kMaxGenericRows).
  Status addGeneric(const ceres::CostFunction* cost, const ceres::LossFunction* loss,
                    std::span<const BlockRef> blocks);

  struct Options {
    int max_iterations = 10;
    double max_time_s = 0.05;
  };
  // Minimises; on return the poses, landmarks and extra blocks hold the best accepted estimate.
  Expected<SchurLmSummary> solve(const Options& options);

  int numLandmarks() const { return n_landmarks_; }
  int numStereo() const { return n_stereo_; }
  int numGeneric() const { return n_generic_; }

 private:
  using Mat6x3 = Eigen::Matrix<double, 6, 3>;
  using Mat3 = Eigen::Matrix3d;
  using Vec3 = Eigen::Vector3d;
  using MatR =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxReducedDim, kMaxReducedDim>;
  using VecR = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxReducedDim, 1>;

  struct Stereo {
    const StereoMeasurement* y;
    const ceres::LossFunction* loss;
    int slot;
    int landmark;
  };
  struct Landmark {
    double* p;
    int first;  // first stereo residual
    int end;
  };
  struct Generic {
    const ceres::CostFunction* cost;
    const ceres::LossFunction* loss;
    int n_blocks;
    std::array<BlockRef, kMaxGenericBlocks> blocks;
  };
  // Per stereo residual at the linearisation point: J wrt (dtheta, dt) of its slot and wrt p.
  struct StereoLin {
    Eigen::Matrix<double, 3, 6> J_pose;
    Mat3 J_p;
    Vec3 r;
    Mat6x3 W;  // J_pose^T J_p (slot > 0)
  };

  // Cost at the current (candidate = false) or candidate state; false if not finite.
  bool evaluateCost(bool candidate, double* cost) const;
  // Fills H_cc_, g_c_, V_/g_l_/lin_ at the current state; returns the cost.
  bool linearize(double* cost);
  bool solveStep(double lambda, double* predicted);
  void makeCandidate();
  void acceptCandidate();
  int extraIndex(const double* block) const;
  const double* blockValue(const BlockRef& b, bool candidate) const;
  int blockOffset(const BlockRef& b) const;  // offset in x_c, -1 when constant
  int blockLocalSize(const BlockRef& b) const;

  int max_stereo_ = 0, max_landmarks_ = 0, max_generic_ = 0;
  int n_poses_ = 0;
  std::array<double*, kMaxPoses> q_{};
  std::array<double*, kMaxPoses> t_{};
  std::array<std::array<double, 4>, kMaxPoses> q_cand_{};
  std::array<std::array<double, 3>, kMaxPoses> t_cand_{};
  int n_extra_ = 0;
  int extra_dim_ = 0;
  std::array<double*, kMaxExtraBlocks> extra_{};
  std::array<int, kMaxExtraBlocks> extra_size_{};
  std::array<int, kMaxExtraBlocks> extra_offset_{};
  std::array<std::array<double, kMaxExtraDim>, kMaxExtraBlocks> extra_cand_{};

  std::vector<Stereo> stereo_;
  std::vector<StereoLin> lin_;
  std::vector<Mat6x3> WV_;  // W (H_ll + lambda D)^-1 per stereo residual
  std::vector<Landmark> landmarks_;
  std::vector<Vec3> p_cand_;
  std::vector<Mat3> V_;      // H_ll (undamped) per landmark
  std::vector<Mat3> V_inv_;  // (H_ll + lambda D_ll)^-1
  std::vector<Vec3> g_l_;
  std::vector<Vec3> dx_l_;
  std::vector<Generic> generic_;
  int n_stereo_ = 0, n_landmarks_ = 0, n_generic_ = 0;

  int dim_ = 0;  // rows of x_c
  MatR H_cc_;
  VecR g_c_;
  VecR dx_c_;
  MatR S_;
  Eigen::LDLT<MatR> ldlt_;
  ceres::EigenQuaternionManifold manifold_;
  const StereoModel* model_ = nullptr;
};

}  // namespace sunvo::backend
