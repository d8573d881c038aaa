#pragma once
// Sun residuals for the sliding-window bundle adjustment.
//
// The window's base frame b is fixed during a solve; C_b_w (world -> base rotation) comes from the
// previous window, and s_w (unit vector toward the sun in the world frame) from the ephemeris at
// the measurement's time and place. The residual touches the rotation of camera k in the base
// frame, q_k_b (Eigen quaternion order x, y, z, w), and optionally a correction delta of the base's
// world attitude (see predictSun).

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::sunfusion {

// The sun predicted in camera k.
//
// Paper form (base fixed):   s_hat_k = C_k_b s_b,            s_b = C_b_w s_w.
// With a base correction delta (rotation vector: the error of the base's world attitude, so that
// C_w_b,true = C_w_b Exp(delta) and C_b_w,true = Exp(-delta) C_b_w):
//                            s_hat_k = C_k_b Exp(-delta) s_b.
// The correction carries a prior delta ~ N(0, P) from the accumulated attitude uncertainty (the
// term the paper left to future work), so a measurement can remove an old attitude error instead
// of only nudging the stiff relative rotation C_k_b. delta == nullptr gives the paper form.
template <typename T>
Eigen::Matrix<T, 3, 1> predictSun(const T* q_k_b, const T* delta, const Eigen::Vector3d& sun_b) {
  const Eigen::Map<const Eigen::Quaternion<T>> C_k_b(q_k_b);
  Eigen::Matrix<T, 3, 1> s_b = sun_b.cast<T>();
  if (delta != nullptr) {
    const T minus_delta[3] = {-delta[0], -delta[1], -delta[2]};
    Eigen::Matrix<T, 3, 1> rotated;
    ceres::AngleAxisRotatePoint(minus_delta, s_b.data(), rotated.data());
    s_b = rotated;
  }
  return C_k_b * s_b;
}

// An image estimator's azimuth error that persists along a street (SunFusionOptions::
// sun_bias_sigma_deg) is a turn of the measured sun about the camera's y axis by b: with the
// camera azimuth psi = atan2(x, z), R_y(b) = [cos b, 0, sin b; 0, 1, 0; -sin b, 0, cos b] maps
// azimuth psi to psi + b, so the measurement is predicted as R_y(b_hat + db) s_hat_k, with b_hat
// the current estimate and db its correction in this solve.
template <typename T>
Eigen::Matrix<T, 3, 1> turnAboutCameraY(const Eigen::Matrix<T, 3, 1>& s, const T& b) {
  using std::cos;
  using std::sin;
  const T c = cos(b), n = sin(b);
  return {c * s.x() + n * s.z(), s.y(), -n * s.x() + c * s.z()};
}

// The vertical cue's error that stays alike over a drive (SunFusionOptions::
// vertical_bias_sigma_deg) is a small turn of the measured "up" about the camera's x axis (pitch)
// and z axis (roll) by c = (c_x, c_z): the measurement is predicted as Exp((c_x, 0, c_z)) s_hat_k.
// A turn about y does not move an up along y (a level camera's) and is not a state.
template <typename T>
Eigen::Matrix<T, 3, 1> turnAboutCameraXZ(const Eigen::Matrix<T, 3, 1>& s, const T& c_x,
                                         const T& c_z) {
  const T angle_axis[3] = {c_x, T(0.0), c_z};
  Eigen::Matrix<T, 3, 1> turned;
  ceres::AngleAxisRotatePoint(angle_axis, s.data(), turned.data());
  return turned;
}

// Which blocks a sun residual acts on, after q_k_b (4): none (the paper's form), the base
// correction delta (3), delta and the azimuth bias's correction db (1), or delta and the up
// bias's correction (2: about camera x and z; SunDirectionResidual only).
enum class SunResidualForm {
  kPaper,
  kBaseCorrection,
  kBaseCorrectionAndBias,
  kBaseCorrectionAndUpBias
};

// The cost function of a sun residual functor in a form; takes ownership of r. The caller may
// keep r and change its numbers with set() between solves (the window term reuses its costs so
// that a measurement allocates nothing).
template <class Residual, int kRows>
ceres::CostFunction* wrapSunResidual(Residual* r, SunResidualForm form) {
  switch (form) {
    case SunResidualForm::kPaper:
      return new ceres::AutoDiffCostFunction<Residual, kRows, 4>(r);
    case SunResidualForm::kBaseCorrection:
      return new ceres::AutoDiffCostFunction<Residual, kRows, 4, 3>(r);
    case SunResidualForm::kBaseCorrectionAndUpBias:
      // An "up" is a 3-D direction: the azimuth-only residual has no up bias and takes the base
      // correction only.
      if constexpr (requires { r->useUpBias(); }) {
        r->useUpBias();
        return new ceres::AutoDiffCostFunction<Residual, kRows, 4, 3, 2>(r);
      } else {
        return new ceres::AutoDiffCostFunction<Residual, kRows, 4, 3>(r);
      }
    case SunResidualForm::kBaseCorrectionAndBias:
      break;
  }
  return new ceres::AutoDiffCostFunction<Residual, kRows, 4, 3, 1>(r);
}

// Full 3-D sun residual (the paper's Eq. 3 term).
//
//   residual   e_s = s_hat_k - s_k                                 (3-vector, Euclidean)
//   cost       e_s^T R_s^-1 e_s with R_s = sigma^2 I, so the weighted residual is e_s / sigma;
//              for a measurement with a strong axis a (sun_measurement.hpp), R_s = sigma^2
//              (I - a a^T) + sigma_s^2 a a^T and the weighted residual W e_s with
//              W = I / sigma + (1 / sigma_s - 1 / sigma) a a^T (W^T W = R_s^-1, a normal to s_k).
//
// The paper found the Euclidean difference of unit vectors converged better in Ceres than the
// cosine distance, whose error distribution is far from Gaussian. Both vectors are unit length,
// so |e_s| = 2 sin(angle / 2): for small errors the residual is the angle in radians.
class SunDirectionResidual {
 public:
  SunDirectionResidual(const Eigen::Vector3d& sun_b, const Eigen::Vector3d& sun_k_measured,
                       double sigma, double b_hat = 0.0) {
    set(sun_b, sun_k_measured, sigma, b_hat);
  }
  // New numbers for the same residual (b_hat: the bias estimate, used in the bias form only;
  // sigma_strong and strong_axis: a better-measured direction, sun_measurement.hpp).
  void set(const Eigen::Vector3d& sun_b, const Eigen::Vector3d& sun_k_measured, double sigma,
           double b_hat = 0.0, double sigma_strong = 0.0,
           const Eigen::Vector3d& strong_axis = Eigen::Vector3d::Zero()) {
    sun_b_ = sun_b;
    sun_k_ = sun_k_measured;
    W_ = directionSqrtInformation(sun_k_measured, sigma, sigma_strong, strong_axis);
    b_hat_ = b_hat;
  }
  // The up bias form (kBaseCorrectionAndUpBias): the bias block is (db_x, db_z), added to the
  // estimate up_b_hat (turnAboutCameraXZ).
  void useUpBias() { up_bias_ = true; }
  void setUpBiasEstimate(const Eigen::Vector2d& up_b_hat) { up_b_hat_ = up_b_hat; }

  template <typename T>
  bool operator()(const T* q_k_b, T* residual) const {
    return evaluate(q_k_b, static_cast<const T*>(nullptr), static_cast<const T*>(nullptr),
                    residual);
  }
  template <typename T>
  bool operator()(const T* q_k_b, const T* delta, T* residual) const {
    return evaluate(q_k_b, delta, static_cast<const T*>(nullptr), residual);
  }
  template <typename T>
  bool operator()(const T* q_k_b, const T* delta, const T* bias, T* residual) const {
    return evaluate(q_k_b, delta, bias, residual);
  }

  // Blocks: q_k_b (4).
  static ceres::CostFunction* Create(const Eigen::Vector3d& sun_b,
                                     const Eigen::Vector3d& sun_k_measured, double sigma) {
    return wrapSunResidual<SunDirectionResidual, 3>(
        new SunDirectionResidual(sun_b, sun_k_measured, sigma), SunResidualForm::kPaper);
  }
  // Blocks: q_k_b (4), delta (3).
  static ceres::CostFunction* CreateWithBaseCorrection(const Eigen::Vector3d& sun_b,
                                                       const Eigen::Vector3d& sun_k_measured,
                                                       double sigma) {
    return wrapSunResidual<SunDirectionResidual, 3>(
        new SunDirectionResidual(sun_b, sun_k_measured, sigma), SunResidualForm::kBaseCorrection);
  }

 private:
  template <typename T>
  bool evaluate(const T* q_k_b, const T* delta, const T* bias, T* residual) const {
    Eigen::Matrix<T, 3, 1> s_hat = predictSun(q_k_b, delta, sun_b_);
    if (bias != nullptr && up_bias_) {
      s_hat = turnAboutCameraXZ(s_hat, T(up_b_hat_.x()) + bias[0], T(up_b_hat_.y()) + bias[1]);
    } else if (bias != nullptr) {
      s_hat = turnAboutCameraY(s_hat, T(b_hat_) + bias[0]);
    }
    const Eigen::Matrix<T, 3, 1> e = s_hat - sun_k_.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = W_.cast<T>() * e;
    return true;
  }

  Eigen::Vector3d sun_b_;
  Eigen::Vector3d sun_k_;
  Eigen::Matrix3d W_ = Eigen::Matrix3d::Identity();  // square-root information
  double b_hat_ = 0.0;
  bool up_bias_ = false;
  Eigen::Vector2d up_b_hat_ = Eigen::Vector2d::Zero();
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
//   p   = (s_hat_x, s_hat_z) / sqrt(s_hat_x^2 + s_hat_z^2)
//   e_s = p - m                                                (2-vector, chord in the x-z plane)
//
// With a perfect measurement e_s = 0 at the true rotation for every sun elevation, so the term
// leaves a correct pose unchanged. |e_s| = 2 sin(dpsi / 2) with dpsi the azimuth error in the
// plane. The term is undefined when the sun is straight above the camera's y axis
// (s_hat_x = s_hat_z = 0); the norm is floored there and the gate rejects such measurements.
class SunAzimuthResidual {
 public:
  SunAzimuthResidual(const Eigen::Vector3d& sun_b, const Eigen::Vector2d& azimuth_xz, double sigma,
                     double b_hat = 0.0) {
    set(sun_b, azimuth_xz, sigma, b_hat);
  }
  void set(const Eigen::Vector3d& sun_b, const Eigen::Vector2d& azimuth_xz, double sigma,
           double b_hat = 0.0) {
    sun_b_ = sun_b;
    m_ = azimuth_xz.normalized();
    inv_sigma_ = 1.0 / sigma;
    b_hat_ = b_hat;
  }

  template <typename T>
  bool operator()(const T* q_k_b, T* residual) const {
    return evaluate(q_k_b, static_cast<const T*>(nullptr), static_cast<const T*>(nullptr),
                    residual);
  }
  template <typename T>
  bool operator()(const T* q_k_b, const T* delta, T* residual) const {
    return evaluate(q_k_b, delta, static_cast<const T*>(nullptr), residual);
  }
  template <typename T>
  bool operator()(const T* q_k_b, const T* delta, const T* bias, T* residual) const {
    return evaluate(q_k_b, delta, bias, residual);
  }

  // Blocks: q_k_b (4).
  static ceres::CostFunction* Create(const Eigen::Vector3d& sun_b,
                                     const Eigen::Vector2d& azimuth_xz, double sigma) {
    return wrapSunResidual<SunAzimuthResidual, 2>(new SunAzimuthResidual(sun_b, azimuth_xz, sigma),
                                                  SunResidualForm::kPaper);
  }
  // Blocks: q_k_b (4), delta (3).
  static ceres::CostFunction* CreateWithBaseCorrection(const Eigen::Vector3d& sun_b,
                                                       const Eigen::Vector2d& azimuth_xz,
                                                       double sigma) {
    return wrapSunResidual<SunAzimuthResidual, 2>(new SunAzimuthResidual(sun_b, azimuth_xz, sigma),
                                                  SunResidualForm::kBaseCorrection);
  }

 private:
  template <typename T>
  bool evaluate(const T* q_k_b, const T* delta, const T* bias, T* residual) const {
    Eigen::Matrix<T, 3, 1> s_hat = predictSun(q_k_b, delta, sun_b_);
    if (bias != nullptr) s_hat = turnAboutCameraY(s_hat, T(b_hat_) + bias[0]);
    using std::sqrt;
    const T n = sqrt(s_hat.x() * s_hat.x() + s_hat.z() * s_hat.z() + T(1e-12));
    residual[0] = (s_hat.x() / n - T(m_.x())) * T(inv_sigma_);
    residual[1] = (s_hat.z() / n - T(m_.y())) * T(inv_sigma_);
    return true;
  }

  Eigen::Vector3d sun_b_;
  Eigen::Vector2d m_;
  double inv_sigma_ = 1.0;
  double b_hat_ = 0.0;
};

// Prior on the base-attitude correction: r = L delta with L^T L = P^-1 (square-root information
// of the accumulated attitude uncertainty P).
class AttitudePriorResidual {
 public:
  explicit AttitudePriorResidual(const Eigen::Matrix3d& sqrt_information) : L_(sqrt_information) {}
  void set(const Eigen::Matrix3d& sqrt_information) { L_ = sqrt_information; }
  template <typename T>
  bool operator()(const T* delta, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> d(delta);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = L_.cast<T>() * d;
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Matrix3d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<AttitudePriorResidual, 3, 3>(
        new AttitudePriorResidual(sqrt_information));
  }

 private:
  Eigen::Matrix3d L_;
};

// Joint prior on the base-attitude correction and the bias states' corrections:
// r = L x with L^T L the inverse of their covariance and x = (delta, bias entries) in block order,
// kN = 3 + the bias entries (4: the sun's azimuth; 5: the up's turn; 6: both, the sun's first).
// L is the top-left kN x kN of a matrix the caller owns and sets before each solve.
using JointPriorMatrix = Eigen::Matrix<double, 6, 6>;
template <int kN>
class JointPriorResidual {
  static_assert(kN >= 4 && kN <= 6);

 public:
  explicit JointPriorResidual(const JointPriorMatrix* sqrt_information) : L_(sqrt_information) {}
  // kN = 4 or 5: blocks delta (3), bias (kN - 3).
  template <typename T>
  bool operator()(const T* delta, const T* bias, T* residual) const {
    T x[kN];
    for (int i = 0; i < 3; ++i) x[i] = delta[i];
    for (int i = 3; i < kN; ++i) x[i] = bias[i - 3];
    return apply(x, residual);
  }
  // kN = 6: blocks delta (3), the sun's bias (1), the up's (2).
  template <typename T>
  bool operator()(const T* delta, const T* sun_bias, const T* up_bias, T* residual) const {
    const T x[kN] = {delta[0], delta[1], delta[2], sun_bias[0], up_bias[0], up_bias[1]};
    return apply(x, residual);
  }
  static ceres::CostFunction* Create(const JointPriorMatrix* sqrt_information) {
    auto* r = new JointPriorResidual(sqrt_information);
    if constexpr (kN == 6) {
      return new ceres::AutoDiffCostFunction<JointPriorResidual, 6, 3, 1, 2>(r);
    } else {
      return new ceres::AutoDiffCostFunction<JointPriorResidual, kN, 3, kN - 3>(r);
    }
  }

 private:
  template <typename T>
  bool apply(const T* x, T* residual) const {
    for (int i = 0; i < kN; ++i) {
      T sum(0.0);
      for (int j = 0; j < kN; ++j) sum += T((*L_)(i, j)) * x[j];
      residual[i] = sum;
    }
    return true;
  }
  const JointPriorMatrix* L_;
};

}  // namespace sunvo::sunfusion
