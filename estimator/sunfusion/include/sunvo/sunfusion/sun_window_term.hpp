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
//  - Adapting q_theta: how fast VO's attitude drifts differs by an order of magnitude between
//    routes (docs/experiment.md), and a sun source with 15-20 deg errors can only help where
//    VO's attitude error has grown beyond what its averaged measurements resolve. Two rules:
//    * kPersistence (default): a drift shows as innovations that keep pointing the same way;
//      noise does not. Each accepted measurement adds its world-frame information H^T H and its
//      whitened innovation H^T w r (H = d r / d dtheta_w at delta = 0, w a Huber weight) to
//      exponentially forgotten sums I and g. The statistic T = g^T I^+ g is chi-square with
//      rank(I) dof while the filter explains the innovations; q_theta takes a large log-step up
//      when T exceeds the chi-square quantile of rank(I) dof at 1 - persistence_false_alarm and
//      a small one down otherwise. The false-alarm rate times the step up must stay well below
//      the step down, so that q_theta sinks to its minimum (the sun barely moves VO) under noise
//      alone and rises only when the evidence of a drift accumulates, up to
//      max_drift_deg_per_frame.
//      With split_drift_by_gravity (default) the walk has two sizes: q_tilt on the plane normal to
//      world_up, q_heading along it (P += N (q_tilt^2 (I - u u^T) + q_heading^2 u u^T)). Each
//      steps with the channel that measures it: q_heading on sun measurements only, on the test of
//      sums of the sun's measurements alone, up to max_drift_deg_per_frame; q_tilt, once a
//      vertical measurement is in the sums, on the vertical channel's measurements only, on the
//      tilt's part of the test of all channels' sums (T_t = e_t^T C^+ e_t, e_t and C the tilt
//      components of I^+ g and I^+; persistence_statistic.hpp), up to
//      vertical_max_drift_deg_per_frame, and the sun's answers then add to those sums without
//      forgetting them (they forget on the cue's answers); or, with vertical_drift_adaptation
//      kEvidence, q_tilt stays at its floor and the cue's evidence widens P's tilt part; or, with
//      kLikelihood (the default), q_tilt is what a bank of tilt filters finds most likely; with
//      heading_drift_adaptation kLikelihood, once the cue measures, q_heading is what a bank fed
//      the sun's answers finds most likely (the persistence test cannot fire on a source far
//      better than it reports once the cue takes the tilt out of its innovations). A
//      precise "up" that evidences a tilt drift thus no longer widens the heading, which a
//      12-20 deg sun would then pull around; and a sun beside the "up" neither dilutes the
//      tilt's test, nor holds its walk to an image estimator's low cap, nor steps it a second
//      time per frame, nor shortens its memory (measured: docs/vertical.md). Without vertical
//      measurements both are the same q_theta.
//    * kInnovationMedian: one log-step up when a measurement's r^T S^-1 r exceeds the chi-square
//      median of its rows, one down otherwise. With a correct R_s and P << R_s this rule walks
//      at random, and outliers push it up: kept for comparison (docs/experiment.md).
//    * kEvidence (covariance matching): q_theta stays at min_drift_deg_per_frame, and P is
//      made to cover the error the measurements evidence. The sums I and g are kept consistent
//      with the estimate (after a correction c_w, g <- g - I c_w, so they describe the error that
//      is left); they forget by evidence_forgetting. Along each eigen-direction v of I with
//      eigenvalue l of at least a tenth of the largest, e = v^T g / l estimates the
//      remaining world attitude error with variance tau/l (tau = evidence_correlation, the
//      source's error correlation length in measurements); when |e| > evidence_sigmas sqrt(tau/l),
//      P grows by (e^2 - v^T P v) v v^T where that is positive. With R_s >> P a single
//      innovation cannot tell P is too small (docs/experiment.md, measured), about 50 of them can.
//  - Correction gate: with max_correction_deg > 0 a measurement whose predicted correction
//    |P_b J^T S^-1 r| exceeds that bound is refused (kRejectedCorrection) and counted.
//  - Innovation gate: besides the fixed gate of sun_gate.hpp, with innovation_gate_chi2 > 0 a
//    measurement is rejected when its whitened innovation r (at delta = 0) has
//    r^T (J P_b J^T + I)^-1 r above that bound: once the filter is confident, shadow flips and
//    outliers that the wide cosine gate lets in are refused.
//
//  - Correlated sun errors (sun_bias_sigma_deg > 0): an image estimator is often wrong the same
//    way for a whole street (measured: the real Sun-CNN on rendered drives, +2 ... +8 deg for 250
//    frames). Its azimuth error is then modelled as a state b, a turn of the measured sun about
//    the camera's y axis (sun_residual.hpp), with a first-order Gauss-Markov prior of stationary
//    std sun_bias_sigma_deg and correlation length sun_bias_length_frames:
//      b <- phi b, P_bb <- phi^2 P_bb + (1 - phi^2) sigma_b^2, P_theta_b <- phi P_theta_b,
//      phi = exp(-frames / length).
//    b is estimated jointly with the base correction (a 4x4 prior on (delta_b, db), the sun
//    residuals on both, and the 4x4 information update afterwards). A rotation of the heading and
//    a constant azimuth error look the same in one image (both turn the sun about the vertical of
//    a level camera); they differ in time only: VO's heading error stays, b decorrelates. So the
//    filter follows a persistent offset no further than the heading walk makes plausible against
//    sigma_b, and it learns the heading from the average over many stretches. The innovation,
//    the gates and the persistence test use the prediction turned by b_hat.
//  - Correlated errors of the vertical cue (vertical_bias_sigma_deg > 0): the cue can be wrong by
//    the same tenth of a degree in pitch for a whole drive (measured on rendered drives,
//    docs/vertical.md), and VO's tilt drift is of that size, so a filter that takes its answers
//    as independent converges onto the bias. The bias is a state c = (c_x, c_z), a turn of the
//    measured up about the camera's x and z axes (turnAboutCameraXZ), Gauss-Markov as b with its
//    own std and length. It is told from VO's tilt error by the route's turns: c stays in the
//    camera, VO's error stays in the world (dtheta_w), so the camera sees that error turn with the
//    heading and the bias not. On a straight drive the two are one, and the prior splits them.
//    The augmented state (dtheta_w, b, c) has one covariance (rows of a bias that is not a state
//    are zero) and the same joint prior and information update.
//
// A second channel of the same form: the camera's "up" measured from the images (the vertical
// vanishing point, estimator/vertical) is a known world direction (world_up) seen in camera k,
// exactly like the sun; addVertical() puts it through its own gate (vertical_gate) and the same
// innovation and correction gates, residual, P and drift adaptation, counted apart
// (verticalCounters()). One sun direction leaves the rotation about the sun axis free; "up"
// fixes roll and pitch, so the two together observe the whole attitude. Where the world's up is
// not known (a world that is the first camera), world_up_alignment_frames > 0 measures it from
// the channel's first answers before any is fused (world_up_alignment.hpp); where it is known but
// the start attitude's tilt is not (a rover), the same answers measure that tilt error, which the
// caller removes by turning VO's world (world_up_alignment_use kStartTilt, takeStartLevelling).
//
// Nothing here allocates per frame: init() builds every cost function a slot of the window can
// need (3-D and azimuth-only sun, in the form the options ask for, and the priors), and a
// measurement only writes its numbers into them.

