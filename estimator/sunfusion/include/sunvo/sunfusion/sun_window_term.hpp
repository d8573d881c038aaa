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
//      kLikelihood (the default), q_tilt is what a bank of tilt filters finds most likely. A
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
//    the gates and the persistence test use the prediction turned by b_hat. The vertical channel
//    has no bias state.
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

enum class DriftAdaptation { kFixed, kPersistence, kInnovationMedian, kEvidence };
inline std::span<const std::string_view> enumNames(DriftAdaptation) {
  static constexpr std::string_view kNames[] = {"fixed", "persistence", "innovation_median",
                                                "evidence"};
  return kNames;
}

// How the tilt's walk follows the vertical channel once it measures (persistence rule, split by
// gravity; header comment).
//  kPersistence (the default until 2026-11-29): q_tilt is stepped on the tilt's persistence test,
//    as the heading's on the sun's.
//  kEvidence: q_tilt stays at min_drift_deg_per_frame, and the tilt part of P is widened to the
//    error the cue's answers evidence (the evidence rule on sums of the vertical channel's answers
//    alone, forgotten by evidence_forgetting and kept consistent with every correction; they lie
//    in the plane normal to world_up). A walk stepped up and down trails a steady drift by a
//    lag just below its test's threshold; under VO's steady tilt drift in the camera's axes that
//    lag follows the camera, and its pitch part integrates into height, where VO's own error,
//    fixed in the world, cancels as the route turns. Measured (docs/vertical.md, "The stepped
//    walk's lag"): kEvidence removes that cost where it showed (00 seed 1) but costs another
//    route its final drift and holds the real cue's tilt worse on a rendered validation drive,
//    so it is not the default.
//  kLikelihood (default): q_tilt comes from a bank of walks in [min_drift_deg_per_frame,
//    vertical_max_drift_deg_per_frame] and noise scales of the cue's sigma, each a Kalman filter
//    of the tilt fed the cue's answers and weighed by the likelihood of their innovations
//    (walk_bank.hpp). Chosen on the validation sets (docs/vertical.md, "The tilt's walk from the
//    likelihood of the cue's answers"): lower tilt RMS than kPersistence in every validation
//    cell of the error-model experiment and on three of the four rendered validation drives,
//    without the lag's height cost.
enum class VerticalDriftAdaptation { kPersistence, kEvidence, kLikelihood };
inline std::span<const std::string_view> enumNames(VerticalDriftAdaptation) {
  static constexpr std::string_view kNames[] = {"persistence", "evidence", "likelihood"};
  return kNames;
}

// What the vertical channel's answers of the first world_up_alignment_frames frames measure.
//  kWorldUp: the world's up, which nobody measured (a world that is the first camera): their
//    estimate becomes the world's up of the vertical channel, its gate and the walk's split.
//  kStartTilt: VO's tilt error at the start, where the world's up is known (ENU) but the start
//    attitude's roll and pitch are not (a rover parked on a slope and started with the configured
//    ones). The answers are fused as they come (held in the paper's form, which corrects no base
//    attitude the alignment could follow), and collected beside; what the filter has left of
//    the error after those frames, where significant (kStartTiltChi2), is removed at once: VO's
//    attitude is turned by the rotation that takes the estimate onto world_up (roll and pitch
//    only), together with the positions built since the first frame, and the tilt part of the
//    attitude covariance becomes the estimate's. world_up stays the world's up.
enum class WorldUpAlignmentUse { kWorldUp, kStartTilt };
inline std::span<const std::string_view> enumNames(WorldUpAlignmentUse) {
  static constexpr std::string_view kNames[] = {"world_up", "start_tilt"};
  return kNames;
}

