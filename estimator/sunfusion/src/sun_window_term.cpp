#include "sunvo/sunfusion/sun_window_term.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/sunfusion/persistence_statistic.hpp"
#include "sunvo/sunfusion/sun_residual.hpp"

namespace sunvo::sunfusion {
namespace {
constexpr double kDeg = M_PI / 180.0;
// A sun cost has 1 to 3 rows (azimuth-only or 3-D): dynamic sizes bounded by 3 keep the
// storage on the stack, so the innovation and information updates do not touch the heap.
using RowsJacobian = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor, 3, 3>;
using RowsSquare = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
using RowsVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;

// A likelihood rule's walk bank (walk_bank.hpp): walks over [min_drift_deg_per_frame, q_max_deg]
// (deg/frame), the likelihood_* noise scales and forgetting, every member starting at s0 (rad).
WalkBankOptions likelihoodBank(const SunFusionOptions& options, double q_max_deg, double s0) {
  WalkBankOptions bank;
  bank.q_min_rad = options.min_drift_deg_per_frame * kDeg;
  bank.q_max_rad = q_max_deg * kDeg;
  bank.walks = options.likelihood_walks;
  bank.noise_min = options.likelihood_noise_min;
  bank.noise_max = options.likelihood_noise_max;
  bank.noise_scales = options.likelihood_noise_scales;
  bank.initial_sigma_rad = s0;
  bank.forgetting = options.likelihood_forgetting;
  return bank;
}

}  // namespace

Status SunWindowTerm::init(const SunFusionOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  options_ = options;
  loss_.reset(options.loss_scale > 0.0 ? new ceres::CauchyLoss(options.loss_scale) : nullptr);
  for (auto& p : pending_) p = Pending{};
  used_.fill(false);
  counters_ = GateCounters{};
  vertical_counters_ = GateCounters{};
  last_decision_.reset();
  delta_ = {0.0, 0.0, 0.0};
  const double s0 = options.initial_attitude_sigma_deg * kDeg;
  Pa_.setZero();
  P() = Eigen::Matrix3d::Identity() * s0 * s0;
  num_active_ = 0;
  for (int i = 0; i < 3; ++i) active_[static_cast<std::size_t>(num_active_++)] = i;
  if (biasEnabled()) {
    Pa_(kSunBias, kSunBias) = std::pow(options.sun_bias_sigma_deg * kDeg, 2);
    active_[static_cast<std::size_t>(num_active_++)] = kSunBias;
  }
  if (upBiasEnabled()) {
    Pa_.block<2, 2>(kUpBias, kUpBias) =
        Eigen::Matrix2d::Identity() * std::pow(options.vertical_bias_sigma_deg * kDeg, 2);
    active_[static_cast<std::size_t>(num_active_++)] = kUpBias;
    active_[static_cast<std::size_t>(num_active_++)] = kUpBias + 1;
  }
  bias_ = 0.0;
  bias_delta_ = 0.0;
  up_bias_.setZero();
  up_bias_delta_ = {0.0, 0.0};
  drift_deg_per_frame_ = options.drift_adaptation == DriftAdaptation::kEvidence
                             ? options.min_drift_deg_per_frame
                             : options.attitude_drift_deg_per_frame;
  heading_drift_deg_per_frame_ = drift_deg_per_frame_;
  persistence_g_.setZero();
  persistence_I_.setZero();
  sun_g_.setZero();
  sun_I_.setZero();
  vertical_g_.setZero();
  vertical_I_.setZero();
  vertical_in_sums_ = false;
  persistence_T_ = 0.0;
  persistence_bound_[0] = 0.0;
  for (int dof = 1; dof <= 3; ++dof) {
    persistence_bound_[static_cast<std::size_t>(dof)] =
        chiSquareQuantile(1.0 - options.persistence_false_alarm, dof);
  }
  last_sequence_.reset();
  levelled_ = false;
  start_decided_ = false;
  num_used_ = 0;
  last_correction_ = Correction{};
  num_corrections_ = 0;
  last_nis_ = 0.0;
  num_inflations_ = 0;
  world_up_.reset(static_cast<std::uint64_t>(options.world_up_alignment_frames), options.world_up);
  if (tiltByLikelihood()) {
    WalkBankOptions bank = likelihoodBank(options, options.vertical_max_drift_deg_per_frame, s0);
    bank.up_bias_scales = options.likelihood_up_bias_scales;
    bank.up_bias_max_rad = options.likelihood_up_bias_max_deg * kDeg;
    bank.up_bias_length_frames = options.vertical_bias_length_frames;
    SUNVO_RETURN_IF_ERROR(tilt_bank_.init(bank));
  }
  if (headingByLikelihood()) {
    WalkBankOptions bank = likelihoodBank(options, options.max_drift_deg_per_frame, s0);
    bank.heading = true;
    SUNVO_RETURN_IF_ERROR(heading_bank_.init(bank));
  }
  alignment_gate_ = options.vertical_gate;
  if (options.levelsStartTilt()) {
    alignment_gate_.max_cosine_distance =
        std::max(options.vertical_gate.max_cosine_distance,
                 1.0 - std::cos(options.start_tilt_max_deg * kDeg));
  }
  // Every cost a slot can need, in the form the options ask for (the only allocations).
  const SunResidualForm base =
      !options.estimate_base_attitude ? SunResidualForm::kPaper : SunResidualForm::kBaseCorrection;
  const SunResidualForm sun_form = biasEnabled() ? SunResidualForm::kBaseCorrectionAndBias : base;
  const SunResidualForm up_form =
      upBiasEnabled() ? SunResidualForm::kBaseCorrectionAndUpBias : base;
  for (std::size_t i = 0; i < kSlots; ++i) {
    // Even slots the sun's, odd ones the vertical channel's.
    const SunResidualForm f = i % kChannels == 0 ? sun_form : up_form;
    CostSlot& c = costs_[i];
    c.direction = new SunDirectionResidual(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), 1.0);
    c.direction_cost.reset(wrapSunResidual<SunDirectionResidual, 3>(c.direction, f));
    c.azimuth = new SunAzimuthResidual(Eigen::Vector3d::UnitZ(), Eigen::Vector2d::UnitY(), 1.0);
    c.azimuth_cost.reset(wrapSunResidual<SunAzimuthResidual, 2>(c.azimuth, f));
  }
  prior_ = new AttitudePriorResidual(Eigen::Matrix3d::Identity());
  prior_cost_.reset(new ceres::AutoDiffCostFunction<AttitudePriorResidual, 3, 3>(prior_));
  joint_prior_cost_.reset(num_active_ == 6   ? JointPriorResidual<6>::Create(&joint_prior_L_)
                          : num_active_ == 5 ? JointPriorResidual<5>::Create(&joint_prior_L_)
                                             : JointPriorResidual<4>::Create(&joint_prior_L_));
  return Status::ok();
}

