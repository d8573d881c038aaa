#include "sunvo/sunfusion/sun_window_term.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

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
  P_ = Eigen::Matrix3d::Identity() * s0 * s0;
  bias_ = 0.0;
  bias_delta_ = 0.0;
  P_bb_ = biasEnabled() ? std::pow(options.sun_bias_sigma_deg * kDeg, 2) : 0.0;
  P_tb_.setZero();
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
    WalkBankOptions bank;
    bank.q_min_rad = options.min_drift_deg_per_frame * kDeg;
    bank.q_max_rad = options.vertical_max_drift_deg_per_frame * kDeg;
    bank.walks = options.likelihood_walks;
    bank.noise_min = options.likelihood_noise_min;
    bank.noise_max = options.likelihood_noise_max;
    bank.noise_scales = options.likelihood_noise_scales;
    bank.initial_sigma_rad = s0;
    bank.forgetting = options.likelihood_forgetting;
    SUNVO_RETURN_IF_ERROR(tilt_bank_.init(bank));
  }
  alignment_gate_ = options.vertical_gate;
  if (options.levelsStartTilt()) {
    alignment_gate_.max_cosine_distance =
        std::max(options.vertical_gate.max_cosine_distance,
                 1.0 - std::cos(options.start_tilt_max_deg * kDeg));
  }
  // Every cost a slot can need, in the form the options ask for (the only allocations).
  const SunResidualForm form = !options.estimate_base_attitude ? SunResidualForm::kPaper
                               : biasEnabled() ? SunResidualForm::kBaseCorrectionAndBias
                                               : SunResidualForm::kBaseCorrection;
  for (std::size_t i = 0; i < kSlots; ++i) {
    // The vertical channel (odd slots) has no bias state.
    const SunResidualForm f = form == SunResidualForm::kBaseCorrectionAndBias && i % kChannels != 0
                                  ? SunResidualForm::kBaseCorrection
                                  : form;
    CostSlot& c = costs_[i];
    c.direction = new SunDirectionResidual(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), 1.0);
    c.direction_cost.reset(wrapSunResidual<SunDirectionResidual, 3>(c.direction, f));
    c.azimuth = new SunAzimuthResidual(Eigen::Vector3d::UnitZ(), Eigen::Vector2d::UnitY(), 1.0);
    c.azimuth_cost.reset(wrapSunResidual<SunAzimuthResidual, 2>(c.azimuth, f));
  }
  prior_ = new AttitudePriorResidual(Eigen::Matrix3d::Identity());
  prior_cost_.reset(new ceres::AutoDiffCostFunction<AttitudePriorResidual, 3, 3>(prior_));
  bias_prior_ = new AttitudeBiasPriorResidual(Eigen::Matrix4d::Identity());
  bias_prior_cost_.reset(
      new ceres::AutoDiffCostFunction<AttitudeBiasPriorResidual, 4, 3, 1>(bias_prior_));
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
  num_used_ = 0;

  // Prior of this solve's base correction delta_b = C_b_w dtheta_w: N(0, C_b_w P_theta C_w_b),
  // jointly with the bias correction db ~ N(0, P_bb) when the bias is a state.
  const Eigen::Matrix3d C_b_w = window.T_w_b().linear().transpose();
  const Eigen::Matrix3d P_b = C_b_w * P_ * C_b_w.transpose();
  const BasePrior prior{P_b, C_b_w * P_tb_, P_bb_};
  const bool with_bias = biasEnabled();
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
    const bool bias_cost = with_bias && channel == 0;
    if (!p.decided) {
      Eigen::Vector3d predicted_c = window.T_k_b(s).linear() * sun_b;
      if (bias_cost) predicted_c = turnAboutCameraY(predicted_c, bias_);
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
      double* extra[] = {delta_.data(), &bias_delta_};
      SUNVO_RETURN_IF_ERROR(window.addResidual(s, p.cost, loss_.get(),
                                               std::span<double* const>(extra, bias_cost ? 2 : 1)));
      p.consumed = true;
      used_in_solve_[static_cast<std::size_t>(num_used_++)] = static_cast<int>(ring);
    } else {
      SUNVO_RETURN_IF_ERROR(window.addPoseResidual(s, p.cost, loss_.get()));
    }
  }
  if (estimate && num_used_ > 0 && with_bias) {
    Eigen::Matrix4d P4;
    P4 << P_b, prior.P_tb_b, prior.P_tb_b.transpose(), P_bb_;
    bias_prior_->set(Eigen::LLT<Eigen::Matrix4d>(P4.inverse()).matrixU());
    double* extra[] = {delta_.data(), &bias_delta_};
    SUNVO_RETURN_IF_ERROR(window.addResidual(-1, bias_prior_cost_.get(), nullptr, extra));
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
  // Information of the sun residuals about (delta_b, db) at the solution (db: zero column
  // without the bias state).
  Eigen::Matrix4d info4 = Eigen::Matrix4d::Zero();
  for (int i = 0; i < num_used_; ++i) {
    const Pending& p =
        pending_[static_cast<std::size_t>(used_in_solve_[static_cast<std::size_t>(i)])];
    int slot = -1;
    for (int s = 1; s < window.size(); ++s) {
      if (window.sequence(s) == p.obs.measurement.sequence) slot = s;
    }
    if (slot < 0 || !p.cost) continue;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J_d;
    Eigen::Vector3d J_b;
    Eigen::Vector3d r;
    int m = 0;
    if (!evaluateAt(*p.cost, window.T_k_b(slot), delta_.data(), bias_delta_, &r, &J_d, &J_b, &m)) {
      continue;
    }
    const RowsJacobian J = J_d.topRows(m);
    info4.topLeftCorner<3, 3>() += J.transpose() * J;
    if (biasEnabled()) {
      const RowsVector jb = J_b.head(m);
      info4.topRightCorner<3, 1>() += J.transpose() * jb;
      info4(3, 3) += jb.squaredNorm();
    }
  }
  info4.bottomLeftCorner<1, 3>() = info4.topRightCorner<3, 1>().transpose();
  const Eigen::Vector3d delta_b(delta_[0], delta_[1], delta_[2]);
  const double db = bias_delta_;
  const int used = num_used_;
  delta_ = {0.0, 0.0, 0.0};
  bias_delta_ = 0.0;
  num_used_ = 0;
  if (!delta_b.allFinite() || !info4.allFinite() || !std::isfinite(db)) return;
  const Eigen::Matrix3d C_w_b = window.T_w_b().linear();
  if (biasEnabled()) {
    // The same update over (dtheta_w, b): T = diag(C_w_b, 1) takes the information to the world.
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = C_w_b;
    const Eigen::Matrix4d A4 = T * info4 * T.transpose();
    Eigen::Matrix4d P4;
    P4 << P_, P_tb_, P_tb_.transpose(), P_bb_;
    const Eigen::Matrix4d M4 = (Eigen::Matrix4d::Identity() + A4 * P4).inverse() * A4;
    Eigen::Matrix4d P4_new = P4 - P4 * M4 * P4;
    P4_new = 0.5 * (P4_new + P4_new.transpose());
    if (!P4_new.allFinite() || !(P4_new(3, 3) >= 0.0)) return;
    P_ = P4_new.topLeftCorner<3, 3>();
    P_tb_ = P4_new.topRightCorner<3, 1>();
    P_bb_ = P4_new(3, 3);
    bias_ += db;
  } else {
    // information about dtheta_w
    const Eigen::Matrix3d A = C_w_b * info4.topLeftCorner<3, 3>() * C_w_b.transpose();
    // P <- (P^-1 + A)^-1, written as P - P (I + A P)^-1 A P: no inverse of a singular A (an
    // azimuth-only measurement informs one or two axes only).
    const Eigen::Matrix3d M = (Eigen::Matrix3d::Identity() + A * P_).inverse() * A;
    Eigen::Matrix3d P_new = P_ - P_ * M * P_;
    P_new = 0.5 * (P_new + P_new.transpose());
    if (!P_new.allFinite()) return;
    P_ = P_new;
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
  P_ = uu * P_ * uu + s2 * (Eigen::Matrix3d::Identity() - uu);
  P_tb_ = uu * P_tb_;
  if (tiltByLikelihood()) tilt_bank_.shift(e);
  last_correction_ = {sequence, e, world_up_.used()};
  ++num_corrections_;
  return e;
}

bool SunWindowTerm::splitByGravity() const {
  return options_.split_drift_by_gravity &&
         options_.drift_adaptation == DriftAdaptation::kPersistence;
}

void SunWindowTerm::propagate(double frames) {
  if (biasEnabled()) {
    // Gauss-Markov: the estimate and its covariance with the attitude decay, the variance relaxes
    // to sigma_b^2.
    const double phi = std::exp(-frames / options_.sun_bias_length_frames);
    const double sigma_b = options_.sun_bias_sigma_deg * kDeg;
    bias_ *= phi;
    P_tb_ *= phi;
    P_bb_ = phi * phi * P_bb_ + (1.0 - phi * phi) * sigma_b * sigma_b;
  }
  if (tiltByLikelihood()) tilt_bank_.propagate(frames, worldUp());
  const double q = drift_deg_per_frame_ * kDeg;
  if (!splitByGravity() || heading_drift_deg_per_frame_ == drift_deg_per_frame_) {
    P_ += Eigen::Matrix3d::Identity() * q * q * frames;
    return;
  }
  // Tilt (the plane normal to the world's up) and heading (about it) walk apart.
  const Eigen::Vector3d& u = worldUp();
  const double qh = heading_drift_deg_per_frame_ * kDeg;
  const Eigen::Matrix3d uu = u * u.transpose();
  P_ += (q * q * (Eigen::Matrix3d::Identity() - uu) + qh * qh * uu) * frames;
}

bool SunWindowTerm::evaluateAt(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                               const double* delta_b, double db, Eigen::Vector3d* r,
                               Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* J_d,
                               Eigen::Vector3d* J_bias, int* m) {
  const Eigen::Quaterniond q(T_k_b.linear());
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> J_q;
  J_bias->setZero();
  const double* params[] = {q.coeffs().data(), delta_b, &db};
  double* jacobians[] = {J_q.data(), J_d->data(), J_bias->data()};
  *m = cost.num_residuals();
  return cost.Evaluate(params, r->data(), jacobians) && r->head(*m).allFinite() &&
         J_d->topRows(*m).allFinite() && J_bias->head(*m).allFinite();
}

void SunWindowTerm::adaptDrift(const Innovation& inn, const Eigen::Matrix3d& C_w_b, int channel) {
  const int m = inn.dof;
  double step = 0.0;
  switch (options_.drift_adaptation) {
    case DriftAdaptation::kFixed:
      return;
    case DriftAdaptation::kInnovationMedian: {
      // With a consistent filter the NIS is chi-square with m dof and exceeds its median half of
      // the time: a stochastic approximation of the median, one step per measurement.
      const double median = m <= 1 ? 0.455 : (m == 2 ? 1.386 : 2.366);
      step = inn.nis > median ? options_.drift_adaptation_rate : -options_.drift_adaptation_rate;
      break;
    }
    case DriftAdaptation::kEvidence:
      accumulate(inn, C_w_b, &persistence_I_, &persistence_g_, options_.evidence_forgetting);
      persistence_T_ = inflateToEvidence(persistence_I_, persistence_g_);
      return;
    case DriftAdaptation::kPersistence: {
      // r ~ r0 + J delta_b and delta_b = C_b_w dtheta_w, so H = J C_b_w is the Jacobian wrt the
      // world-frame attitude error. If dtheta_w stayed constant while the filter ignores it, the
      // whitened innovations r_i ~ N(H_i dtheta_w, I) and the least-squares estimate from all of
      // them, I^+ g with g = sum H_i^T r_i and I = sum H_i^T H_i, has the chi-square statistic
      // T = g^T I^+ g with rank(I) dof when dtheta_w = 0 (noise only). The sums forget by
      // persistence_forgetting per measurement, so T weighs the recent drift; a Huber weight
      // caps an outlier's pull at persistence_huber sigmas per row. Once the vertical channel
      // steps the tilt's walk (split below), the sums forget on its answers only: a sun answer
      // between two of them would halve the memory of the cue's evidence the tilt's test reads.
      const bool forget = !(splitByGravity() && channel == 0 && vertical_in_sums_);
      accumulate(inn, C_w_b, &persistence_I_, &persistence_g_,
                 forget ? options_.persistence_forgetting : 1.0);
      std::size_t rank = 0;
      persistence_T_ = sunfusion::persistenceStatistic(persistence_I_, persistence_g_, &rank);
      step = rank > 0 && persistence_T_ > persistence_bound_[rank]
                 ? options_.persistence_step_up
                 : -options_.persistence_step_down;
      if (splitByGravity()) {
        // Each walk steps with the channel that measures it. The heading's on the sun's
        // measurements, from sums of the sun's alone: an "up" never sees the heading. The tilt's,
        // once a vertical measurement is in the sums, on the vertical channel's, up to that
        // channel's cap, on the tilt's part of the test of all channels' sums
        // (tiltPersistenceStatistic): a sun beside it that informs the tilt little (an
        // azimuth-only 15 deg beside a 0.1 deg "up") neither dilutes the test, nor holds the walk
        // to the sun's cap, nor steps it a second time per frame on the cue's evidence. Without
        // vertical measurements the sun steps both walks on the same test, as one.
        if (channel == 1 && tiltByEvidence()) {
          // P's tilt part is made to cover the error the cue's answers evidence, and q_tilt
          // stays at the floor: no walk to trail a steady drift.
          vertical_in_sums_ = true;
          accumulate(inn, C_w_b, &vertical_I_, &vertical_g_, options_.evidence_forgetting);
          inflateToEvidence(vertical_I_, vertical_g_);
          drift_deg_per_frame_ = options_.min_drift_deg_per_frame;
        } else if (channel == 1 && tiltByLikelihood()) {
          // The walk the cue's innovations make most likely (walk_bank.hpp), an outlier's pull
          // capped as in the sums.
          vertical_in_sums_ = true;
          const Eigen::Matrix3d H = inn.J * C_w_b.transpose();
          tilt_bank_.update(H, huberWeight(inn) * inn.r, inn.dof);
          drift_deg_per_frame_ =
              std::clamp(tilt_bank_.walk() / kDeg, options_.min_drift_deg_per_frame,
                         options_.vertical_max_drift_deg_per_frame);
        } else if (channel == 1) {
          vertical_in_sums_ = true;
          std::size_t tilt_rank = 0;
          const double T_tilt =
              tiltPersistenceStatistic(persistence_I_, persistence_g_, worldUp(), &tilt_rank);
          const double step_t = tilt_rank > 0 && T_tilt > persistence_bound_[tilt_rank]
                                    ? options_.persistence_step_up
                                    : -options_.persistence_step_down;
          drift_deg_per_frame_ =
              stepDrift(drift_deg_per_frame_, step_t, options_.vertical_max_drift_deg_per_frame);
        } else if (!vertical_in_sums_) {
          drift_deg_per_frame_ = clampDrift(drift_deg_per_frame_ * std::exp(step));
        }
        if (channel == 0) {
          accumulate(inn, C_w_b, &sun_I_, &sun_g_, options_.persistence_forgetting);
          std::size_t sun_rank = 0;
          const double T = sunfusion::persistenceStatistic(sun_I_, sun_g_, &sun_rank);
          const double step_h = sun_rank > 0 && T > persistence_bound_[sun_rank]
                                    ? options_.persistence_step_up
                                    : -options_.persistence_step_down;
          heading_drift_deg_per_frame_ =
              clampDrift(heading_drift_deg_per_frame_ * std::exp(step_h));
        }
        return;
      }
      break;
    }
  }
  drift_deg_per_frame_ = clampDrift(drift_deg_per_frame_ * std::exp(step));
}

double SunWindowTerm::clampDrift(double q) const {
  return std::clamp(q, options_.min_drift_deg_per_frame, options_.max_drift_deg_per_frame);
}

double SunWindowTerm::stepDrift(double q, double step, double cap) const {
  const double next = q * std::exp(step);
  const double upper = step > 0.0 ? std::max(cap, q) : next;
  return std::max(std::min(next, upper), options_.min_drift_deg_per_frame);
}

bool SunWindowTerm::tiltByEvidence() const {
  return splitByGravity() &&
         options_.vertical_drift_adaptation == VerticalDriftAdaptation::kEvidence;
}

bool SunWindowTerm::tiltByLikelihood() const {
  return splitByGravity() &&
         options_.vertical_drift_adaptation == VerticalDriftAdaptation::kLikelihood;
}

double SunWindowTerm::huberWeight(const Innovation& inn) const {
  const double cap = options_.persistence_huber * std::sqrt(static_cast<double>(inn.dof));
  const double norm = inn.r.head(inn.dof).norm();
  return norm > cap ? cap / norm : 1.0;
}

void SunWindowTerm::accumulate(const Innovation& inn, const Eigen::Matrix3d& C_w_b,
                               Eigen::Matrix3d* I, Eigen::Vector3d* g, double lambda) const {
  // Fixed-size, with the rows past m zero (no heap allocation).
  const int m = inn.dof;
  Eigen::Matrix3d J = inn.J;
  Eigen::Vector3d r = inn.r;
  J.bottomRows(3 - m).setZero();
  r.tail(3 - m).setZero();
  const Eigen::Matrix3d H = J * C_w_b.transpose();
  *g = lambda * *g + H.transpose() * (huberWeight(inn) * r);
  *I = lambda * *I + H.transpose() * H;
}

double SunWindowTerm::inflateToEvidence(const Eigen::Matrix3d& I, const Eigen::Vector3d& g) {
  // Along each well-informed direction v of I: e = v^T g / l estimates the error left, with
  // variance 1/l under noise alone. A significant e that P does not cover (v^T P v < e^2) widens P
  // along v to e^2, so that the following measurements may remove it; P never shrinks here.
  // Directions with less than a tenth of the strongest information are left alone: an
  // azimuth-only source barely informs some, and a few outliers would make e large there.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  const double floor = 0.1 * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  double T = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double l = eig.eigenvalues()(i);
    if (!(l > floor)) continue;
    const Eigen::Vector3d v = eig.eigenvectors().col(i);
    const double e = v.dot(g) / l;
    T += e * e * l;
    const double deficit = e * e - v.dot(P_ * v);
    const double bound = options_.evidence_sigmas * options_.evidence_sigmas;
    if (e * e * l > bound * options_.evidence_correlation && deficit > 0.0 &&
        std::isfinite(deficit)) {
      P_ += deficit * v * v.transpose();
      ++num_inflations_;
    }
  }
  return T;
}

