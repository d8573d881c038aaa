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
//  - base attitude (default): the residual also acts on a correction delta of the base's world
//    attitude, with a prior delta ~ N(0, P). P is the attitude uncertainty accumulated by VO: it
//    starts at initial_attitude_sigma_deg and grows by attitude_drift_deg_per_frame^2 per frame
//    (a random walk), and after each solve shrinks with the information of the sun residuals
//    (P <- (P^-1 + sum J^T J)^-1, J = d(whitened residual)/d(delta) at the solution). After a
//    successful solve the window's base attitude is corrected by Exp(delta). Each measurement is
//    used in one solve only, so its information is not counted twice.
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
  // deg, [0, 5]: random-walk std growth per frame; 0.2 matched the real 0020 tracks best
  // (sweep 0.01..0.5 in docs/experiment.md)
  double attitude_drift_deg_per_frame = 0.2;

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
  // Current attitude uncertainty P (rad^2) of the VO world attitude (base-attitude mode).
  const Eigen::Matrix3d& attitudeCovariance() const { return P_; }

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

  SunFusionOptions options_;
  std::unique_ptr<ceres::LossFunction> loss_;
  std::array<Pending, backend::BundleWindow::kMaxWindowSize> pending_;  // ring by sequence
  std::array<bool, backend::BundleWindow::kMaxWindowSize> used_{};
  GateCounters counters_;
  std::optional<GateResult> last_decision_;
  // Base-attitude mode state.
  std::array<double, 3> delta_{0.0, 0.0, 0.0};
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Zero();
  std::optional<std::uint64_t> last_sequence_;
  std::unique_ptr<ceres::CostFunction> prior_cost_;
  std::array<int, backend::BundleWindow::kMaxWindowSize> used_in_solve_{};  // ring indices
  int num_used_ = 0;
};

}  // namespace sunvo::sunfusion
