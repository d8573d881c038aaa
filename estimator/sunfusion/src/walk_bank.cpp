#include "sunvo/sunfusion/walk_bank.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace sunvo::sunfusion {
namespace {

// n log-spaced values over [lo, hi] (lo alone when n == 1), as logarithms.
template <std::size_t N>
void logSpaced(double lo, double hi, int n, std::array<double, N>* out) {
  const double step = n > 1 ? std::log(hi / lo) / (n - 1) : 0.0;
  for (int i = 0; i < n; ++i) (*out)[static_cast<std::size_t>(i)] = std::log(lo) + step * i;
}

}  // namespace

Status WalkBank::init(const WalkBankOptions& o) {
  if (!(o.q_min_rad > 0.0 && o.q_max_rad >= o.q_min_rad && std::isfinite(o.q_max_rad))) {
    return invalidArgument("walk bank: need 0 < q_min <= q_max");
  }
  if (o.walks < 2 || o.walks > kMaxWalks) return invalidArgument("walk bank: walks out of range");
  if (!(o.noise_min > 0.0 && o.noise_max >= o.noise_min && std::isfinite(o.noise_max))) {
    return invalidArgument("walk bank: need 0 < noise_min <= noise_max");
  }
  if (o.noise_scales < 1 || o.noise_scales > kMaxScales) {
    return invalidArgument("walk bank: noise scales out of range");
  }
  if (!(o.initial_sigma_rad > 0.0) || !(o.forgetting > 0.0 && o.forgetting <= 1.0)) {
    return invalidArgument("walk bank: initial sigma or forgetting out of range");
  }
  if (o.up_bias_scales < 1 || o.up_bias_scales > kMaxBiasScales) {
    return invalidArgument("walk bank: up bias scales out of range");
  }
  if (o.up_bias_scales > 1 && !(o.up_bias_max_rad > 0.0 && std::isfinite(o.up_bias_max_rad))) {
    return invalidArgument("walk bank: need up_bias_max > 0 with a bias axis");
  }
  if (!(o.up_bias_length_frames >= 1.0 && o.up_bias_length_frames <= 1e7)) {
    return invalidArgument("walk bank: up bias length out of range");
  }
  walks_ = o.walks;
  scales_ = o.noise_scales;
  biases_ = o.up_bias_scales;
  forgetting_ = o.forgetting;
  bias_length_ = o.up_bias_length_frames;
  heading_ = o.heading;
  logSpaced(o.q_min_rad, o.q_max_rad, walks_, &log_q_);
  logSpaced(o.noise_min, o.noise_max, scales_, &log_s_);
  // 0, then halving down to the widest: 0, max / 4, max / 2, max with four.
  bias_sigma_[0] = 0.0;
  for (int l = 1; l < biases_; ++l) {
    bias_sigma_[static_cast<std::size_t>(l)] = o.up_bias_max_rad * std::pow(0.5, biases_ - 1 - l);
  }
  restart(Eigen::Matrix3d::Identity() * o.initial_sigma_rad * o.initial_sigma_rad);
  return Status::ok();
}

void WalkBank::restart(const Eigen::Matrix3d& P_e) {
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double sigma_c = bias_sigma_[biasOf(k)];
    loglik_[i] = 0.0;
    x_[i].setZero();
    P_[i].setZero();
    P_[i].topLeftCorner<3, 3>() = P_e;
    P_[i].bottomRightCorner<2, 2>() = Eigen::Matrix2d::Identity() * sigma_c * sigma_c;
  }
}

void WalkBank::propagate(double frames, const Eigen::Vector3d& up, double other_q) {
  const Eigen::Matrix3d uu = up * up.transpose();
  const Eigen::Matrix3d tilt_plane = Eigen::Matrix3d::Identity() - uu;
  const Eigen::Matrix3d& walk_space = heading_ ? uu : tilt_plane;
  const Eigen::Matrix3d& other_space = heading_ ? tilt_plane : uu;
  const double phi = std::exp(-frames / bias_length_);
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double q = std::exp(log_q_[walkOf(k)]);
    P_[i].topLeftCorner<3, 3>() += q * q * frames * walk_space;
    if (other_q > 0.0) P_[i].topLeftCorner<3, 3>() += other_q * other_q * frames * other_space;
    if (biases_ == 1) continue;
    // Gauss-Markov: c and its covariances decay by phi, its variance relaxes to sigma_l^2.
    const double sigma_c = bias_sigma_[biasOf(k)];
    x_[i].tail<2>() *= phi;
    P_[i].topRightCorner<3, 2>() *= phi;
    P_[i].bottomLeftCorner<2, 3>() *= phi;
    P_[i].bottomRightCorner<2, 2>() *= phi * phi;
    P_[i].bottomRightCorner<2, 2>() +=
        Eigen::Matrix2d::Identity() * (1.0 - phi * phi) * sigma_c * sigma_c;
  }
}

namespace {

// One member's Kalman update over its first N states (3: e alone, 5: e and c) with noise s^2 on
// the m rows; false (the member left alone) if anything is not finite.
template <int N, class X, class P>
bool updateMember(const Eigen::Matrix<double, 3, N>& H, const Eigen::Vector3d& r, int m, double s,
                  X x, P cov, double* l_out) {
  Eigen::Matrix3d S = H * cov * H.transpose();
  for (int row = 0; row < 3; ++row) S(row, row) += row < m ? s * s : 1.0;
  const Eigen::LLT<Eigen::Matrix3d> llt(S);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Vector3d nu = r - H * x;
  const Eigen::Matrix3d L = llt.matrixL();
  const double log_det = 2.0 * L.diagonal().array().log().sum();
  const double l = -0.5 * (nu.dot(llt.solve(nu)) + log_det);
  const Eigen::Matrix<double, N, 3> K = llt.solve(H * cov).transpose();  // P H^T S^-1
  const Eigen::Matrix<double, N, 1> x_new = x + K * nu;
  Eigen::Matrix<double, N, N> P_new = cov - K * H * cov;
  P_new = 0.5 * (P_new + P_new.transpose());
  if (!std::isfinite(l) || !x_new.allFinite() || !P_new.allFinite()) return false;
  *l_out = l;
  x = x_new;
  cov = P_new;
  return true;
}

}  // namespace

