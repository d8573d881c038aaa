#pragma once
// Puts sun measurements into the bundle window (the paper's Eq. 3).
//
// For a frame k with a measurement s_k, the window's hook is called during solve(). With the
// window's fixed base pose T_w_b and the current estimate C_k_b it predicts the sun in camera k,
//   s_hat_k = C_k_b C_b_w s_w,
// gates the measurement against that prediction (sun_gate.hpp), and when accepted adds the 3-D
// or azimuth-only residual (sun_residual.hpp) on the rotation block of slot k. The decision is
// made once per measurement (at its first solve) and counted. s_w is given per measurement in
// the VO world frame, computed per frame by the caller (the sun moves ~0.25 deg/min).
//
// Two ways to use an accepted measurement:
//  - paper (estimate_base_attitude = false): C_b_w is fixed and the residual acts on C_k_b only.
//    The stereo terms pin the relative rotation stiffly, so a window removes only a small share
//    of an accumulated attitude error (measured in tests/sunfusion: ~7 % per window).
//  - base attitude (default): the residual also acts on a correction delta_b of the base's world
//    attitude (C_w_b,true = C_w_b Exp(delta_b)). The attitude error of VO is kept as a world-frame
//    rotation vector dtheta_w = C_w_b delta_b (C_w_c,true = Exp(dtheta_w) C_w_c) with covariance
//    P in the world frame, so that it stays meaningful while the base slides and turns. P starts
//    at initial_attitude_sigma_deg and grows by q_theta^2 per frame (a random walk,
//    attitude_drift_deg_per_frame). A solve with accepted measurements carries the prior
//    delta_b ~ N(0, C_b_w P C_w_b) jointly with the stereo terms; afterwards the measurements'
//    information J^T J about delta_b (J = d whitened residual / d delta_b at the solution) is
//    rotated into the world, P <- (P^-1 + C_w_b J^T J C_b_w)^-1, and the base is corrected by
//    Exp(delta_b). Each measurement is used in one solve only, so its information is not counted
//    twice.
//  - Adaptive q_theta (adaptive_drift): how fast VO's attitude drifts differs by an order of
//    magnitude between routes (docs/experiment.md). With it on, q_theta follows the innovations:
//    one log-step up when a measurement's r^T S^-1 r exceeds the chi-square median of its rows,
//    one down otherwise, within [min, max]; an outlier moves q_theta by one step only.
//  - Innovation gate: besides the fixed gate of sun_gate.hpp, with innovation_gate_chi2 > 0 a
//    measurement is rejected when its whitened innovation r (at delta = 0) has
//    r^T (J P_b J^T + I)^-1 r above that bound: once the filter is confident, shadow flips and
//    outliers that the wide cosine gate lets in are refused.
//
// Nothing here allocates per frame except the cost functions of an accepted measurement (every
// fifth frame by default), which live until the next solve.

#include <ceres/loss_function.h>

#include <array>
#include <memory>
#include <optional>

#include "sunvo/backend/bundle_window.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::sunfusion {

struct SunObservation {
  SunMeasurement measurement;                        // in camera k (k = measurement.sequence)
  Eigen::Vector3d sun_w = Eigen::Vector3d::UnitZ();  // unit vector toward the sun, VO world frame
};