#include <ceres/loss_function.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "sunvo/backend/bundle_window.hpp"
#include "sunvo/sunfusion/sun_fusion_options.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"
#include "sunvo/sunfusion/sun_residual.hpp"
#include "sunvo/sunfusion/walk_bank.hpp"
#include "sunvo/sunfusion/world_up_alignment.hpp"

namespace sunvo::sunfusion {

struct SunObservation {
  SunMeasurement measurement;                        // in camera k (k = measurement.sequence)
  Eigen::Vector3d sun_w = Eigen::Vector3d::UnitZ();  // unit vector toward the sun, VO world frame
};

class SunWindowTerm {
 public:
  Status init(const SunFusionOptions& options);
  // Installs this term as the window's pose-residual hook.
  void attach(backend::BundleWindow& window);
  // Measurement for a frame that is about to be added to the window (or already is).
  void addObservation(const SunObservation& observation);
  // The camera's "up" for a frame, as a direction observation: measurement.sun_c = up in camera
  // k, sigma its 1-sigma angle (rad). observation.sun_w is not read: the world's up is worldUp().
  void addVertical(const SunObservation& observation);
  // The world's up the vertical channel uses: options.world_up, or once aligned
  // (world_up_alignment_frames > 0, kWorldUp) its estimate; and the alignment's state (with
  // kStartTilt its estimate measured the start's tilt error: tiltDeg()).
  const Eigen::Vector3d& worldUp() const {
    return options_.levelsStartTilt() ? options_.world_up : world_up_.up();
  }
  const WorldUpAlignment& worldUpAlignment() const { return world_up_; }
  // kStartTilt, called before frame `sequence` is processed: once the alignment is done (the
  // frame is past its frames and enough answers were taken), the tilt error its answers measure
  // (what the filter, which fused them too, left of the start's error) is judged against the
  // mean's sigma. Where it is significant (|e|^2 > kStartTiltChi2 sigma^2), the world-frame
  // rotation vector e (rad) by which the caller must turn VO's world poses, C_w_c <- Exp(e)
  // C_w_c, and the positions built since the first frame about it; the tilt part of the attitude
  // covariance becomes the estimate's. Given once; nullopt otherwise.
  std::optional<Eigen::Vector3d> takeStartLevelling(std::uint64_t sequence);
  // The start's tilt was judged (startTiltJudged) and removed (startLevelled); the measured tilt
  // is worldUpAlignment().tiltDeg(), its sigma worldUpAlignment().sigma().
  bool startTiltJudged() const { return start_decided_; }
  bool startLevelled() const { return levelled_; }