struct SunFusionOptions {
  SunGateOptions gate;
  // Gate of the vertical channel (addVertical): the default refuses an "up" more than 10 deg from
  // the predicted one (1 - cos 10 deg); the vertical-error gate is off (it is a sun cue).
  SunGateOptions vertical_gate = [] {
    SunGateOptions g;
    g.max_cosine_distance = 0.0152;
    g.max_vertical_error = 2.0;
    return g;
  }();
  // Unit vector "up" in the VO world frame, for the sun-elevation gate: ENU (0, 0, 1); a KITTI
  // camera-0 world has up = (0, -1, 0).
  Eigen::Vector3d world_up = Eigen::Vector3d::UnitZ();
  // frames, [0, 100000]: take the world's up from the vertical channel's answers of the first
  // this many frames (world_up_alignment.hpp) instead of world_up; world_up is then only the
  // guess they are gated against. 0 = world_up is known (ENU from GPS/INS, a render's world). For
  // a world that is the first camera (KITTI odometry, track folders), whose tilt nobody measured:
  // kWorldUpAlignmentFrames.
  int world_up_alignment_frames = 0;
  // What those answers measure (above): the world's up, or VO's tilt error at the start.
  WorldUpAlignmentUse world_up_alignment_use = WorldUpAlignmentUse::kWorldUp;
  // deg, (0, 45]: kStartTilt: the largest start tilt error whose answers the levelling takes
  // (vertical_gate's cosine bound replaced by this one while the answers are collected; they are
  // fused only inside vertical_gate). 15 = the cue's own search around the predicted up
  // (vertical.max_tilt_deg); a slope steeper than that is not measured.
  double start_tilt_max_deg = 15.0;
  // Robust loss on the whitened sun residual: Cauchy scale in sigmas, (0, 100]; 0 = no loss.
  double loss_scale = 0.0;
  // Estimate a correction of the base's world attitude (see above); false = the paper's form.
  bool estimate_base_attitude = true;
  double initial_attitude_sigma_deg = 1.0;  // deg, (0, 45]: first pose's attitude std
  // deg, [0, 5]: random-walk std growth of the world attitude per frame (q_theta); when it adapts,
  // the starting value.
  double attitude_drift_deg_per_frame = 0.01;
  // How q_theta adapts (see the header comment). kFixed keeps attitude_drift_deg_per_frame.
  DriftAdaptation drift_adaptation = DriftAdaptation::kPersistence;
  double min_drift_deg_per_frame = 0.002;  // deg/frame, [0, max]
  // deg/frame, [min, 5]. The persistence test assumes independent measurement errors; an image
  // estimator's errors are correlated from frame to frame (the same street), which it cannot tell
  // from a drift. The cap bounds how fast such a source can turn the estimate. 0.05 is above the
  // constant part of VO's drift on the worst route measured (0.018 deg/frame, real 0020 tracks);
  // raise it for sources with independent errors (docs/experiment.md, ablations).
  double max_drift_deg_per_frame = 0.05;
  // deg/frame, [min, 5]: with split_drift_by_gravity, the cap up to which the vertical channel
  // raises the tilt's walk. max_drift_deg_per_frame bounds the walks the sun's
  // measurements raise (an image estimator's is lowered for its street-long errors,
  // ImageEstimatorFusion); the cue's errors are not the sun's, so that bound is not the cue's
  // either (measured: docs/vertical.md, "Two channels, two caps"). 0.05 = the default of
  // max_drift_deg_per_frame, the cap of the cue alone.
  double vertical_max_drift_deg_per_frame = 0.05;
  // How the tilt's walk follows the vertical channel (above); evidence_sigmas,
  // evidence_forgetting and evidence_correlation are its test's with kEvidence.
  VerticalDriftAdaptation vertical_drift_adaptation = VerticalDriftAdaptation::kLikelihood;
  // kLikelihood (walk_bank.hpp): walks in the bank, [2, 8], log-spaced over
  // [min_drift_deg_per_frame (> 0), vertical_max_drift_deg_per_frame]; the cue's noise scales
  // (true / reported std), [1, 8], log-spaced over [likelihood_noise_min, likelihood_noise_max],
  // both (0, 100]; forgetting of the log-likelihoods per answer of the cue, (0, 1] (0.99: about
  // the last 100 answers).
  int likelihood_walks = 6;
  int likelihood_noise_scales = 6;
  double likelihood_noise_min = 0.35;
  double likelihood_noise_max = 2.0;
  double likelihood_forgetting = 0.99;
  double drift_adaptation_rate = 0.1;  // (0, 1]: log-step of q_theta per measurement (median rule)
  // Persistence rule: forgetting factor of the sums per measurement, (0, 1) (0.98: about the last
  // 50 measurements); false-alarm probability of the test on T, (0, 0.5]; log-steps up and down
  // per measurement, (0, 2]; Huber threshold on the whitened innovation norm in sigmas per row,
  // (0, 100].
  double persistence_forgetting = 0.98;
  double persistence_false_alarm = 0.01;
  double persistence_step_up = 0.5;
  double persistence_step_down = 0.1;
  double persistence_huber = 2.0;
  // Persistence rule: one q_theta for the tilt (roll/pitch: the plane normal to world_up), stepped
  // by the vertical channel once it measures, and one for the heading (about world_up), tested on
  // the sun's measurements only (header comment); false = one q_theta for all three axes, as before
  // 2026-11-26. The same without vertical measurements.
  bool split_drift_by_gravity = true;
  // Innovation gate bound on r^T S^-1 r, [0, 1e6]; 0 = off. 16.3 = chi-square 3 dof, 99.9 %.
  double innovation_gate_chi2 = 16.3;
  // Evidence rule: how many standard deviations of its estimate an error must reach along a
  // direction before P is made to cover it, (0, 100]; forgetting factor of its sums per accepted
  // measurement, (0, 1) (0.99: about the last 100). Uses persistence_huber.
  double evidence_sigmas = 3.0;
  double evidence_forgetting = 0.99;
  // Evidence rule: the source's error correlation length in measurements, [1, 1000]. The test
  // assumes independent errors; an estimator whose errors stay alike for tau measurements (a
  // street-long bias) gives about 1/tau as many independent ones, so the estimate's variance is
  // taken tau times larger (decorrelation in time). 1 = independent (the error models).
  double evidence_correlation = 1.0;
  // deg, [0, 180]; 0 = off: refuse a measurement whose predicted correction of the attitude is
  // larger (counted as rejected_correction).
  double max_correction_deg = 0.0;
  // Correlated azimuth error of the sun channel (header comment): stationary std, deg, [0, 45];
  // 0 = no bias state (the errors are taken as independent). Only with estimate_base_attitude.
  double sun_bias_sigma_deg = 0.0;
  // Its correlation length, frames, [1, 1e6] (250: a street at 10 m/s and 10 fps).
  double sun_bias_length_frames = 250.0;