ceres::CostFunction* SunWindowTerm::setSunCost(std::size_t ring, const Eigen::Vector3d& sun_b,
                                               const SunMeasurement& m) {
  CostSlot& c = costs_[ring];
  if (m.kind == SunMeasurementKind::kAzimuthOnly) {
    c.azimuth->set(sun_b, xzDirection(m.sun_c), m.sigma, bias_);
    return c.azimuth_cost.get();
  }
  c.direction->set(sun_b, m.sun_c, m.sigma, bias_, m.sigma_strong, m.strong_axis_c);
  c.direction->setUpBiasEstimate(up_bias_);
  return c.direction_cost.get();
}

void SunWindowTerm::attach(backend::BundleWindow& window) {
  window.setPoseResidualHook([this](backend::BundleWindow& w) { return onSolve(w); });
  window.setPostSolveHook([this](backend::BundleWindow& w) { onSolved(w); });
}

void SunWindowTerm::addObservation(const SunObservation& observation) {
  add(observation, 0);
}

void SunWindowTerm::addVertical(const SunObservation& observation) {
  add(observation, 1);
}

void SunWindowTerm::add(const SunObservation& observation, int channel) {
  const std::size_t slot =
      (observation.measurement.sequence % backend::BundleWindow::kMaxWindowSize) * kChannels +
      static_cast<std::size_t>(channel);
  pending_[slot] = Pending{};
  pending_[slot].obs = observation;
  used_[slot] = true;
}

