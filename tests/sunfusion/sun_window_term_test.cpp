#include "sunvo/sunfusion/sun_window_term.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sun_window_term_fixture.hpp"
#include "sunvo/sunfusion/simulated_sun_source.hpp"
#include "sunvo/sunfusion/sun_residual.hpp"

#ifdef SUNVO_HAVE_ALLOC_COUNTER
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::sunfusion {
namespace {

using test_support::baseAttitudeOptions;
using test_support::cameraWorldOptions;
using test_support::kDeg;
using test_support::SunWindowTermTest;

TEST_F(SunWindowTermTest, WithoutSunTheNewFrameInheritsTheBaseError) {
  EXPECT_NEAR(solveAndYawError(nullptr, std::nullopt), 2.0, 0.01);
}

TEST_F(SunWindowTermTest, FullSunMeasurementPullsOrientationBack) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(cameraWorldOptions()).isOk());
  const double err =
      solveAndYawError(&term, perfectObservation(SunMeasurementKind::kFull3d, 0.001));
  // In the paper's formulation the base's world pose is fixed, and 150 exact stereo points pin the
  // relative rotation C_k_b stiffly, so one window removes only a share of the absolute error
  // (measured: 6.9 %); repeated every fifth frame the shares compound and bound the drift.
  EXPECT_LT(err, 1.95);
  EXPECT_GT(err, 1.5);
  // A looser sun term corrects less.
  SunWindowTerm loose;
  ASSERT_TRUE(loose.init(cameraWorldOptions()).isOk());
  const double err_loose =
      solveAndYawError(&loose, perfectObservation(SunMeasurementKind::kFull3d, 0.01));
  EXPECT_GT(err_loose, err);
  EXPECT_LT(err_loose, 2.0);
  EXPECT_EQ(term.counters().accepted, 1u);
  EXPECT_EQ(window_.T_w_b().linear(), T_w_b_est_.linear());  // the base itself stays fixed
}

TEST_F(SunWindowTermTest, AzimuthOnlyMeasurementAlsoCorrectsYaw) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(cameraWorldOptions()).isOk());
  const double err =
      solveAndYawError(&term, perfectObservation(SunMeasurementKind::kAzimuthOnly, 0.001));
  EXPECT_LT(err, 1.9);  // measured 1.68: the in-plane chord acts on yaw alone
  EXPECT_EQ(term.counters().accepted, 1u);
}

TEST_F(SunWindowTermTest, GatedMeasurementLeavesTheSolutionUnchanged) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(cameraWorldOptions()).isOk());
  SunObservation wrong = perfectObservation(SunMeasurementKind::kFull3d, 0.001);
  wrong.measurement.sun_c = sunFromAzimuthZenith(-110.0 * kDeg, 50.0 * kDeg);  // shadow flip
  const double err = solveAndYawError(&term, wrong);
  EXPECT_NEAR(err, 2.0, 0.01);
  EXPECT_EQ(term.counters().rejected_cosine, 1u);
  EXPECT_EQ(term.counters().accepted, 0u);
  ASSERT_TRUE(term.lastDecision().has_value());
  EXPECT_EQ(*term.lastDecision(), GateResult::kRejectedCosine);
}

TEST_F(SunWindowTermTest, SunBelowHorizonIsNotUsed) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(cameraWorldOptions()).isOk());
  SunObservation night = perfectObservation(SunMeasurementKind::kFull3d, 0.001);
  night.sun_w = sunFromAzimuthZenith(70.0 * kDeg, 100.0 * kDeg);  // 10 degrees below
  night.measurement.sun_c = T_k_b_true_.linear() * night.sun_w;
  EXPECT_NEAR(solveAndYawError(&term, night), 2.0, 0.01);
  EXPECT_EQ(term.counters().rejected_sun_down, 1u);
}