  // Whether the first answers level the start (kStartTilt with frames to take them from).
  bool levelsStartTilt() const {
    return world_up_alignment_use == WorldUpAlignmentUse::kStartTilt &&
           world_up_alignment_frames > 0;
  }
  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("gate", s.gate);
    v("vertical_gate", s.vertical_gate);
    v("world_up_alignment_frames", s.world_up_alignment_frames);
    v("world_up_alignment_use", s.world_up_alignment_use);
    v("start_tilt_max_deg", s.start_tilt_max_deg);
    v("loss_scale", s.loss_scale);
    v("estimate_base_attitude", s.estimate_base_attitude);
    v("initial_attitude_sigma_deg", s.initial_attitude_sigma_deg);
    v("attitude_drift_deg_per_frame", s.attitude_drift_deg_per_frame);
    v("drift_adaptation", s.drift_adaptation);
    v("min_drift_deg_per_frame", s.min_drift_deg_per_frame);
    v("max_drift_deg_per_frame", s.max_drift_deg_per_frame);
    v("vertical_max_drift_deg_per_frame", s.vertical_max_drift_deg_per_frame);
    v("vertical_drift_adaptation", s.vertical_drift_adaptation);
    v("likelihood_walks", s.likelihood_walks);
    v("likelihood_noise_scales", s.likelihood_noise_scales);
    v("likelihood_noise_min", s.likelihood_noise_min);
    v("likelihood_noise_max", s.likelihood_noise_max);
    v("likelihood_forgetting", s.likelihood_forgetting);
    v("drift_adaptation_rate", s.drift_adaptation_rate);
    v("persistence_forgetting", s.persistence_forgetting);
    v("persistence_false_alarm", s.persistence_false_alarm);
    v("persistence_step_up", s.persistence_step_up);
    v("persistence_step_down", s.persistence_step_down);
    v("persistence_huber", s.persistence_huber);
    v("split_drift_by_gravity", s.split_drift_by_gravity);
    v("innovation_gate_chi2", s.innovation_gate_chi2);
    v("evidence_sigmas", s.evidence_sigmas);
    v("evidence_forgetting", s.evidence_forgetting);
    v("evidence_correlation", s.evidence_correlation);
    v("max_correction_deg", s.max_correction_deg);
    v("sun_bias_sigma_deg", s.sun_bias_sigma_deg);
    v("sun_bias_length_frames", s.sun_bias_length_frames);
  }
};