Status SunWindowTerm::onSolve(backend::BundleWindow& window) {
  const bool estimate = options_.estimate_base_attitude;
  const std::uint64_t newest = window.sequence(window.size() - 1);
  if (estimate && last_sequence_ && newest > *last_sequence_) {
    propagate(static_cast<double>(newest - *last_sequence_));
  }
  last_sequence_ = newest;
  delta_ = {0.0, 0.0, 0.0};
  bias_delta_ = 0.0;
  up_bias_delta_ = {0.0, 0.0};
  num_used_ = 0;

  // Prior of this solve's base correction delta_b = C_b_w dtheta_w: N(0, C_b_w P_theta C_w_b),
  // jointly with the bias states' corrections where they are states.
  const Eigen::Matrix3d C_b_w = window.T_w_b().linear().transpose();
  const ActiveMatrix prior = activeCovariance(C_b_w);
  const Eigen::Matrix3d P_b = prior.topLeftCorner<3, 3>();
  for (int i = kChannels; i < window.size() * kChannels; ++i) {
    const int s = i / kChannels, channel = i % kChannels;
    const std::size_t ring =
        (window.sequence(s) % backend::BundleWindow::kMaxWindowSize) * kChannels +
        static_cast<std::size_t>(channel);
    if (!used_[ring] || pending_[ring].obs.measurement.sequence != window.sequence(s)) continue;
    Pending& p = pending_[ring];
    // An undecided "up" of the first frames measures the world's up (world_up_alignment.hpp);
    // the first one past them ends that, and is used with the estimate.
    const bool aligning = channel == 1 && !p.decided && world_up_.takes(window.sequence(s));
    const Eigen::Vector3d sun_w = channel == 0 ? p.obs.sun_w : worldUp();
    const Eigen::Vector3d sun_b = C_b_w * sun_w;
    bool cost_built = false;  // p.cost already holds this solve's residual
    double* const bias_block = biasBlock(channel);
    if (!p.decided) {
      if (channel == 1 && bankUpBias()) {
        // Two-stage: the answer as the bank's estimate of the cue's bias says it was meant,
        // Exp(-c) up_c (the residual's Exp(c) s_hat_k moved to the measurement).
        p.up_bias_removed = tilt_bank_.upBias();
        const Eigen::Matrix3d unturn =
            expSO3(Eigen::Vector3d(-p.up_bias_removed.x(), 0.0, -p.up_bias_removed.y()));
        p.obs.measurement.sun_c = unturn * p.obs.measurement.sun_c;
        p.obs.measurement.strong_axis_c = unturn * p.obs.measurement.strong_axis_c;
      }
      Eigen::Vector3d predicted_c = window.T_k_b(s).linear() * sun_b;
      if (bias_block != nullptr && channel == 0) predicted_c = turnAboutCameraY(predicted_c, bias_);
      if (bias_block != nullptr && channel == 1) {
        predicted_c = turnAboutCameraXZ(predicted_c, up_bias_.x(), up_bias_.y());
      }
      const double up = sun_w.dot(worldUp());
      GateResult r = gateSunMeasurement(channel == 0 ? options_.gate : options_.vertical_gate,
                                        predicted_c, up, p.obs.measurement);
      // A start's tilt is measured up to start_tilt_max_deg, wider than the channel's gate.
      if (aligning && gateSunMeasurement(alignment_gate_, predicted_c, up, p.obs.measurement) ==
                          GateResult::kAccepted) {
        // up_w = C_w_b C_b_k up_k.
        world_up_.add(window.T_w_b().linear() * window.T_k_b(s).linear().transpose() *
                          p.obs.measurement.sun_c,
                      p.obs.measurement.sigma);
        // An unknown world's up: the answer is held, it is what the up is measured from. A
        // start's tilt: the answer is also fused, and the alignment follows the corrections of
        // the base attitude (onSolved); the paper's form corrects none (it moves the relative
        // rotations), so there the answer is held too.
        if (!options_.levelsStartTilt() || !estimate) {
          p.decided = true;
          p.accepted = false;
          continue;
        }
      }
      if (r == GateResult::kAccepted && estimate) {
        p.cost = setSunCost(ring, sun_b, p.obs.measurement);
        cost_built = true;
        Innovation inn;
        const bool finite = innovation(*p.cost, window.T_k_b(s), prior, &inn);
        if (finite) last_nis_ = inn.nis;
        if (p.obs.measurement.kind != SunMeasurementKind::kAzimuthOnly && inn.dof == 3) {
          inn.radial = p.obs.measurement.sun_c.normalized();
        }
        if (channel == 1 && bankUpBias()) {
          // J = W [s_k]x C_k_b (the base correction's Jacobian), so W [s_k]x = J C_b_k.
          const Eigen::Matrix3d W_s = inn.J * window.T_k_b(s).linear().transpose();
          inn.J_up << W_s.col(0), W_s.col(2);
          inn.up_bias_removed = p.up_bias_removed;
        }
        if (!finite ||
            (options_.innovation_gate_chi2 > 0.0 && inn.nis > options_.innovation_gate_chi2)) {
          r = GateResult::kRejectedInnovation;
        } else if (options_.max_correction_deg > 0.0 &&
                   inn.move_b.norm() > options_.max_correction_deg * kDeg) {
          r = GateResult::kRejectedCorrection;
        } else {
          adaptDrift(inn, window.T_w_b().linear(), channel);
        }
      }
      if (channel == 0) {
        counters_.count(r);
        last_decision_ = r;
      } else {
        vertical_counters_.count(r);
      }
      p.decided = true;
      p.accepted = r == GateResult::kAccepted;
    }
    if (!p.accepted || p.consumed) continue;
    // The base may have moved since the last solve (the window slid), so s_b is rebuilt each time.
    if (!cost_built) p.cost = setSunCost(ring, sun_b, p.obs.measurement);
    if (estimate) {
      double* extra[] = {delta_.data(), bias_block};
      SUNVO_RETURN_IF_ERROR(window.addResidual(
          s, p.cost, loss_.get(), std::span<double* const>(extra, bias_block ? 2 : 1)));
      p.consumed = true;
      used_in_solve_[static_cast<std::size_t>(num_used_++)] = static_cast<int>(ring);
    } else {
      SUNVO_RETURN_IF_ERROR(window.addPoseResidual(s, p.cost, loss_.get()));
    }
  }
  if (estimate && num_used_ > 0 && num_active_ > 3) {
    // Square-root information of the joint prior over (delta_b, the bias corrections).
    const ActiveMatrix info = prior.inverse();
    joint_prior_L_.topLeftCorner(num_active_, num_active_) =
        Eigen::LLT<ActiveMatrix>(info).matrixU();
    std::array<double*, 3> extra{delta_.data()};
    std::size_t blocks = 1;
    if (biasEnabled()) extra[blocks++] = &bias_delta_;
    if (upBiasEnabled()) extra[blocks++] = up_bias_delta_.data();
    SUNVO_RETURN_IF_ERROR(window.addResidual(-1, joint_prior_cost_.get(), nullptr,
                                             std::span<double* const>(extra.data(), blocks)));
  } else if (estimate && num_used_ > 0) {
    // Square-root information of the prior: L^T L = P_b^-1.
    const Eigen::Matrix3d info = P_b.inverse();
    const Eigen::Matrix3d L = Eigen::LLT<Eigen::Matrix3d>(info).matrixU();
    prior_->set(L);
    double* extra[] = {delta_.data()};
    SUNVO_RETURN_IF_ERROR(window.addResidual(-1, prior_cost_.get(), nullptr, extra));
  }
  return Status::ok();
}