// One sun direction observes two of the three attitude degrees of freedom: the rotation about
// the sun axis is invisible to it. The base-attitude mode must remove the observable part of the
// error (perpendicular to the sun) and leave the invisible part alone.
double perpendicularErrorDeg(const Eigen::Matrix3d& C_w_est, const Eigen::Vector3d& sun_w) {
  const Eigen::Vector3d e = logSO3(C_w_est);  // truth is the identity here
  return (e - e.dot(sun_w) * sun_w).norm() / kDeg;
}

TEST_F(SunWindowTermTest, BaseAttitudeModeRemovesTheObservableError) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(baseAttitudeOptions()).isOk());
  EXPECT_NEAR(perpendicularErrorDeg(T_w_b_est_.linear(), sun_w_), 2.0 * 0.7660, 1e-3);
  solveAndYawError(&term, perfectObservation(SunMeasurementKind::kFull3d, 0.01));
  // The 1.53 degree observable error is within the 3 degree prior; a measurement with
  // sigma = 0.01 rad (0.573 deg) leaves the Kalman share s^2 / (s^2 + p^2) = 3.52 % of it, in the
  // base and in the new frame.
  const double expected = 2.0 * 0.7660 * 0.573 * 0.573 / (0.573 * 0.573 + 9.0);
  EXPECT_NEAR(perpendicularErrorDeg(window_.T_w_b().linear(), sun_w_), expected, 0.005);
  const Eigen::Matrix3d C_w_k_true = T_k_b_true_.inverse().linear();
  EXPECT_NEAR(perpendicularErrorDeg(window_.T_w_newest().linear() * C_w_k_true.transpose(), sun_w_),
              expected, 0.005);
  // The unobservable part (2 deg * cos(50 deg) about the sun axis) is untouched.
  EXPECT_NEAR(rotationAngle(window_.T_w_b().linear()) / kDeg, 2.0 * 0.6428, 0.02);
  // The attitude uncertainty shrank across the sun axis only.
  const Eigen::Matrix3d P = term.attitudeCovariance();
  EXPECT_NEAR(sun_w_.dot(P * sun_w_), std::pow(3.0 * kDeg, 2), 1e-6);
  EXPECT_LT(P.trace(), 1.5 * std::pow(3.0 * kDeg, 2));
}

TEST_F(SunWindowTermTest, BaseAttitudeModeWithAzimuthOnlyCorrectsTheObservablePart) {
  SunWindowTerm term;
  ASSERT_TRUE(term.init(baseAttitudeOptions()).isOk());
  const double before = solveAndYawError(nullptr, std::nullopt);
  SunWindowTerm az;
  ASSERT_TRUE(az.init(baseAttitudeOptions()).isOk());
  const double after =
      solveAndYawError(&az, perfectObservation(SunMeasurementKind::kAzimuthOnly, 0.01));
  EXPECT_LT(after, 0.5 * before);
  EXPECT_EQ(az.counters().accepted, 1u);
}

TEST_F(SunWindowTermTest, BaseAttitudeModeWeighsAnImpreciseMeasurementAgainstThePrior) {
  // sigma 0.1 (about 6 degrees) against a 3 degree prior: a partial, not a full, correction.
  SunWindowTerm term;
  ASSERT_TRUE(term.init(baseAttitudeOptions()).isOk());
  const double err = solveAndYawError(&term, perfectObservation(SunMeasurementKind::kFull3d, 0.1));
  EXPECT_GT(err, 0.2);
  EXPECT_LT(err, 1.8);
}