// world_up_alignment_frames for a world that is the first camera: 50 frames (5 s at 10 Hz, ten
// answers at one every fifth frame) put the mean of answers with the cue's 0.3-1.7 deg spread
// within 0.1-0.5 deg, while VO's tilt drifts by 0.01-0.5 deg in them (0.0002-0.01 deg/frame on
// the simulated and real tracks, docs/experiment.md). Fixed from those figures before any run;
// what it gives is measured in docs/vertical.md ("A world without gravity").
inline constexpr int kWorldUpAlignmentFrames = 50;

// world_up_alignment_frames for kStartTilt (a rover's start): the fewest frames that give the
// alignment its three answers at one every fifth frame. The levelling only has to bring the
// start's tilt error inside the gates; the filter refines it with every later answer. Chosen
// against 50 on validation drives (docs/start_levelling.md).
inline constexpr int kStartTiltFrames = 15;

// Significance of the start's tilt error left after those frames: chi-square with two degrees of
// freedom at 99 % (3.03 sigma of the answers' mean). Below it the turn would add the mean's noise
// to an estimate the filter has already taken the answers into; above it the filter was not
// taking them (an attitude covariance too small for the start's error refuses them at the
// innovation gate).
inline constexpr double kStartTiltChi2 = 9.21;

// How the programs say what became of the start's tilt once judged: "... measured from N answers
// and removed" or "... (within their noise: left to the filter)".
inline const char* startTiltOutcome(bool removed) {
  return removed ? "and removed" : "(within their noise: left to the filter)";
}

// The fusion's settings for an image sun estimator (Sun-CNN, Lalonde, Lalonde-VO), whose errors
// stay alike for a street and can be biased for a whole drive; sunvo_replay's image-estimator
// options and the rover's estimator defaults start from these.
struct ImageEstimatorFusion {
  // Cap of the adapted attitude random walk, deg/frame: the persistence test reads a street-long
  // stretch of the estimator's error as a drift. 0.01 is the walk's start value: on the three
  // benchmark drives Sun-CNN made VO worse by up to +246 % rot. ARMSE with 0.05, and by at most
  // +0.5 % with 0.01 (docs/sun_estimators.md).
  static constexpr double kMaxDriftDegPerFrame = 0.01;
  // The azimuth bias state (sun_bias_sigma_deg, sun_bias_length_frames; docs/fusion_bias.md,
  // "Sources biased for a whole drive"): an estimator that meets a look it was not trained on can
  // be wrong by the same tens of degrees for a whole drive (the Sun-CNN ran at -66 deg on a
  // foreign generator's drive, issue 14), and without the state the fusion follows it (+80 ...
  // +2900 % final drift with a -30 or -66 deg offset on the simulated routes). 30 deg puts such
  // an offset within about 2 sigma; 2500 frames (about 4 min at 10 Hz) is a drive's look, longer
  // than a street.
  static constexpr double kSunBiasSigmaDeg = 30.0;
  static constexpr double kSunBiasLengthFrames = 2500.0;
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
  const Eigen::Matrix3d& attitudeCovariance() const { return P_; }
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
  double sunAzimuthBiasSigma() const { return std::sqrt(std::max(P_bb_, 0.0)); }