void SunWindowTerm::onSolved(backend::BundleWindow& window) {
  if (!options_.estimate_base_attitude || num_used_ == 0) return;
  // Information of the sun residuals about the active state (delta_b, the bias corrections) at
  // the solution; columns as in the solve's prior.
  const int n = num_active_;
  ActiveMatrix info = ActiveMatrix::Zero(n, n);
  Eigen::Matrix3d info_t = Eigen::Matrix3d::Zero();  // about delta_b alone (no bias state)
  for (int i = 0; i < num_used_; ++i) {
    const Pending& p =
        pending_[static_cast<std::size_t>(used_in_solve_[static_cast<std::size_t>(i)])];
    int slot = -1;
    for (int s = 1; s < window.size(); ++s) {
      if (window.sequence(s) == p.obs.measurement.sequence) slot = s;
    }
    if (slot < 0 || !p.cost) continue;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J_d;
    BiasJacobian J_b;
    Eigen::Vector3d r;
    int m = 0, cols = 0;
    // The cost's bias block at this solve's correction.
    const int channel = used_in_solve_[static_cast<std::size_t>(i)] % kChannels;
    if (!evaluateAt(*p.cost, window.T_k_b(slot), delta_.data(), biasBlock(channel), &r, &J_d, &J_b,
                    &cols, &m)) {
      continue;
    }
    const RowsJacobian J_t = J_d.topRows(m);
    info_t += J_t.transpose() * J_t;
    if (n == 3) continue;
    const ActiveJacobian J = activeJacobian(J_d, J_b, cols, m);
    info += J.transpose() * J;
  }
  const Eigen::Vector3d delta_b(delta_[0], delta_[1], delta_[2]);
  const double db = bias_delta_;
  const Eigen::Vector2d dc(up_bias_delta_[0], up_bias_delta_[1]);
  const int used = num_used_;
  delta_ = {0.0, 0.0, 0.0};
  bias_delta_ = 0.0;
  up_bias_delta_ = {0.0, 0.0};
  num_used_ = 0;
  if (!delta_b.allFinite() || !info.allFinite() || !info_t.allFinite() || !std::isfinite(db) ||
      !dc.allFinite()) {
    return;
  }
  const Eigen::Matrix3d C_w_b = window.T_w_b().linear();
  if (n > 3) {
    // The same update over the augmented state: T = diag(C_w_b, I) takes the information to the
    // world.
    ActiveMatrix T = ActiveMatrix::Identity(n, n);
    T.topLeftCorner<3, 3>() = C_w_b;
    const ActiveMatrix A = T * info * T.transpose();
    const ActiveMatrix Pn = activeCovariance(Eigen::Matrix3d::Identity());
    const ActiveMatrix M = (ActiveMatrix::Identity(n, n) + A * Pn).inverse() * A;
    ActiveMatrix P_new = Pn - Pn * M * Pn;
    P_new = 0.5 * (P_new + P_new.transpose());
    if (!P_new.allFinite() || !(P_new.diagonal().bottomRows(n - 3).minCoeff() >= 0.0)) return;
    setActiveCovariance(P_new);
    bias_ += db;
    up_bias_ += dc;
  } else {
    // information about dtheta_w
    const Eigen::Matrix3d A = C_w_b * info_t * C_w_b.transpose();
    // P <- (P^-1 + A)^-1, written as P - P (I + A P)^-1 A P: no inverse of a singular A (an
    // azimuth-only measurement informs one or two axes only).
    const Eigen::Matrix3d P_old = P();
    const Eigen::Matrix3d M = (Eigen::Matrix3d::Identity() + A * P_old).inverse() * A;
    Eigen::Matrix3d P_new = P_old - P_old * M * P_old;
    P_new = 0.5 * (P_new + P_new.transpose());
    if (!P_new.allFinite()) return;
    P() = P_new;
  }
  window.correctBaseAttitude(expSO3(delta_b));
  const Eigen::Vector3d c_w = C_w_b * delta_b;
  // The answers collected for the start's tilt were carried by the attitude just corrected.
  if (options_.levelsStartTilt() && !start_decided_) world_up_.turn(expSO3(c_w));
  last_correction_ = {window.sequence(window.size() - 1), c_w, used};
  ++num_corrections_;
  // The evidence sums describe the error left: each innovation r_i ~ H_i e becomes H_i (e - c_w).
  if (options_.drift_adaptation == DriftAdaptation::kEvidence) {
    persistence_g_ -= persistence_I_ * c_w;
  }
  if (tiltByEvidence()) vertical_g_ -= vertical_I_ * c_w;
  if (tiltByLikelihood()) tilt_bank_.shift(c_w);
  if (headingByLikelihood()) heading_bank_.shift(c_w);
}