TEST_F(SunWindowTermTest, InnovationGateRefusesAMeasurementTheConfidentFilterCannotExplain) {
  // A 0.3 deg prior and a measurement 30 deg off in azimuth (inside the cosine gate: distance
  // 1 - cos 30 deg = 0.13 < 0.3) with a 3 deg sigma: r^T S^-1 r is about 100, far above 16.3.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.3;
  T_w_b_est_ = Isometry3::Identity();  // no base error: the measurement alone is wrong
  SunObservation wrong = perfectObservation(SunMeasurementKind::kFull3d, 0.05);
  wrong.measurement.sun_c =
      expSO3(Eigen::Vector3d(0.0, 30.0 * kDeg, 0.0)) * wrong.measurement.sun_c;
  SunWindowTerm gated;
  ASSERT_TRUE(gated.init(opt).isOk());
  const double err_gated = solveAndYawError(&gated, wrong);
  EXPECT_EQ(gated.counters().rejected_innovation, 1u);
  EXPECT_EQ(gated.counters().accepted, 0u);
  EXPECT_EQ(gated.lastDecision(), GateResult::kRejectedInnovation);
  EXPECT_LT(err_gated, 0.01);
  // Without the innovation gate the same measurement is taken and drags the attitude.
  opt.innovation_gate_chi2 = 0.0;
  SunWindowTerm open;
  ASSERT_TRUE(open.init(opt).isOk());
  EXPECT_GT(solveAndYawError(&open, wrong), 0.1);
  EXPECT_EQ(open.counters().accepted, 1u);
}

TEST_F(SunWindowTermTest, PersistenceRuleRaisesDriftOnlyWhenTheErrorStandsOutOfTheNoise) {
  // Every window starts from the same 2 deg base error. Precise measurements (0.57 deg) see it
  // clearly, window after window: q_theta must rise. Imprecise ones (17 deg) see the same error
  // at 0.1 sigma per measurement, too little to tell it from noise in 21 windows: q_theta must
  // fall, and the sun barely moves VO.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.innovation_gate_chi2 = 0.0;
  opt.max_drift_deg_per_frame = 0.5;  // above the default cap, to see the rule itself
  ASSERT_EQ(opt.drift_adaptation, DriftAdaptation::kPersistence);
  SunWindowTerm precise, imprecise;
  solvePreciseAndImprecise(opt, &precise, &imprecise);
  EXPECT_GT(precise.persistenceStatistic(), 100.0);
  EXPECT_GT(precise.driftDegPerFrame(), 0.2);
  EXPECT_LE(precise.driftDegPerFrame(), opt.max_drift_deg_per_frame);
  EXPECT_LT(imprecise.persistenceStatistic(), 6.0);
  EXPECT_LT(imprecise.driftDegPerFrame(), opt.attitude_drift_deg_per_frame);
  EXPECT_GE(imprecise.driftDegPerFrame(), opt.min_drift_deg_per_frame);
  EXPECT_TRUE(precise.attitudeCovariance().allFinite());
}

TEST_F(SunWindowTermTest, PersistenceRuleIgnoresZeroMeanNoiseAndOutliers) {
  // No attitude error at all; measurements scattered with their reported sigma (0.2, about
  // 11 deg) and 20 % of them 40 deg off in a random direction, as a Lalonde-like source would
  // give. The persistence rule sees no consistent direction and keeps q_theta at its minimum,
  // and the attitude stays put.
  T_w_b_est_ = Isometry3::Identity();
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.5;
  opt.innovation_gate_chi2 = 0.0;
  SunWindowTerm persistence;
  ASSERT_TRUE(persistence.init(opt).isOk());
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::uint64_t k = 1; k <= 121; k += 2) {
    SunObservation obs = perfectObservation(SunMeasurementKind::kFull3d, 0.2);
    Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    axis.normalize();
    const double angle = unit(rng) < 0.2 ? 40.0 * kDeg : 0.2 * std::abs(normal(rng));
    obs.measurement.sun_c = expSO3(angle * axis) * obs.measurement.sun_c;
    solveAt(&persistence, k, obs);
  }
  EXPECT_LT(persistence.driftDegPerFrame(), 1.5 * opt.min_drift_deg_per_frame);
  EXPECT_LT(persistence.persistenceStatistic(), 11.34);  // chi-square 3 dof, 99 %
  // The last window's base correction: the newest frame's world attitude error stays small.
  const Eigen::Matrix3d dC = window_.T_w_newest().linear() * T_k_b_true_.linear();
  EXPECT_LT(logSO3(dC).norm() / kDeg, 0.5);
}