 private:
  struct Pending {
    SunObservation obs;
    bool decided = false;
    bool accepted = false;
    bool consumed = false;                // used in a base-attitude solve already
    ceres::CostFunction* cost = nullptr;  // one of costs_[ring], set for this measurement
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
  // Whitened residual and its Jacobians wrt delta_b and (for a cost with the bias block, else
  // zero) the bias correction db, of a sun cost at (C_k_b, delta_b, db); m rows.
  static bool evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                         const double* delta_b, double db, Eigen::Vector3d* r,
                         Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d, Eigen::Vector3d* J_bias,
                         int* m);
  bool biasEnabled() const {
    return options_.sun_bias_sigma_deg > 0.0 && options_.estimate_base_attitude;
  }
  // The joint covariance of (delta_b, db) in the base frame (P_tb_ = 0, P_bb_ = 0 without bias).
  struct BasePrior {
    Eigen::Matrix3d P_b;
    Eigen::Vector3d P_tb_b;
    double P_bb = 0.0;
  };
  // A measurement's innovation at delta_b = 0, from its base-correction cost: whitened residual r
  // (dof rows) and its Jacobian J wrt delta_b; nis = r^T (J P_b J^T + I)^-1 r (innovation gate).
  // False if not finite.
  struct Innovation {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J =
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor>::Zero();
    int dof = 0;
    double nis = 0.0;
    Eigen::Vector3d move_b = Eigen::Vector3d::Zero();  // predicted correction P_b J^T S^-1 r
    Eigen::Vector3d J_bias = Eigen::Vector3d::Zero();  // wrt db (zero without the bias state)
  };
  static bool innovation(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                         const BasePrior& prior, Innovation* out);
  // One adaptation step of q_theta from an accepted measurement's innovation (C_w_b: base;
  // channel 0 sun, 1 vertical).
  void adaptDrift(const Innovation& inn, const Eigen::Matrix3d& C_w_b, int channel);
  bool splitByGravity() const;
  double clampDrift(double q) const;
  // One log-step of a walk q raised by a channel whose evidence may take it up to cap: a step up
  // stops at max(cap, q) (another channel's larger cap is not undone), a step down at the floor.
  double stepDrift(double q, double step, double cap) const;
  // The tilt's walk follows the vertical channel by the evidence rule (kEvidence, split).
  bool tiltByEvidence() const;
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
  std::array<double, 3> delta_{0.0, 0.0, 0.0};   // delta_b of the current solve
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Zero();  // of dtheta_w, world frame, rad^2
  // Sun azimuth bias state: estimate b (rad), its correction in the current solve, its variance
  // and its covariance with dtheta_w (world frame).
  double bias_ = 0.0;
  double bias_delta_ = 0.0;
  double P_bb_ = 0.0;
  Eigen::Vector3d P_tb_ = Eigen::Vector3d::Zero();
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
  AttitudeBiasPriorResidual* bias_prior_ = nullptr;  // owned by bias_prior_cost_
  std::unique_ptr<ceres::CostFunction> bias_prior_cost_;
  std::array<int, kSlots> used_in_solve_{};  // ring indices
  int num_used_ = 0;
  Correction last_correction_;
  std::uint64_t num_corrections_ = 0;
  double last_nis_ = 0.0;
  std::uint64_t num_inflations_ = 0;
  WorldUpAlignment world_up_;
  WalkBank tilt_bank_;  // kLikelihood: the tilt's walks and their likelihoods
};

}  // namespace sunvo::sunfusion