std::optional<Eigen::Vector3d> SunWindowTerm::takeStartLevelling(std::uint64_t sequence) {
  if (!options_.levelsStartTilt() || start_decided_) return std::nullopt;
  world_up_.finishIfPast(sequence);
  if (!world_up_.done()) return std::nullopt;
  start_decided_ = true;
  // The answers measured u_est = C_w_ck up_ck with VO's attitude (turned by every correction
  // since); the truth is C_w_ck,true = Exp(e) C_w_ck with Exp(e) u_est = world_up, e normal to
  // both (the heading is not seen).
  const Eigen::Vector3d e = world_up_.tiltCorrection();
  const double sigma = world_up_.sigma();
  if (!e.allFinite() || !(sigma > 0.0)) return std::nullopt;
  // What is left is the filter's to take unless the answers say it is there: e has two dof
  // (normal to the up), each with the mean's sigma.
  if (e.squaredNorm() <= kStartTiltChi2 * sigma * sigma) return std::nullopt;
  levelled_ = true;
  // The tilt part of P is now the estimate's; the heading part (and its bias covariance) stays.
  const Eigen::Vector3d& u = options_.world_up;
  const Eigen::Matrix3d uu = u * u.transpose();
  const double s2 = sigma * sigma;
  P() = uu * P() * uu + s2 * (Eigen::Matrix3d::Identity() - uu);
  const Eigen::Matrix<double, 3, 3> P_tbias = uu * Pa_.topRightCorner<3, 3>();
  Pa_.topRightCorner<3, 3>() = P_tbias;
  Pa_.bottomLeftCorner<3, 3>() = P_tbias.transpose();
  if (tiltByLikelihood()) {
    // The tilt's bank chose its walk on answers that saw the start error; it starts again from
    // what the levelling left (P's tilt part) and its prior's walk.
    tilt_bank_.restart(P());
    drift_deg_per_frame_ = bankTiltDrift();
  }
  if (headingByLikelihood()) heading_bank_.shift(e);
  last_correction_ = {sequence, e, world_up_.used()};
  ++num_corrections_;
  return e;
}