// The evidence rule on the sun channel: a 2 deg roll error at the start, full 3-D sun answers.
TEST_F(SunWindowTermTest, EvidenceRuleWidensPOnlyWhereTheErrorStandsOutOfTheNoise) {
  // A 0.1 deg prior against a 2 deg base error, each window starting from the last one's corrected
  // base. Precise measurements (0.57 deg) evidence the error within two windows: P must be widened
  // to cover it, and the error removed. Imprecise ones (17 deg) evidence it at 0.5 sigma after 21
  // windows: P must stay as the random walk makes it.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.1;
  opt.innovation_gate_chi2 = 0.0;
  opt.drift_adaptation = DriftAdaptation::kEvidence;
  carry_corrections_ = true;
  SunWindowTerm precise, imprecise;
  solvePreciseAndImprecise(opt, &precise, &imprecise);
  EXPECT_GT(precise.numInflations(), 0u);
  const auto max_sigma_deg = [](const SunWindowTerm& t) {
    return std::sqrt(t.attitudeCovariance().eigenvalues().real().maxCoeff()) / kDeg;
  };
  // The widened P let the answers remove the error a sun direction sees (0.073 deg of 1.53 deg
  // left, 4 widenings, measured 2026-11-29); the imprecise ones leave it (1.53 deg).
  EXPECT_LT(precise_error_deg_, 0.15);
  EXPECT_GT(imprecise_error_deg_, 1.4);
  EXPECT_EQ(imprecise.numInflations(), 0u);
  EXPECT_LT(max_sigma_deg(imprecise), 0.15);
  // The random walk is not adapted by this rule.
  EXPECT_EQ(precise.driftDegPerFrame(), opt.min_drift_deg_per_frame);
  EXPECT_TRUE(precise.attitudeCovariance().allFinite());
}

TEST_F(SunWindowTermTest, EvidenceRuleDiscountsASourceWithCorrelatedErrors) {
  // The precise measurements of the standing 2 deg error above, now from a source whose errors
  // are stated to stay alike for 100 measurements: 21 of them count as less than one independent
  // one, and P is not widened. A standing source bias looks exactly like this.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.1;
  opt.innovation_gate_chi2 = 0.0;
  opt.drift_adaptation = DriftAdaptation::kEvidence;
  opt.evidence_correlation = 100.0;
  SunWindowTerm correlated, unused;
  solvePreciseAndImprecise(opt, &correlated, &unused);
  EXPECT_EQ(correlated.numInflations(), 0u);
  EXPECT_LT(std::sqrt(correlated.attitudeCovariance().eigenvalues().real().maxCoeff()) / kDeg,
            0.15);
}

// A source whose azimuth stays 4 deg off (a street-long bias of an image estimator) and an
// attitude without error: without the bias state the precise measurements pull the attitude
// toward their bias; with it the standing offset goes to the bias estimate, since a heading error
// of that size is implausible for VO with a 0.5 deg prior and a slow walk.
TEST_F(SunWindowTermTest, BiasStateTakesAStandingAzimuthErrorAsTheSources) {
  T_w_b_est_ = Isometry3::Identity();
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.5;
  opt.innovation_gate_chi2 = 0.0;
  opt.max_drift_deg_per_frame = 0.5;  // let the walk open up, as for an independent source
  SunObservation biased = perfectObservation(SunMeasurementKind::kFull3d, 0.01);
  biased.measurement.sun_c = turnAboutCameraY(biased.measurement.sun_c, 4.0 * kDeg);
  const auto run = [&](const SunFusionOptions& o, SunWindowTerm* term) {
    ASSERT_TRUE(term->init(o).isOk());
    for (std::uint64_t k = 1; k <= 41; k += 2) solveAt(term, k, biased);
  };
  const auto headingErrorDeg = [&] {
    const Eigen::Matrix3d dC = window_.T_w_newest().linear() * T_k_b_true_.linear();
    return std::abs(logSO3(dC).y()) / kDeg;
  };
  SunWindowTerm plain;
  run(opt, &plain);
  const double followed = headingErrorDeg();
  EXPECT_EQ(plain.sunAzimuthBias(), 0.0);
  opt.sun_bias_sigma_deg = 5.0;
  SunWindowTerm with_bias;
  run(opt, &with_bias);
  const double kept = headingErrorDeg();
  EXPECT_GT(followed, 1.0);
  EXPECT_LT(kept, 0.25);
  EXPECT_NEAR(with_bias.sunAzimuthBias() / kDeg, 4.0, 0.3);
  EXPECT_LT(with_bias.sunAzimuthBiasSigma() / kDeg, 1.0);
  EXPECT_TRUE(with_bias.attitudeCovariance().allFinite());
}