struct SunFusionOptions {
  SunGateOptions gate;
  // Unit vector "up" in the VO world frame, for the sun-elevation gate: ENU (0, 0, 1); a KITTI
  // camera-0 world has up = (0, -1, 0).
  Eigen::Vector3d world_up = Eigen::Vector3d::UnitZ();
  // Robust loss on the whitened sun residual: Cauchy scale in sigmas, (0, 100]; 0 = no loss.
  double loss_scale = 0.0;
  // Estimate a correction of the base's world attitude (see above); false = the paper's form.
  bool estimate_base_attitude = true;
  double initial_attitude_sigma_deg = 1.0;  // deg, (0, 45]: first pose's attitude std
  // deg, [0, 5]: random-walk std growth of the world attitude per frame (q_theta); with
  // adaptive_drift the starting value.
  double attitude_drift_deg_per_frame = 0.05;
  // Adapt q_theta to the innovations (see the header comment), within [min, max] deg/frame. On by
  // default: a fixed 0.2 deg/frame gains more where VO drifts fast (real 0020 tracks) but makes
  // noisy sources far worse where VO drifts little (docs/experiment.md, ablations).
  bool adaptive_drift = true;
  double min_drift_deg_per_frame = 0.002;  // deg/frame, [0, max]
  double max_drift_deg_per_frame = 0.5;    // deg/frame, [min, 5]
  double drift_adaptation_rate = 0.1;      // (0, 1]: log-step of q_theta per measurement
  // Innovation gate bound on r^T S^-1 r, [0, 1e6]; 0 = off. 16.3 = chi-square 3 dof, 99.9 %.
  double innovation_gate_chi2 = 16.3;

  Status validate() const;
};

class SunWindowTerm {
 public:
  Status init(const SunFusionOptions& options);
  // Installs this term as the window's pose-residual hook.
  void attach(backend::BundleWindow& window);
  // Measurement for a frame that is about to be added to the window (or already is).
  void addObservation(const SunObservation& observation);

  const GateCounters& counters() const { return counters_; }
  // Result of the gate for the last measurement decided (for logs and the sun thread).
  std::optional<GateResult> lastDecision() const { return last_decision_; }
  // Current uncertainty (rad^2) of the VO world attitude, world frame (base-attitude mode).
  const Eigen::Matrix3d& attitudeCovariance() const { return P_; }
  // The attitude random walk q_theta in use, deg/frame (adapted when adaptive_drift).
  double driftDegPerFrame() const { return drift_deg_per_frame_; }

 private:
  struct Pending {
    SunObservation obs;
    bool decided = false;
    bool accepted = false;
    bool consumed = false;  // used in a base-attitude solve already
    std::unique_ptr<ceres::CostFunction> cost;
  };
  Status onSolve(backend::BundleWindow& window);
  void onSolved(backend::BundleWindow& window);
  // Covariance propagation over `frames` new frames.
  void propagate(double frames);
  // Whitened residual and its Jacobian wrt delta_b of a sun cost at (C_k_b, delta_b); m rows.
  static bool evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                         const double* delta_b, Eigen::Vector3d* r,
                         Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d, int* m);
  // r^T (J P_b J^T + I)^-1 r of a measurement at delta_b = 0 (innovation gate); dof = rows of r.
  double innovationSq(const Isometry3& T_k_b, const Eigen::Vector3d& sun_b, const SunMeasurement& m,
                      const Eigen::Matrix3d& P_b, int* dof) const;
  // One adaptation step of q_theta from a normalised innovation squared with dof rows.
  void adaptDrift(double nis, int dof);

  SunFusionOptions options_;
  std::unique_ptr<ceres::LossFunction> loss_;
  std::array<Pending, backend::BundleWindow::kMaxWindowSize> pending_;  // ring by sequence
  std::array<bool, backend::BundleWindow::kMaxWindowSize> used_{};
  GateCounters counters_;
  std::optional<GateResult> last_decision_;
  // Base-attitude mode state.
  std::array<double, 3> delta_{0.0, 0.0, 0.0};   // delta_b of the current solve
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Zero();  // of dtheta_w, world frame, rad^2
  double drift_deg_per_frame_ = 0.0;             // q_theta in use, deg/frame (adapted)
  std::optional<std::uint64_t> last_sequence_;
  std::unique_ptr<ceres::CostFunction> prior_cost_;
  std::array<int, backend::BundleWindow::kMaxWindowSize> used_in_solve_{};  // ring indices
  int num_used_ = 0;
};

}  // namespace sunvo::sunfusion