  const GateCounters& counters() const { return counters_; }
  const GateCounters& verticalCounters() const { return vertical_counters_; }
  // Result of the gate for the last measurement decided (for logs and the sun thread).
  std::optional<GateResult> lastDecision() const { return last_decision_; }
  // Current uncertainty (rad^2) of the VO world attitude, world frame (base-attitude mode).
  Eigen::Matrix3d attitudeCovariance() const { return Pa_.topLeftCorner<3, 3>(); }
  // The attitude random walk q_theta in use, deg/frame (adapted unless kFixed); with
  // split_drift_by_gravity the larger of the tilt's and the heading's, given apart below.
  double driftDegPerFrame() const {
    return splitByGravity() ? std::max(drift_deg_per_frame_, heading_drift_deg_per_frame_)
                            : drift_deg_per_frame_;
  }
  double tiltDriftDegPerFrame() const { return drift_deg_per_frame_; }
  // kLikelihood: the bank the tilt's walk is chosen from (its walk and the cue's noise scale),
  // and whether it is in use (the likelihood rule with the walk split by gravity).
  const WalkBank& tiltBank() const { return tilt_bank_; }
  bool tiltByLikelihood() const;
  // heading_drift_adaptation kLikelihood: the bank the heading's walk is chosen from, fed the sun's
  // answers, and whether it is in use (the likelihood rule with the walk split by gravity).
  const WalkBank& headingBank() const { return heading_bank_; }
  bool headingByLikelihood() const;
  double headingDriftDegPerFrame() const {
    return splitByGravity() ? heading_drift_deg_per_frame_ : drift_deg_per_frame_;
  }
  // Last value of the persistence statistic T (0 before the first accepted measurement).
  double persistenceStatistic() const { return persistence_T_; }
  // The last correction of the base's world attitude (base-attitude mode), for diagnostics:
  // dtheta_w = C_w_b delta_b (rad, world frame; the VO world attitude turns by Exp(dtheta_w)),
  // the newest frame of the solve that made it, and how many measurements it used.
  struct Correction {
    std::uint64_t sequence = 0;
    Eigen::Vector3d dtheta_w = Eigen::Vector3d::Zero();
    int measurements = 0;
  };
  const Correction& lastCorrection() const { return last_correction_; }
  std::uint64_t numCorrections() const { return num_corrections_; }
  // r^T S^-1 r of the last measurement that reached the innovation gate (0 before the first).
  double lastInnovationNis() const { return last_nis_; }
  // Evidence rule: how often P was widened to cover an evidenced error.
  std::uint64_t numInflations() const { return num_inflations_; }
  // The sun's azimuth bias state (sun_bias_sigma_deg > 0): estimate and std, rad (0 without it).
  double sunAzimuthBias() const { return bias_; }
  double sunAzimuthBiasSigma() const { return std::sqrt(std::max(Pa_(kSunBias, kSunBias), 0.0)); }
  // The vertical cue's bias: its turn about the camera's x and z axes and their std, rad; the
  // fusion's state (vertical_bias_sigma_deg > 0) or the walk bank's estimate
  // (likelihood_up_bias_scales > 1), 0 without either.
  Eigen::Vector2d upBias() const { return bankUpBias() ? tilt_bank_.upBias() : up_bias_; }
  Eigen::Vector2d upBiasSigma() const {
    return bankUpBias()
               ? tilt_bank_.upBiasSigma()
               : Eigen::Vector2d(Pa_.diagonal().segment<2>(kUpBias).cwiseMax(0.0).cwiseSqrt());
  }