// The bias state explains an azimuth offset, not a tilt: a 2 deg base error about the horizontal
// axis across the sun (it moves the sun in elevation, which no turn about the vertical can) is
// removed by a precise, unbiased measurement with the bias state on as without it (the Kalman
// share left, 3.5 %: BaseAttitudeModeRemovesTheObservableError), and the bias stays near zero.
TEST_F(SunWindowTermTest, BiasStateLeavesTheTiltToTheSun) {
  SunFusionOptions opt = baseAttitudeOptions();
  const Eigen::Vector3d across = sun_w_.cross(opt.world_up).normalized();
  T_w_b_est_ = Isometry3::Identity();
  T_w_b_est_.linear() = expSO3(2.0 * kDeg * across);
  opt.sun_bias_sigma_deg = 5.0;
  SunWindowTerm term;
  ASSERT_TRUE(term.init(opt).isOk());
  solveAndYawError(&term, perfectObservation(SunMeasurementKind::kFull3d, 0.01));
  const Eigen::Vector3d e_w = logSO3(window_.T_w_b().linear());
  EXPECT_LT(std::abs(e_w.dot(across)) / kDeg, 0.1);
  EXPECT_LT(std::abs(term.sunAzimuthBias()) / kDeg, 0.1);
}

// A frame with a sun and an "up" measurement allocates nothing once the term and the window are
// warm (issue 19: no heap allocation per sun frame): the term's costs are built by init() and only
// get new numbers. Every form is checked: the paper's, the base correction, the sun's bias state,
// the cue's, both, and the walk bank's bias axis.
TEST_F(SunWindowTermTest, SunFramesAllocateNothingOnceWarm) {
#if !defined(SUNVO_HAVE_ALLOC_COUNTER)
  GTEST_SKIP() << "no allocation counter in this build";
#else
  ASSERT_TRUE(runtime::allocCounterActive());
  SunObservation up;
  up.sun_w = Eigen::Vector3d(0.0, -1.0, 0.0);
  up.measurement.kind = SunMeasurementKind::kFull3d;
  up.measurement.sigma = 1.0 * kDeg;
  up.measurement.sigma_strong = 0.2 * kDeg;  // measured better along x, as the cue reports it
  up.measurement.strong_axis_c = Eigen::Vector3d::UnitX();
  up.measurement.sun_c = T_k_b_true_.linear() * up.sun_w;
  for (int form = 0; form < 6; ++form) {
    SunFusionOptions opt = form == 0 ? cameraWorldOptions() : baseAttitudeOptions();
    if (form == 2 || form == 4) opt.sun_bias_sigma_deg = 5.0;
    if (form == 3 || form == 4) opt.vertical_bias_sigma_deg = 0.2;
    if (form == 5) opt.likelihood_up_bias_scales = 4;
    SunWindowTerm term;
    ASSERT_TRUE(term.init(opt).isOk());
    const auto frame = [&](std::uint64_t k) {
      window_.reset(T_w_b_est_);
      term.attach(window_);
      SunObservation sun = perfectObservation(
          k % 4 == 1 ? SunMeasurementKind::kAzimuthOnly : SunMeasurementKind::kFull3d, 0.05);
      sun.measurement.sequence = k;
      term.addObservation(sun);
      up.measurement.sequence = k;
      term.addVertical(up);
      const TimeNs t = static_cast<TimeNs>(k) * 100'000'000;
      EXPECT_TRUE(window_.addFrame(k - 1, t - 100'000'000, obs_b_, Isometry3::Identity()).isOk());
      EXPECT_TRUE(window_.addFrame(k, t, obs_k_, T_k_b_true_).isOk());
      EXPECT_TRUE(window_.solve());
    };
    for (std::uint64_t k = 1; k <= 9; k += 2) frame(k);  // warm-up
    const std::uint64_t before = runtime::allocationCount();
    for (std::uint64_t k = 11; k <= 49; k += 2) frame(k);
    EXPECT_EQ(runtime::allocationCount() - before, 0u) << "form " << form;
    EXPECT_EQ(term.counters().accepted + term.verticalCounters().accepted, 50u) << "form " << form;
  }
#endif
}