bool SunWindowTerm::splitByGravity() const {
  return options_.split_drift_by_gravity &&
         options_.drift_adaptation == DriftAdaptation::kPersistence;
}

void SunWindowTerm::propagate(double frames) {
  if (biasEnabled() || upBiasEnabled()) {
    // Gauss-Markov: each bias estimate and its covariances decay by its phi, its variance relaxes
    // to its sigma^2 (a bias that is not a state keeps zero rows).
    const double phi_b = std::exp(-frames / options_.sun_bias_length_frames);
    const double phi_c = std::exp(-frames / options_.vertical_bias_length_frames);
    Eigen::Matrix<double, kAugmented, 1> phi;
    phi << 1.0, 1.0, 1.0, phi_b, phi_c, phi_c;
    bias_ *= phi_b;
    up_bias_ *= phi_c;
    Pa_ = phi.asDiagonal() * Pa_ * phi.asDiagonal();
    if (biasEnabled()) {
      const double sigma_b = options_.sun_bias_sigma_deg * kDeg;
      Pa_(kSunBias, kSunBias) += (1.0 - phi_b * phi_b) * sigma_b * sigma_b;
    }
    if (upBiasEnabled()) {
      const double sigma_c = options_.vertical_bias_sigma_deg * kDeg;
      for (int i = kUpBias; i < kUpBias + 2; ++i)
        Pa_(i, i) += (1.0 - phi_c * phi_c) * sigma_c * sigma_c;
    }
  }
  if (tiltByLikelihood()) tilt_bank_.propagate(frames, worldUp());
  if (headingByLikelihood()) {
    // The heading bank's members walk in tilt as the truth does once they take the cue's answers
    // in at its noise scale: the tilt bank's own walk, not the fusion's gain-matched one.
    const bool cue_in = vertical_in_sums_ && tiltByLikelihood();
    heading_bank_.propagate(frames, worldUp(),
                            cue_in ? tilt_bank_.tiltWalk() : drift_deg_per_frame_ * kDeg);
  }
  const double q = drift_deg_per_frame_ * kDeg;
  if (!splitByGravity() || heading_drift_deg_per_frame_ == drift_deg_per_frame_) {
    P() += Eigen::Matrix3d::Identity() * q * q * frames;
    return;
  }
  // Tilt (the plane normal to the world's up) and heading (about it) walk apart.
  const Eigen::Vector3d& u = worldUp();
  const double qh = heading_drift_deg_per_frame_ * kDeg;
  const Eigen::Matrix3d uu = u * u.transpose();
  P() += (q * q * (Eigen::Matrix3d::Identity() - uu) + qh * qh * uu) * frames;
}