 private:
  struct Pending {
    SunObservation obs;
    bool decided = false;
    bool accepted = false;
    bool consumed = false;                // used in a base-attitude solve already
    ceres::CostFunction* cost = nullptr;  // one of costs_[ring], set for this measurement
    // bankUpBias: the bank's estimate of the cue's bias taken out of this answer (rad).
    Eigen::Vector2d up_bias_removed = Eigen::Vector2d::Zero();
  };
  // The pre-built sun costs of one ring slot; each functor is owned by its cost function.
  struct CostSlot {
    SunDirectionResidual* direction = nullptr;
    SunAzimuthResidual* azimuth = nullptr;
    std::unique_ptr<ceres::CostFunction> direction_cost;
    std::unique_ptr<ceres::CostFunction> azimuth_cost;
  };
  // The slot's cost for a measurement, its numbers set (s_b: the sun in the base frame; the bias
  // form takes the current bias estimate).
  ceres::CostFunction* setSunCost(std::size_t ring, const Eigen::Vector3d& sun_b,
                                  const SunMeasurement& m);
  Status onSolve(backend::BundleWindow& window);
  void onSolved(backend::BundleWindow& window);
  // Covariance propagation over `frames` new frames.
  void propagate(double frames);
  // The Jacobian of a cost's whitened residual wrt its bias block: m rows, 1 (the sun's azimuth)
  // or 2 (the up's turn) columns; 0 columns for a cost without one.
  using BiasJacobian = Eigen::Matrix<double, 3, 2, Eigen::RowMajor>;
  // Whitened residual and its Jacobians wrt delta_b and the bias block's correction (bias: two
  // entries, the block's first ones read) of a sun cost at (C_k_b, delta_b, bias); m rows.
  static bool evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                         const double* delta_b, const double* bias, Eigen::Vector3d* r,
                         Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d, BiasJacobian* J_bias,
                         int* bias_cols, int* m);
  bool biasEnabled() const {
    return options_.sun_bias_sigma_deg > 0.0 && options_.estimate_base_attitude;
  }
  bool upBiasEnabled() const {
    return options_.vertical_bias_sigma_deg > 0.0 && options_.estimate_base_attitude;
  }
  // The walk bank estimates the cue's bias, which is taken out of its answers (two-stage).
  bool bankUpBias() const { return tiltByLikelihood() && tilt_bank_.hasUpBias(); }
  // The augmented state (dtheta_w, b, c) in Pa_'s rows, and the active rows: 3 + 1 with the sun's
  // bias + 2 with the up's, in that order.
  static constexpr int kSunBias = 3;
  static constexpr int kUpBias = 4;
  static constexpr int kAugmented = 6;
  using AugmentedMatrix = Eigen::Matrix<double, kAugmented, kAugmented>;
  using ActiveMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  // The active rows and columns of Pa_, the attitude's turned by C (C_b_w: the base frame).
  ActiveMatrix activeCovariance(const Eigen::Matrix3d& C) const;
  // Writes an active covariance in the world frame back into Pa_.
  void setActiveCovariance(const ActiveMatrix& P);
  // A cost's Jacobian over the active state (3 to 6 columns).
  using ActiveJacobian =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 3, 6>;
  // The m rows of a cost's Jacobians wrt delta_b (J_d) and its bias block (J_b, cols columns) in
  // the active state's columns: a 1-column block is the sun's azimuth (right after the
  // attitude), a 2-column one the up's turn (after the sun's, if that is a state).
  ActiveJacobian activeJacobian(const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>& J_d,
                                const BiasJacobian& J_b, int cols, int m) const;
  // The bias block of a channel's costs (0 sun, 1 vertical); nullptr where that bias is no state.
  double* biasBlock(int channel);
  // A measurement's innovation at delta_b = 0, from its base-correction cost: whitened residual r
  // (dof rows) and its Jacobian J wrt delta_b; nis = r^T (J_a P J_a^T + I)^-1 r with J_a its
  // Jacobian over the active state and P the solve's prior (activeCovariance in the base frame)
  // (innovation gate). False if not finite.
  struct Innovation {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J =
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor>::Zero();
    int dof = 0;
    double nis = 0.0;
    Eigen::Vector3d move_b = Eigen::Vector3d::Zero();  // predicted correction of delta_b
    // bankUpBias, vertical channel: d r / d c at c = 0 (walk_bank.hpp) and the bias taken out of
    // the answer r was computed from (the bank's members see the answer as it came).
    Eigen::Matrix<double, 3, 2> J_up = Eigen::Matrix<double, 3, 2>::Zero();
    Eigen::Vector2d up_bias_removed = Eigen::Vector2d::Zero();
    // A 3-D direction's residual: the measured direction, along which the difference of two unit
    // vectors has no first-order part (nor noise); zero for the azimuth-only residual.
    Eigen::Vector3d radial = Eigen::Vector3d::Zero();
  };
  bool innovation(const ceres::CostFunction& cost, const Isometry3& T_k_b, const ActiveMatrix& P,
                  Innovation* out) const;
  // d r / d e of an innovation r at the current estimate, e the world-frame error of the base's
  // attitude (the truth is Exp(e) C_w_b): r(delta_b) ~ r + J delta_b vanishes at delta_b = C_b_w
  // e, so r ~ -J C_b_w e. The sign matters where e is tracked across corrections (the evidence
  // sums and the walk bank: a correction c_w leaves e - c_w).
  static Eigen::Matrix3d errorJacobian(const Eigen::Matrix3d& J, const Eigen::Matrix3d& C_w_b) {
    return -J * C_w_b.transpose();
  }
  // One adaptation step of q_theta from an accepted measurement's innovation (C_w_b: base;
  // channel 0 sun, 1 vertical).
  void adaptDrift(const Innovation& inn, const Eigen::Matrix3d& C_w_b, int channel);
  bool splitByGravity() const;
  double clampDrift(double q) const;
  // One log-step of a walk q raised by a channel whose evidence may take it up to cap: a step up
  // stops at max(cap, q) (another channel's larger cap is not undone), a step down at the floor.
  double stepDrift(double q, double step, double cap) const;
  // The tilt's walk the likelihood rule gives the fusion (deg/frame): the bank's, within
  // [min_drift_deg_per_frame, vertical_max_drift_deg_per_frame].
  double bankTiltDrift() const;
  // The tilt's walk follows the vertical channel by the evidence rule (kEvidence, split).
  bool tiltByEvidence() const;
  // An answer for a walk bank: H = d r / d e (world) and the Huber-weighted r; a 3-D direction's
  // rows across the measured direction only (its radial row has no first-order signal, and read
  // as a row of noise it would make the noise scales read sqrt(2/3) of the truth), the bias
  // Jacobian H_c turned with them. Returns the rows.
  int bankAnswer(const Innovation& inn, const Eigen::Matrix3d& C_w_b, Eigen::Matrix3d* H,
                 Eigen::Vector3d* r, Eigen::Matrix<double, 3, 2>* H_c) const;
  // The weight that caps a whitened innovation's norm at persistence_huber sigmas per row.
  double huberWeight(const Innovation& inn) const;
  // Adds an accepted measurement to sums I and g (world frame) after forgetting them by lambda
  // (1 = no forgetting).
  void accumulate(const Innovation& inn, const Eigen::Matrix3d& C_w_b, Eigen::Matrix3d* I,
                  Eigen::Vector3d* g, double lambda) const;
  // Evidence rule: widens P along directions where I^+ g stands out of its noise; returns the
  // statistic over the informed directions.
  double inflateToEvidence(const Eigen::Matrix3d& I, const Eigen::Vector3d& g);

