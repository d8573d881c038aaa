#include "sunvo/sunfusion/world_up_alignment.hpp"

#include <cmath>

#include "sunvo/core/geometry.hpp"

namespace sunvo::sunfusion {

void WorldUpAlignment::reset(std::uint64_t frames, const Eigen::Vector3d& assumed_up) {
  frames_ = frames;
  assumed_ = assumed_up;
  up_ = assumed_up;
  count_ = 0;
  mean_sigma_ = 0.0;
  done_ = frames == 0;
}

void WorldUpAlignment::finishIfPast(std::uint64_t sequence) {
  if (!done_ && sequence > frames_ && count_ >= kMinMeasurements) finish();
}

bool WorldUpAlignment::takes(std::uint64_t sequence) {
  if (done_) return false;
  if (sequence <= frames_ || count_ < kMinMeasurements) return true;
  finish();
  return false;
}

void WorldUpAlignment::add(const Eigen::Vector3d& up_w, double sigma) {
  if (done_ || !up_w.allFinite() || !(sigma > 0.0) || !std::isfinite(sigma)) return;
  const double n = up_w.norm();
  if (!(n > 0.5)) return;
  u_[static_cast<std::size_t>(count_)] = up_w / n;
  sigma_[static_cast<std::size_t>(count_)] = sigma;
  if (++count_ == kMaxMeasurements) finish();
}

void WorldUpAlignment::turn(const Eigen::Matrix3d& C) {
  if (!C.allFinite()) return;
  for (int i = 0; i < count_; ++i) {
    Eigen::Vector3d& u = u_[static_cast<std::size_t>(i)];
    u = (C * u).normalized();
  }
  if (done_ && count_ > 0) up_ = (C * up_).normalized();
}

void WorldUpAlignment::finish() {
  done_ = true;
  if (count_ == 0) return;  // nothing measured: keep the assumed up
  // Weighted mean, then Cauchy reweighting about it (scale 2 sigma per answer).
  Eigen::Vector3d mean = assumed_;
  double weight = 0.0;
  for (int iteration = 0; iteration < 6; ++iteration) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    weight = 0.0;
    for (int i = 0; i < count_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      double w = 1.0 / (sigma_[k] * sigma_[k]);
      if (iteration > 0) {
        const double z = angleBetween(u_[k], mean) / (2.0 * sigma_[k]);
        w /= 1.0 + z * z;
      }
      sum += w * u_[k];
      weight += w;
    }
    if (!(sum.norm() > 0.0) || !sum.allFinite()) return;  // keep the assumed up
    mean = sum.normalized();
  }
  up_ = mean;
  mean_sigma_ = 1.0 / std::sqrt(weight);
}

Eigen::Vector3d WorldUpAlignment::tiltCorrection() const {
  const Eigen::Vector3d axis = up_.cross(assumed_);
  const double s = axis.norm();
  if (!(s > 1e-12)) return Eigen::Vector3d::Zero();
  return axis / s * angleBetween(up_, assumed_);
}

double WorldUpAlignment::tiltDeg() const {
  return angleBetween(up_, assumed_) * 180.0 / M_PI;
}

}  // namespace sunvo::sunfusion
