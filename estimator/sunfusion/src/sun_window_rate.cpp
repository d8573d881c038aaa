// SunWindowTerm between answers: the covariance's propagation over new frames, VO's steady drift
// (the rate state, attitude_rate_sigma_deg) and what a correction of the estimate means to the
// filters that track the error left (sun_window_term.hpp, header comment).
#include <Eigen/Cholesky>
#include <cmath>

#include "sunvo/core/geometry.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"

namespace sunvo::sunfusion {
namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

Eigen::Vector3d SunWindowTerm::propagate(double frames, const Eigen::Matrix3d& C_w_c) {
  Eigen::Vector3d step_w = Eigen::Vector3d::Zero();
  if (rateEnabled()) {
    // dtheta_w <- dtheta_w + G rho, G = frames C_w_c: P <- F P F^T with F the identity but for G
    // from rho's rows to dtheta_w's, done as (F P) then (F P) F^T.
    const Eigen::Matrix3d G = frames * C_w_c;
    step_w = G * rate_;
    Pa_.topRows<3>() += G * Pa_.middleRows<3>(kRate);
    Pa_.leftCols<3>() += Pa_.middleCols<3>(kRate) * G.transpose();
  }
  if (biasEnabled() || upBiasEnabled() || rateEnabled()) {
    // Gauss-Markov: each bias's and the rate's estimate and covariances decay by its phi, its
    // variance relaxes to its sigma^2 (a state that is off keeps zero rows).
    const double phi_b = std::exp(-frames / options_.sun_bias_length_frames);
    const double phi_c = std::exp(-frames / options_.vertical_bias_length_frames);
    const double phi_r = std::exp(-frames / options_.attitude_rate_length_frames);
    Eigen::Matrix<double, kAugmented, 1> phi;
    phi << 1.0, 1.0, 1.0, phi_b, phi_c, phi_c, phi_r, phi_r, phi_r;
    bias_ *= phi_b;
    up_bias_ *= phi_c;
    rate_ *= phi_r;
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
    if (rateEnabled()) {
      const double sigma_r = options_.attitude_rate_sigma_deg * kDeg;
      for (int i = kRate; i < kRate + 3; ++i)
        Pa_(i, i) += (1.0 - phi_r * phi_r) * sigma_r * sigma_r;
    }
  }
  if (tiltByLikelihood()) tilt_bank_.propagate(frames, worldUp());
  const double q = drift_deg_per_frame_ * kDeg;
  if (!splitByGravity() || heading_drift_deg_per_frame_ == drift_deg_per_frame_) {
    P() += Eigen::Matrix3d::Identity() * q * q * frames;
    return step_w;
  }
  // Tilt (the plane normal to the world's up) and heading (about it) walk apart.
  const Eigen::Vector3d& u = worldUp();
  const double qh = heading_drift_deg_per_frame_ * kDeg;
  const Eigen::Matrix3d uu = u * u.transpose();
  P() += (q * q * (Eigen::Matrix3d::Identity() - uu) + qh * qh * uu) * frames;
  return step_w;
}

void SunWindowTerm::noteCorrection(const Eigen::Vector3d& c_w) {
  // The answers collected for the start's tilt were carried by the attitude just corrected.
  if (options_.levelsStartTilt() && !start_decided_) world_up_.turn(expSO3(c_w));
  // The evidence sums describe the error left: each innovation r_i ~ H_i e becomes H_i (e - c_w).
  if (options_.drift_adaptation == DriftAdaptation::kEvidence) {
    persistence_g_ -= persistence_I_ * c_w;
  }
  if (tiltByEvidence()) vertical_g_ -= vertical_I_ * c_w;
  if (tiltByLikelihood()) tilt_bank_.shift(c_w);
}

void SunWindowTerm::updateRate(const ActiveMatrix& Pn, const ActiveMatrix& M,
                               const ActiveVector& dx) {
  const int n = num_active_;
  // P_ra: rho's covariance with the active state (world frame: dtheta_w is kept there).
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 6> P_ra(3, n);
  for (int j = 0; j < n; ++j)
    P_ra.col(j) = Pa_.block<3, 1>(kRate, active_[static_cast<std::size_t>(j)]);
  const Eigen::Vector3d d_rate = P_ra * Pn.ldlt().solve(dx);
  Eigen::Matrix3d P_rr = Pa_.block<3, 3>(kRate, kRate) - P_ra * M * P_ra.transpose();
  P_rr = 0.5 * (P_rr + P_rr.transpose());
  const Eigen::Matrix<double, Eigen::Dynamic, 3, 0, 6, 3> P_ar =
      P_ra.transpose() - Pn * M * P_ra.transpose();
  if (!d_rate.allFinite() || !P_rr.allFinite() || !P_ar.allFinite() ||
      !(P_rr.diagonal().minCoeff() >= 0.0)) {
    return;
  }
  rate_ += d_rate;
  Pa_.block<3, 3>(kRate, kRate) = P_rr;
  for (int j = 0; j < n; ++j) {
    const int a = active_[static_cast<std::size_t>(j)];
    Pa_.block<3, 1>(kRate, a) = P_ar.row(j).transpose();
    Pa_.block<1, 3>(a, kRate) = P_ar.row(j);
  }
}

}  // namespace sunvo::sunfusion