TEST_F(SunWindowTermTest, EvidenceRuleIgnoresZeroMeanNoiseAndOutliers) {
  // As for the persistence rule: no attitude error, 11 deg noise and 20 % of 40 deg outliers.
  T_w_b_est_ = Isometry3::Identity();
  SunFusionOptions opt = baseAttitudeOptions();
  opt.initial_attitude_sigma_deg = 0.5;
  opt.innovation_gate_chi2 = 0.0;
  opt.drift_adaptation = DriftAdaptation::kEvidence;
  SunWindowTerm term;
  ASSERT_TRUE(term.init(opt).isOk());
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::uint64_t k = 1; k <= 121; k += 2) {
    SunObservation obs = perfectObservation(SunMeasurementKind::kFull3d, 0.2);
    Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    axis.normalize();
    const double angle = unit(rng) < 0.2 ? 40.0 * kDeg : 0.2 * std::abs(normal(rng));
    obs.measurement.sun_c = expSO3(angle * axis) * obs.measurement.sun_c;
    solveAt(&term, k, obs);
  }
  // The noise must not read as an attitude error: P stays near its start (a rule fooled by the
  // 11 deg noise and the outliers would widen it towards them) and the attitude stays right.
  // Measured (2026-11-25): x86-64 0 widenings, sigma 0.50 deg, error 0.008 deg; aarch64 (FMA
  // contraction, other libm) 3 widenings, sigma 1.58 deg, error 0.10 deg: the rule's statistic
  // passes close to its threshold here, and a last-bit difference flips one decision.
  EXPECT_LE(term.numInflations(), 3u);
  EXPECT_LT(std::sqrt(term.attitudeCovariance().eigenvalues().real().maxCoeff()) / kDeg, 2.0);
  const Eigen::Matrix3d dC = window_.T_w_newest().linear() * T_k_b_true_.linear();
  EXPECT_LT(logSO3(dC).norm() / kDeg, 0.5);
}

TEST_F(SunWindowTermTest, CorrectionGateRefusesAMeasurementThatWouldTurnTheAttitudeTooFar) {
  // A 3 deg prior and a precise measurement of the 2 deg base error: the predicted correction is
  // about 1.5 deg (the observable part). A 0.5 deg bound refuses it and counts it; 5 deg lets it
  // in.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.innovation_gate_chi2 = 0.0;
  opt.max_correction_deg = 0.5;
  SunWindowTerm bounded;
  ASSERT_TRUE(bounded.init(opt).isOk());
  const double before = solveAndYawError(nullptr, std::nullopt);
  const double err_bounded =
      solveAndYawError(&bounded, perfectObservation(SunMeasurementKind::kFull3d, 0.01));
  EXPECT_EQ(bounded.counters().rejected_correction, 1u);
  EXPECT_EQ(bounded.counters().accepted, 0u);
  EXPECT_EQ(bounded.lastDecision(), GateResult::kRejectedCorrection);
  EXPECT_NEAR(err_bounded, before, 1e-6);
  opt.max_correction_deg = 5.0;
  SunWindowTerm wide;
  ASSERT_TRUE(wide.init(opt).isOk());
  EXPECT_LT(solveAndYawError(&wide, perfectObservation(SunMeasurementKind::kFull3d, 0.01)),
            0.5 * before);
  EXPECT_EQ(wide.counters().accepted, 1u);
  EXPECT_EQ(wide.numCorrections(), 1u);
  EXPECT_GT(wide.lastCorrection().dtheta_w.norm() / kDeg, 0.5);
}

