#pragma once
// The stereo observation residual of the paper's Eq. 1 for Ceres.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sunvo::backend {

// A stereo measurement y = (u, v, d) of one landmark in one frame, in pixels.
struct StereoMeasurement {
  double u = 0.0;  // px, left image column
  double v = 0.0;  // px, left image row
  double d = 0.0;  // px, disparity u_left - u_right
};

// Constant data shared by all stereo residuals of a window: intrinsics and the square root of the
// measurement information R_y^-1 = diag(1/su^2, 1/sv^2, 1/sd^2).
struct StereoModel {
  double fu = 0.0, fv = 0.0, cu = 0.0, cv = 0.0, baseline_m = 0.0;
  double sqrt_info_u = 1.0;  // 1/px
  double sqrt_info_v = 1.0;  // 1/px
  double sqrt_info_d = 1.0;  // 1/px
};

// Residual of one stereo observation of landmark p_b (window base frame b) in camera k.
//
// Parameters: q_k_b (4, Eigen order x y z w, unit; EigenQuaternionManifold), t_k_b (3, m), p_b (3,
// m).
//   p_k = C_k_b p_b + t_k_b = (x, y, z)
// Predicted measurement (Eq. 1), with fu, fv, cu, cv the rectified intrinsics and l the baseline:
//   y_hat = (u, v, d) = (fu x / z + cu,  fv y / z + cv,  fu l / z)
// Error e_y = y_hat - y and cost e_y^T R_y^-1 e_y with R_y = diag(su^2, sv^2, sd^2): Ceres
// minimises |r|^2, so the residual is the whitened error
//   r = R_y^{-1/2} e_y = (e_u / su, e_v / sv, e_d / sd).
// A point at or behind the camera (z <= kMinDepth) has no valid projection: the residual is then a
// large constant (kBehindCameraResidual in whitened units, zero derivatives), finite by
// construction, so a step that pushes a point behind the camera is rejected by the trust region
// without NaN; the robust loss bounds its influence.
class StereoResidual {
 public:
  static constexpr double kMinDepth = 1e-3;             // m
  static constexpr double kBehindCameraResidual = 1e3;  // whitened units

  // y and model must outlive the residual; the window rewrites *y between solves.
  StereoResidual(const StereoMeasurement* y, const StereoModel* model) : y_(y), model_(model) {}

  template <typename T>
  bool operator()(const T* q_k_b, const T* t_k_b, const T* p_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> C_k_b(q_k_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_k_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_b);
    const Eigen::Matrix<T, 3, 1> p_k = C_k_b * p + t;
    if (!(p_k.z() > T(kMinDepth))) {
      residual[0] = residual[1] = residual[2] = T(kBehindCameraResidual);
      return true;
    }
    const StereoModel& m = *model_;
    const T inv_z = T(1.0) / p_k.z();
    const T u_hat = T(m.fu) * p_k.x() * inv_z + T(m.cu);
    const T v_hat = T(m.fv) * p_k.y() * inv_z + T(m.cv);
    const T d_hat = T(m.fu * m.baseline_m) * inv_z;
    residual[0] = T(m.sqrt_info_u) * (u_hat - T(y_->u));
    residual[1] = T(m.sqrt_info_v) * (v_hat - T(y_->v));
    residual[2] = T(m.sqrt_info_d) * (d_hat - T(y_->d));
    return true;
  }

  // The caller owns the returned cost function (the window keeps a pool of them).
  static ceres::CostFunction* Create(const StereoMeasurement* y, const StereoModel* model) {
    return new ceres::AutoDiffCostFunction<StereoResidual, 3, 4, 3, 3>(
        new StereoResidual(y, model));
  }

 private:
  const StereoMeasurement* y_;
  const StereoModel* model_;
};

}  // namespace sunvo::backend