bool SunWindowTerm::innovation(const ceres::CostFunction& cost, const Isometry3& T_k_b,
                               const BasePrior& prior, Innovation* out) {
  const double zero[3] = {0.0, 0.0, 0.0};
  int n = 0;
  if (!evaluateAt(cost, T_k_b, zero, 0.0, &out->r, &out->J, &out->J_bias, &n) || n <= 0) {
    return false;
  }
  out->dof = n;
  const RowsJacobian J = out->J.topRows(n);
  RowsSquare S = J * prior.P_b * J.transpose() + RowsSquare::Identity(n, n);
  const RowsVector rn = out->r.head(n);
  if (prior.P_bb > 0.0) {
    // S += J P_tb jb^T + jb P_tb^T J^T + P_bb jb jb^T: the bias's share of the innovation.
    const RowsVector jb = out->J_bias.head(n);
    const RowsVector Jp = J * prior.P_tb_b;
    S += Jp * jb.transpose() + jb * Jp.transpose() + prior.P_bb * jb * jb.transpose();
    const RowsVector Sinv_r = S.ldlt().solve(rn);
    out->nis = rn.dot(Sinv_r);
    out->move_b = (prior.P_b * J.transpose() + prior.P_tb_b * jb.transpose()) * Sinv_r;
  } else {
    const RowsVector Sinv_r = S.ldlt().solve(rn);
    out->nis = rn.dot(Sinv_r);
    out->move_b = prior.P_b * J.transpose() * Sinv_r;
  }
  return std::isfinite(out->nis) && out->move_b.allFinite();
}

}  // namespace sunvo::sunfusion