bool SunWindowTerm::evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                               const double* delta_b, const double* bias, Eigen::Vector3d* r,
                               Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d,
                               BiasJacobian* J_bias, int* bias_cols, int* m) {
  const Eigen::Quaterniond q(T_k_b.linear());
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_q;
  // The bias block's Jacobian, m x cols row-major; at most 3 x 2.
  std::array<double, 6> J_b{};
  const std::vector<std::int32_t>& sizes = cost.parameter_block_sizes();
  *bias_cols = sizes.size() > 2 ? sizes[2] : 0;
  const double* params[] = {q.coeffs().data(), delta_b, bias};
  double* jacobians[] = {J_q.data(), J_d->data(), J_b.data()};
  *m = cost.num_residuals();
  if (!cost.Evaluate(params, r->data(), jacobians)) return false;
  J_bias->setZero();
  for (int i = 0; i < *m; ++i) {
    for (int j = 0; j < *bias_cols; ++j)
      (*J_bias)(i, j) = J_b[static_cast<std::size_t>(i * *bias_cols + j)];
  }
  return r->head(*m).allFinite() && J_d->topRows(*m).allFinite() && J_bias->allFinite();
}

bool SunWindowTerm::innovation(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                               const ActiveMatrix& P, Innovation* out) const {
  const double zero[3] = {0.0, 0.0, 0.0};
  int n = 0, cols = 0;
  BiasJacobian J_b;
  if (!evaluateAt(cost, T_k_b, zero, zero, &out->r, &out->J, &J_b, &cols, &n) || n <= 0) {
    return false;
  }
  out->dof = n;
  const RowsJacobian J = out->J.topRows(n);
  const RowsVector rn = out->r.head(n);
  if (P.rows() > 3) {
    // Over the active state: S = J_a P J_a^T + I, the bias states' share included; the predicted
    // correction of delta_b is the top of P J_a^T S^-1 r.
    const ActiveJacobian J_a = activeJacobian(out->J, J_b, cols, n);
    const RowsSquare S = J_a * P * J_a.transpose() + RowsSquare::Identity(n, n);
    const RowsVector Sinv_r = S.ldlt().solve(rn);
    out->nis = rn.dot(Sinv_r);
    out->move_b = (P * J_a.transpose() * Sinv_r).head<3>();
  } else {
    const Eigen::Matrix3d P_b = P.topLeftCorner<3, 3>();
    const RowsSquare S = J * P_b * J.transpose() + RowsSquare::Identity(n, n);
    const RowsVector Sinv_r = S.ldlt().solve(rn);
    out->nis = rn.dot(Sinv_r);
    out->move_b = P_b * J.transpose() * Sinv_r;
  }
  return std::isfinite(out->nis) && out->move_b.allFinite();
}

SunWindowTerm::ActiveJacobian SunWindowTerm::activeJacobian(
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>& J_d, const BiasJacobian& J_b, int cols,
    int m) const {
  ActiveJacobian J = ActiveJacobian::Zero(m, num_active_);
  J.leftCols(3) = J_d.topRows(m);
  if (cols > 0) {
    const int first = cols == 1 ? 3 : 3 + (biasEnabled() ? 1 : 0);
    J.middleCols(first, cols) = J_b.topLeftCorner(m, cols);
  }
  return J;
}

double* SunWindowTerm::biasBlock(int channel) {
  if (channel == 0) return biasEnabled() ? &bias_delta_ : nullptr;
  return upBiasEnabled() ? up_bias_delta_.data() : nullptr;
}

SunWindowTerm::ActiveMatrix SunWindowTerm::activeCovariance(const Eigen::Matrix3d& C) const {
  ActiveMatrix P(num_active_, num_active_);
  for (int i = 0; i < num_active_; ++i) {
    for (int j = 0; j < num_active_; ++j) {
      P(i, j) = Pa_(active_[static_cast<std::size_t>(i)], active_[static_cast<std::size_t>(j)]);
    }
  }
  // The attitude's rows and columns in C's frame.
  const Eigen::Matrix3d P_t = Pa_.topLeftCorner<3, 3>();
  P.topLeftCorner<3, 3>() = C * P_t * C.transpose();
  const int b = num_active_ - 3;
  if (b > 0) {
    P.topRightCorner(3, b) = C * P.topRightCorner(3, b);
    P.bottomLeftCorner(b, 3) = P.topRightCorner(3, b).transpose();
  }
  return P;
}

void SunWindowTerm::setActiveCovariance(const ActiveMatrix& P) {
  for (int i = 0; i < num_active_; ++i) {
    for (int j = 0; j < num_active_; ++j) {
      Pa_(active_[static_cast<std::size_t>(i)], active_[static_cast<std::size_t>(j)]) = P(i, j);
    }
  }
}

}  // namespace sunvo::sunfusion
