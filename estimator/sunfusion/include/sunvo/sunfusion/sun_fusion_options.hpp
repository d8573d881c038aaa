#pragma once
// The sun fusion's options (SunWindowTerm, sun_window_term.hpp, whose header comment says what each
// rule and state does) and the constants the programs share for them.

#include <Eigen/Core>
#include <span>
#include <string_view>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"

namespace sunvo::sunfusion {

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

// How the heading's walk follows the sun's answers (persistence rule, split by gravity).
//  kPersistence (default): stepped on the persistence test of the sun's answers alone.
//  kLikelihood: chosen by a bank of walks in [min_drift_deg_per_frame, max_drift_deg_per_frame]
//    and noise scales of the sun's sigma (walk_bank.hpp with its walk about world_up), each member
//    fed the sun's answers, as the tilt's bank is fed the cue's. A source far better than it
//    reports (the true vector: 0.05 rad for an error of 0) cannot fire the persistence test on a
//    heading that moves by a fraction of that sigma, and once the cue takes the tilt out of the
//    sun's innovations nothing else fires it (docs/vertical.md, "Why 00's true vector loses its
//    gain beside the up").
enum class HeadingDriftAdaptation { kPersistence, kLikelihood };
inline std::span<const std::string_view> enumNames(HeadingDriftAdaptation) {
  static constexpr std::string_view kNames[] = {"persistence", "likelihood"};
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
  // either (measured: docs/vertical.md, "Two channels, two caps"). 0.2 since 2026-12-03 (0.05,
  // the sun's default, before): a walk trails a drift that is steady in the camera by a lag whose
  // pitch part builds height on every heading, and on the real 0020 tracks (+0.0063 deg/frame
  // about the camera's x) the cap held the walk there: with a perfect "up" 0.05 left 5.2 m of
  // height, 0.2 1.6 m (the true tilt's final drift). The likelihood chooses below it elsewhere
  // (docs/vertical_height.md: validation seeds, two rendered validation drives).
  double vertical_max_drift_deg_per_frame = 0.2;
  // How the tilt's walk follows the vertical channel (above); evidence_sigmas,
  // evidence_forgetting and evidence_correlation are its test's with kEvidence.
  VerticalDriftAdaptation vertical_drift_adaptation = VerticalDriftAdaptation::kLikelihood;
  // How the heading's walk follows the sun (above); the bank's walks span [min_drift_deg_per_frame,
  // max_drift_deg_per_frame] and it shares the likelihood_* settings below.
  HeadingDriftAdaptation heading_drift_adaptation = HeadingDriftAdaptation::kPersistence;
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
  // kLikelihood: the bank's third axis, the cue's bias (walk_bank.hpp): its stds are 0 and then
  // halving down to likelihood_up_bias_max_deg (deg, (0, 10]), likelihood_up_bias_scales of them
  // in all, [1, 4]; 1 = no bias axis. With one the fusion takes the bank's estimate of the bias
  // out of the cue's answers before it gates and fuses them (two-stage bias estimation); the
  // bias's correlation length is vertical_bias_length_frames. Not with vertical_bias_sigma_deg
  // (a bias state of the fusion's own).
  int likelihood_up_bias_scales = 1;
  double likelihood_up_bias_max_deg = 0.2;
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
  // Correlated error of the vertical cue (header comment): stationary std of its turn about the
  // camera's x and z axes, deg, [0, 10]; 0 = no bias state. Only with estimate_base_attitude.
  double vertical_bias_sigma_deg = 0.0;
  // Its correlation length, frames, [1, 1e7].
  double vertical_bias_length_frames = 2500.0;

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
    v("heading_drift_adaptation", s.heading_drift_adaptation);
    v("likelihood_walks", s.likelihood_walks);
    v("likelihood_noise_scales", s.likelihood_noise_scales);
    v("likelihood_noise_min", s.likelihood_noise_min);
    v("likelihood_noise_max", s.likelihood_noise_max);
    v("likelihood_forgetting", s.likelihood_forgetting);
    v("likelihood_up_bias_scales", s.likelihood_up_bias_scales);
    v("likelihood_up_bias_max_deg", s.likelihood_up_bias_max_deg);
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
    v("vertical_bias_sigma_deg", s.vertical_bias_sigma_deg);
    v("vertical_bias_length_frames", s.vertical_bias_length_frames);
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

}  // namespace sunvo::sunfusion