  SunFusionOptions options_;
  std::unique_ptr<ceres::LossFunction> loss_;
  // Ring by sequence, two channels per frame: index (sequence % kMaxWindowSize) * 2 + channel.
  static constexpr int kChannels = 2;  // 0: sun, 1: vertical
  static constexpr std::size_t kSlots = backend::BundleWindow::kMaxWindowSize * kChannels;
  void add(const SunObservation& observation, int channel);
  std::array<Pending, kSlots> pending_;
  std::array<CostSlot, kSlots> costs_;
  std::array<bool, kSlots> used_{};
  GateCounters counters_;
  GateCounters vertical_counters_;
  std::optional<GateResult> last_decision_;
  // Base-attitude mode state.
  std::array<double, 3> delta_{0.0, 0.0, 0.0};  // delta_b of the current solve
  // Covariance of (dtheta_w (world frame), b, c), rad^2; rows of a bias off are zero.
  AugmentedMatrix Pa_ = AugmentedMatrix::Zero();
  auto P() { return Pa_.topLeftCorner<3, 3>(); }  // of dtheta_w
  std::array<int, kAugmented> active_{};          // Pa_'s active rows
  int num_active_ = 3;
  // The bias states' estimates (rad) and their corrections in the current solve: the sun's
  // azimuth b and the up's turn c.
  double bias_ = 0.0;
  double bias_delta_ = 0.0;
  Eigen::Vector2d up_bias_ = Eigen::Vector2d::Zero();
  std::array<double, 2> up_bias_delta_{0.0, 0.0};
  double drift_deg_per_frame_ = 0.0;          // q_theta in use (the tilt's when split), deg/frame
  double heading_drift_deg_per_frame_ = 0.0;  // the heading's q_theta when split, deg/frame
  Eigen::Vector3d persistence_g_ = Eigen::Vector3d::Zero();  // forgotten sum of H^T w r
  Eigen::Matrix3d persistence_I_ = Eigen::Matrix3d::Zero();  // forgotten sum of H^T H
  Eigen::Vector3d sun_g_ = Eigen::Vector3d::Zero();  // the same sums, sun channel only (split)
  Eigen::Matrix3d sun_I_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d vertical_g_ = Eigen::Vector3d::Zero();  // the same, vertical channel only, kept
  Eigen::Matrix3d vertical_I_ = Eigen::Matrix3d::Zero();  // consistent with the corrections
  bool vertical_in_sums_ = false;  // the vertical channel has taken the tilt's walk over
  double persistence_T_ = 0.0;
  std::array<double, 4> persistence_bound_{};  // chi-square quantile by rank 1..3
  std::optional<std::uint64_t> last_sequence_;
  // The gate an answer must pass to be collected by world_up_: vertical_gate, its cosine bound
  // widened to start_tilt_max_deg for kStartTilt.
  SunGateOptions alignment_gate_;
  bool start_decided_ = false;  // kStartTilt: the alignment is done and its tilt was judged
  bool levelled_ = false;       // kStartTilt: the start was levelled (takeStartLevelling)
  AttitudePriorResidual* prior_ = nullptr;  // owned by prior_cost_
  std::unique_ptr<ceres::CostFunction> prior_cost_;
  // With a bias state: the joint prior's square-root information and its cost.
  JointPriorMatrix joint_prior_L_ = JointPriorMatrix::Identity();
  std::unique_ptr<ceres::CostFunction> joint_prior_cost_;
  std::array<int, kSlots> used_in_solve_{};  // ring indices
  int num_used_ = 0;
  Correction last_correction_;
  std::uint64_t num_corrections_ = 0;
  double last_nis_ = 0.0;
  std::uint64_t num_inflations_ = 0;
  WorldUpAlignment world_up_;
  WalkBank tilt_bank_;     // kLikelihood: the tilt's walks and their likelihoods
  WalkBank heading_bank_;  // heading_drift_adaptation kLikelihood: the heading's
};

}  // namespace sunvo::sunfusion
