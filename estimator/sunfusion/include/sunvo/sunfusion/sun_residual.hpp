#pragma once
// Sun residuals for the sliding-window bundle adjustment.
//
// The window's base frame b is fixed during a solve; C_b_w (world -> base rotation) comes from the
// previous window, and s_w (unit vector toward the sun in the world frame) from the ephemeris at
// the measurement's time and place. The only unknown the residual touches is the rotation of
// camera k in the base frame, q_k_b (Eigen quaternion order x, y, z, w).

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace sunvo::sunfusion {

// Full 3-D sun residual (the paper's Eq. 3 term).
//
//   predicted  s_hat_k = C_k_b * (C_b_w * s_w) = C_k_b * s_b        (s_b fixed during the solve)
//   residual   e_s     = s_hat_k - s_k                               (3-vector, Euclidean)
//   cost       e_s^T R_s^-1 e_s with R_s = sigma^2 I, so the weighted residual is e_s / sigma.
//
// The paper found the Euclidean difference of unit vectors converged better in Ceres than the
// cosine distance, whose error distribution is far from Gaussian. Both vectors are unit length,
// so |e_s| = 2 sin(angle / 2): for small errors the residual is the angle in radians.
class SunDirectionResidual {
 public:
  SunDirectionResidual(const Eigen::Vector3d& sun_b, const Eigen::Vector3d& sun_k_measured,
                       double sigma)
      : sun_b_(sun_b), sun_k_(sun_k_measured), inv_sigma_(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* q_k_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> C_k_b(q_k_b);
    const Eigen::Matrix<T, 3, 1> s_hat = C_k_b * sun_b_.cast<T>();
    for (int i = 0; i < 3; ++i) residual[i] = (s_hat[i] - T(sun_k_[i])) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& sun_b,
                                     const Eigen::Vector3d& sun_k_measured, double sigma) {
    return new ceres::AutoDiffCostFunction<SunDirectionResidual, 3, 4>(
        new SunDirectionResidual(sun_b, sun_k_measured, sigma));
  }

 private:
  Eigen::Vector3d sun_b_;
  Eigen::Vector3d sun_k_;
  double inv_sigma_;
};

// Azimuth-only sun residual (Sun-CNN), free of elevation bias.
//
// The measurement gives only the direction of the sun within the camera's x-z plane,
// m = (m_x, m_z) with |m| = 1. Writing it as the 3-vector (m_x, 0, m_z) and comparing it with a
// predicted s_hat whose y component is non-zero (the sun is above the horizon) biases the
// solution: the residual's y entry pulls the camera to tilt the sun down into the x-z plane, and
// the x, z entries disagree in length with a normalised m. Instead the prediction is projected
// onto the same plane and normalised:
//
//   s_hat_k = C_k_b s_b,   p = (s_hat_x, s_hat_z) / sqrt(s_hat_x^2 + s_hat_z^2)
//   e_s     = p - m                                            (2-vector, chord in the x-z plane)
//
// With a perfect measurement e_s = 0 at the true rotation for every sun elevation, so the term
// leaves a correct pose unchanged. |e_s| = 2 sin(dpsi / 2) with dpsi the azimuth error in the
// plane. The term is undefined when the sun is straight above the camera's y axis
// (s_hat_x = s_hat_z = 0); the norm is floored there and the gate rejects such measurements.
class SunAzimuthResidual {
 public:
  SunAzimuthResidual(const Eigen::Vector3d& sun_b, const Eigen::Vector2d& azimuth_xz, double sigma)
      : sun_b_(sun_b), m_(azimuth_xz.normalized()), inv_sigma_(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* q_k_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> C_k_b(q_k_b);
    const Eigen::Matrix<T, 3, 1> s_hat = C_k_b * sun_b_.cast<T>();
    using std::sqrt;
    const T n = sqrt(s_hat.x() * s_hat.x() + s_hat.z() * s_hat.z() + T(1e-12));
    residual[0] = (s_hat.x() / n - T(m_.x())) * T(inv_sigma_);
    residual[1] = (s_hat.z() / n - T(m_.y())) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& sun_b,
                                     const Eigen::Vector2d& azimuth_xz, double sigma) {
    return new ceres::AutoDiffCostFunction<SunAzimuthResidual, 2, 4>(
        new SunAzimuthResidual(sun_b, azimuth_xz, sigma));
  }

 private:
  Eigen::Vector3d sun_b_;
  Eigen::Vector2d m_;
  double inv_sigma_;
};

}  // namespace sunvo::sunfusion