TEST_F(SunWindowTermTest, MedianRuleFollowsTheSizeOfTheInnovations) {
  // The comparison rule: precise measurements of a standing 2 deg error raise q_theta, imprecise
  // ones (innovations well inside S) lower it.
  SunFusionOptions opt = baseAttitudeOptions();
  opt.innovation_gate_chi2 = 0.0;
  opt.drift_adaptation = DriftAdaptation::kInnovationMedian;
  opt.attitude_drift_deg_per_frame = 0.05;
  opt.max_drift_deg_per_frame = 0.5;
  SunWindowTerm precise, imprecise;
  solvePreciseAndImprecise(opt, &precise, &imprecise);
  EXPECT_GT(precise.driftDegPerFrame(), 0.2);
  EXPECT_LT(imprecise.driftDegPerFrame(), 0.01);
}

TEST(SunFusionOptionsTest, ValidationNamesTheBadKey) {
  EXPECT_TRUE(SunFusionOptions{}.validate().isOk());
  using Set = void (*)(SunFusionOptions&);
  const std::vector<std::pair<Set, const char*>> cases = {
      // min_drift: above max_drift
      {[](SunFusionOptions& o) { o.min_drift_deg_per_frame = 1.0; }, "min_drift_deg_per_frame"},
      {[](SunFusionOptions& o) { o.vertical_max_drift_deg_per_frame = 0.001; },
       "vertical_max_drift_deg_per_frame"},
      {[](SunFusionOptions& o) { o.drift_adaptation_rate = 0.0; }, "drift_adaptation_rate"},
      {[](SunFusionOptions& o) { o.persistence_false_alarm = 0.0; }, "persistence_false_alarm"},
      {[](SunFusionOptions& o) { o.persistence_forgetting = 1.0; }, "persistence_forgetting"},
      {[](SunFusionOptions& o) { o.innovation_gate_chi2 = -1.0; }, "innovation_gate_chi2"},
      {[](SunFusionOptions& o) { o.evidence_sigmas = 0.0; }, "evidence_sigmas"},
      {[](SunFusionOptions& o) { o.evidence_forgetting = 1.0; }, "evidence_forgetting"},
      {[](SunFusionOptions& o) { o.evidence_correlation = 0.5; }, "evidence_correlation"},
      {[](SunFusionOptions& o) { o.max_correction_deg = -1.0; }, "max_correction_deg"},
      {[](SunFusionOptions& o) { o.sun_bias_sigma_deg = 50.0; }, "sun_bias_sigma_deg"},
      {[](SunFusionOptions& o) { o.sun_bias_length_frames = 0.0; }, "sun_bias_length_frames"},
      {[](SunFusionOptions& o) { o.vertical_bias_sigma_deg = 11.0; }, "vertical_bias_sigma_deg"},
      {[](SunFusionOptions& o) { o.likelihood_up_bias_scales = 5; }, "likelihood_up_bias_scales"},
      {[](SunFusionOptions& o) { o.likelihood_up_bias_max_deg = 0.0; },
       "likelihood_up_bias_max_deg"},
      // the bank's bias axis beside the fusion's own bias state
      {[](SunFusionOptions& o) {
         o.likelihood_up_bias_scales = 4;
         o.vertical_bias_sigma_deg = 0.1;
       },
       "likelihood_up_bias_scales"},
      {[](SunFusionOptions& o) { o.vertical_bias_length_frames = 0.5; },
       "vertical_bias_length_frames"},
      {[](SunFusionOptions& o) { o.start_tilt_max_deg = 0.0; }, "start_tilt_max_deg"},
      {[](SunFusionOptions& o) { o.start_tilt_max_deg = 46.0; }, "start_tilt_max_deg"},
  };
  for (const auto& [set, key] : cases) {
    SunFusionOptions opt;
    set(opt);
    EXPECT_NE(opt.validate().toString().find(key), std::string::npos) << key;
  }
}

}  // namespace
}  // namespace sunvo::sunfusion