void WalkBank::update(const Eigen::Matrix3d& H, const BiasJacobian& H_c, const Eigen::Vector3d& r,
                      int m) {
  updateMembers(H, H_c, r, m, std::nullopt);
}

void WalkBank::absorb(const Eigen::Matrix3d& H, const Eigen::Vector3d& r, int m, double s) {
  if (!(s > 0.0) || !std::isfinite(s)) return;
  updateMembers(H, BiasJacobian::Zero(), r, m, s);
}

void WalkBank::updateMembers(const Eigen::Matrix3d& H, const BiasJacobian& H_c,
                             const Eigen::Vector3d& r, int m, std::optional<double> other_s) {
  if (walks_ == 0 || m < 1 || m > 3 || !H.allFinite() || !H_c.allFinite() || !r.allFinite()) {
    return;
  }
  // Rows past m zero, with unit noise there: they add nothing (fixed size, no allocation).
  Eigen::Matrix3d Hm = H;
  Eigen::Vector3d rm = r;
  Hm.bottomRows(3 - m).setZero();
  rm.tail(3 - m).setZero();
  Eigen::Matrix<double, 3, 5> H5;
  H5 << Hm, H_c;
  H5.bottomRows(3 - m).setZero();
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double s = other_s ? *other_s : std::exp(log_s_[scaleOf(k)]);
    double l = 0.0;
    // Without a bias axis the members are filters of e alone (the same arithmetic as before it).
    const bool ok =
        biases_ == 1
            ? updateMember<3>(Hm, rm, m, s, x_[i].head<3>(), P_[i].topLeftCorner<3, 3>(), &l)
            : updateMember<5>(H5, rm, m, s, x_[i].head<5>(), P_[i].topLeftCorner<5, 5>(), &l);
    // The other channel's answers inform the states only: the walk is chosen by this bank's own.
    if (ok && !other_s) loglik_[i] = forgetting_ * loglik_[i] + l;
  }
}

void WalkBank::shift(const Eigen::Vector3d& c_w) {
  if (!c_w.allFinite()) return;
  for (int k = 0; k < members(); ++k) x_[static_cast<std::size_t>(k)].head<3>() -= c_w;
}

// The prior: each walk as likely as 1/q (q_min's as likely as all the others together, about):
// the fusion starts near the slow end and a faster walk must be earned by the innovations, as
// the persistence rule's walk sinks under noise alone. A cue without a bias is as likely as all
// the biased ones together. It is not forgotten.
double WalkBank::logPosterior(int k) const {
  const double bias_prior = biasOf(k) == 0 ? 0.0 : -std::log(static_cast<double>(biases_ - 1));
  return loglik_[static_cast<std::size_t>(k)] - (log_q_[walkOf(k)] - log_q_[0]) + bias_prior;
}

double WalkBank::maxLogPosterior() const {
  double top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < members(); ++k) top = std::max(top, logPosterior(k));
  return top;
}

double WalkBank::posteriorWeights(std::array<double, kMax>* w) const {
  const double top = maxLogPosterior();
  double sum = 0.0;
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    (*w)[i] = std::exp(logPosterior(k) - top);
    sum += (*w)[i];
  }
  return sum;
}

double WalkBank::weight(int member) const {
  if (member < 0 || member >= members()) return 0.0;
  std::array<double, kMax> w;
  const double sum = posteriorWeights(&w);
  return w[static_cast<std::size_t>(member)] / sum;
}

double WalkBank::mean(bool walk_part, bool noise_part) const {
  if (walks_ == 0) return 0.0;
  std::array<double, kMax> w;
  const double sum = posteriorWeights(&w);
  double log_value = 0.0;
  for (int k = 0; k < members(); ++k) {
    const double term =
        (walk_part ? log_q_[walkOf(k)] : 0.0) - (noise_part ? log_s_[scaleOf(k)] : 0.0);
    log_value += w[static_cast<std::size_t>(k)] * term;
  }
  return std::exp(log_value / sum);
}

Eigen::Vector2d WalkBank::upBias() const {
  if (biases_ == 1) return Eigen::Vector2d::Zero();
  std::array<double, kMax> w;
  const double sum = posteriorWeights(&w);
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    c += w[i] * x_[i].tail<2>();
  }
  return c / sum;
}

Eigen::Vector2d WalkBank::upBiasSigma() const {
  if (biases_ == 1) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d mean_c = upBias();
  std::array<double, kMax> w;
  const double sum = posteriorWeights(&w);
  Eigen::Vector2d second = Eigen::Vector2d::Zero();  // E[(c - mean)^2] per axis
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const Eigen::Vector2d d = x_[i].tail<2>() - mean_c;
    second += w[i] * (P_[i].bottomRightCorner<2, 2>().diagonal() + d.cwiseProduct(d));
  }
  return (second / sum).cwiseSqrt();
}

double WalkBank::walk() const {
  return mean(true, true);
}
double WalkBank::tiltWalk() const {
  return mean(true, false);
}
double WalkBank::noiseScale() const {
  return 1.0 / mean(false, true);
}

}  // namespace sunvo::sunfusion
