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
  walks_ = o.walks;
  scales_ = o.noise_scales;
  forgetting_ = o.forgetting;
  logSpaced(o.q_min_rad, o.q_max_rad, walks_, &log_q_);
  logSpaced(o.noise_min, o.noise_max, scales_, &log_s_);
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    loglik_[i] = 0.0;
    x_[i].setZero();
    P_[i] = Eigen::Matrix3d::Identity() * o.initial_sigma_rad * o.initial_sigma_rad;
  }
  return Status::ok();
}

// Member k = j * scales_ + i: walk j, noise scale i.
void WalkBank::propagate(double frames, const Eigen::Vector3d& up) {
  const Eigen::Matrix3d tilt_plane = Eigen::Matrix3d::Identity() - up * up.transpose();
  for (int k = 0; k < members(); ++k) {
    const double q = std::exp(log_q_[static_cast<std::size_t>(k / scales_)]);
    P_[static_cast<std::size_t>(k)] += q * q * frames * tilt_plane;
  }
}

void WalkBank::update(const Eigen::Matrix3d& H, const Eigen::Vector3d& r, int m) {
  if (walks_ == 0 || m < 1 || m > 3 || !H.allFinite() || !r.allFinite()) return;
  // Rows past m zero, with unit noise there: they add nothing (fixed size, no allocation).
  Eigen::Matrix3d Hm = H;
  Eigen::Vector3d rm = r;
  Hm.bottomRows(3 - m).setZero();
  rm.tail(3 - m).setZero();
  for (int k = 0; k < members(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double s = std::exp(log_s_[static_cast<std::size_t>(k % scales_)]);
    Eigen::Matrix3d S = Hm * P_[i] * Hm.transpose();
    for (int row = 0; row < 3; ++row) S(row, row) += row < m ? s * s : 1.0;
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    if (llt.info() != Eigen::Success) continue;
    const Eigen::Vector3d nu = rm - Hm * x_[i];
    const Eigen::Matrix3d L = llt.matrixL();
    const double log_det = 2.0 * L.diagonal().array().log().sum();
    const double l = -0.5 * (nu.dot(llt.solve(nu)) + log_det);
    const Eigen::Matrix3d K = llt.solve(Hm * P_[i]).transpose();  // P H^T S^-1
    const Eigen::Vector3d x_new = x_[i] + K * nu;
    Eigen::Matrix3d P_new = P_[i] - K * Hm * P_[i];
    P_new = 0.5 * (P_new + P_new.transpose());
    if (!std::isfinite(l) || !x_new.allFinite() || !P_new.allFinite()) continue;
    loglik_[i] = forgetting_ * loglik_[i] + l;
    x_[i] = x_new;
    P_[i] = P_new;
  }
}

void WalkBank::shift(const Eigen::Vector3d& c_w) {
  if (!c_w.allFinite()) return;
  for (int k = 0; k < members(); ++k) x_[static_cast<std::size_t>(k)] -= c_w;
}

// The prior: each walk as likely as 1/q (q_min's as likely as all the others together, about):
// the fusion starts near the slow end and a faster walk must be earned by the innovations, as
// the persistence rule's walk sinks under noise alone. It is not forgotten.
double WalkBank::logPosterior(int k) const {
  return loglik_[static_cast<std::size_t>(k)] -
         (log_q_[static_cast<std::size_t>(k / scales_)] - log_q_[0]);
}

double WalkBank::maxLogPosterior() const {
  double top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < members(); ++k) top = std::max(top, logPosterior(k));
  return top;
}

double WalkBank::weight(int member) const {
  if (member < 0 || member >= members()) return 0.0;
  const double top = maxLogPosterior();
  double sum = 0.0;
  for (int k = 0; k < members(); ++k) sum += std::exp(logPosterior(k) - top);
  return std::exp(logPosterior(member) - top) / sum;
}

double WalkBank::mean(bool walk_part, bool noise_part) const {
  if (walks_ == 0) return 0.0;
  const double top = maxLogPosterior();
  double sum = 0.0;
  double log_value = 0.0;
  for (int k = 0; k < members(); ++k) {
    const double w = std::exp(logPosterior(k) - top);
    const double term = (walk_part ? log_q_[static_cast<std::size_t>(k / scales_)] : 0.0) -
                        (noise_part ? log_s_[static_cast<std::size_t>(k % scales_)] : 0.0);
    sum += w;
    log_value += w * term;
  }
  return std::exp(log_value / sum);
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
