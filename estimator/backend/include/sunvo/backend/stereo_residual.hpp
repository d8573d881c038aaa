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

// A predicted relative motion between consecutive window frames (e.g. constant velocity).
struct MotionPriorData {
  double q_pred[4] = {0.0, 0.0, 0.0, 1.0};  // C_k_km1 predicted, Eigen order x y z w
  double t_pred[3] = {0.0, 0.0, 0.0};       // t_k_km1 predicted, m
  double sqrt_info_rot = 1.0;               // 1/rad
  double sqrt_info_trans = 1.0;             // 1/m
  // The non-holonomic row (below): the direction of travel seen by the camera (x slope), the
  // camera's lever arm ahead of the rear axle, and the row's weight (0 = no row).
  double lateral_beta = 0.0;       // rad
  double lateral_lever_m = 0.0;    // m
  double sqrt_info_lateral = 0.0;  // 1/m
  // The vertical row (below): the direction of travel's y slope seen by the camera and the row's
  // weight (0 = no row).
  double vertical_gamma = 0.0;      // rad
  double sqrt_info_vertical = 0.0;  // 1/m
};

// Soft prior on the relative motion of slots km1 and k (both expressed in the base b):
//   T_k_km1 = T_k_b T_km1_b^-1:  C = C_k_b C_km1_b^T,  t = t_k_b - C t_km1_b.
// Rotation error: dq = q_pred^-1 * q(C); for a small error dq = (sin(a/2) n, cos(a/2)) so
// 2 vec(dq) = a n, the rotation vector (sign chosen so that dq.w >= 0). Translation error
// t - t_pred. Residual r = (2 vec(dq) / sigma_rot, (t - t_pred) / sigma_trans, r_lat, r_vert)
// with the non-holonomic row of a wheeled vehicle that does not skid (docs/lateral_prior.md):
//   psi = 2 vec(q(C)).y (the yaw part of the relative rotation, sign as above),
//   r_lat = (t_x - beta t_z - psi (t_z / 2 + L)) / sigma_lat.
// Derivation, first order in psi: the rear axle has no sideways velocity, so over the frame it
// moves along an arc of length s turning by psi, whose chord leaves at psi/2 to the old heading.
// A camera L ahead of the axle then moves in frame k-1 by d = (s psi/2 + L psi, 0, s) (x towards
// the turn). t = -C d and C turns x by -psi z, so t_x = -(s psi/2 + L psi) + psi s =
// s psi/2 - L psi; with s = -t_z and psi's sign taken from C, t_x = psi (t_z/2 + L). A camera that
// sees the direction of travel at (beta, 0, 1) adds -beta s = beta t_z.
// It holds the sideways step to what the step's own yaw and length imply, not to the last step's.
// The vertical row is the same constraint in the camera's y-z plane (a vehicle on the road moves
// along its own body axis as it pitches over the road's crests and dips):
//   theta = 2 vec(q(C)).x (the pitch part of the relative rotation),
//   r_vert = (t_y - gamma t_z + theta t_z / 2) / sigma_vert.
// Derivation, as above with y for x: a rotation by theta about x maps z to
// (0, -sin theta, cos theta) where one by psi about y maps it to (sin psi, 0, cos psi), so theta
// enters with psi's sign reversed and the chord at theta/2 gives t_y = -theta t_z / 2; a camera
// that sees the direction of travel at (0, gamma, 1) adds gamma t_z. There is no lever term: a
// body pitches about a point between its axles, not about the rear axle, and on the KITTI truths
// a lever of 0 leaves the smallest scatter (0020: 3.9 mm per frame robust at 0, 4.6 mm at 0.88 m;
// odometry 00: 7.3 against 8.3 mm).
class MotionPriorResidual {
 public:
  explicit MotionPriorResidual(const MotionPriorData* prior) : prior_(prior) {}

  template <typename T>
  bool operator()(const T* q_km1_b, const T* t_km1_b, const T* q_k_b, const T* t_k_b,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_km1(q_km1_b);
    const Eigen::Map<const Eigen::Quaternion<T>> q_k(q_k_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_km1(t_km1_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_k(t_k_b);
    const Eigen::Quaternion<T> q_rel = q_k * q_km1.conjugate();
    const Eigen::Matrix<T, 3, 1> t_rel = t_k - q_rel * t_km1;
    const Eigen::Quaternion<T> q_pred(T(prior_->q_pred[3]), T(prior_->q_pred[0]),
                                      T(prior_->q_pred[1]), T(prior_->q_pred[2]));
    Eigen::Quaternion<T> dq = q_pred.conjugate() * q_rel;
    const T sign = dq.w() < T(0.0) ? T(-1.0) : T(1.0);
    const T sr = T(2.0 * prior_->sqrt_info_rot) * sign;
    residual[0] = sr * dq.x();
    residual[1] = sr * dq.y();
    residual[2] = sr * dq.z();
    for (int i = 0; i < 3; ++i) {
      residual[3 + i] = T(prior_->sqrt_info_trans) * (t_rel[i] - T(prior_->t_pred[i]));
    }
    const T two_sign = q_rel.w() < T(0.0) ? T(-2.0) : T(2.0);
    const T psi = two_sign * q_rel.y();
    residual[6] =
        T(prior_->sqrt_info_lateral) * (t_rel[0] - T(prior_->lateral_beta) * t_rel[2] -
                                        psi * (T(0.5) * t_rel[2] + T(prior_->lateral_lever_m)));
    const T theta = two_sign * q_rel.x();
    residual[7] = T(prior_->sqrt_info_vertical) *
                  (t_rel[1] - T(prior_->vertical_gamma) * t_rel[2] + T(0.5) * theta * t_rel[2]);
    return true;
  }

  static ceres::CostFunction* Create(const MotionPriorData* prior) {
    return new ceres::AutoDiffCostFunction<MotionPriorResidual, 8, 4, 3, 4, 3>(
        new MotionPriorResidual(prior));
  }

 private:
  const MotionPriorData* prior_;
};

// The rotation-rate prior between two consecutive window frames (issue 15): an orthonormal basis
// of camera k whose row 1 is the vehicle's yaw (turn) axis and whose rows 0 and 2 are the
// pitch-like and roll-like (closest to the optical axis) directions orthogonal to it, and the
// weights 1 / (rate std x dt) per row (0 = no prior along that row).
struct RotationRatePriorData {
  double basis[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};  // row-major
  double sqrt_info[3] = {0.0, 0.0, 0.0};                            // 1/rad
};

// Zero-mean prior on the rotation between consecutive window frames km1 and k, along the
// directions orthogonal to the yaw axis:
//   C_k_km1 = C_k_b C_km1_b^T,  q_rel = q_k_b * q_km1_b^-1 = (sin(a/2) n, cos(a/2)),
//   phi = 2 vec(q_rel) ~ a n for a small rotation (sign chosen so that q_rel.w >= 0),
//   r_i = sqrt_info_i * (B phi)_i,  B the basis above.
// A ground vehicle's roll and pitch angles stay bounded, so the rotation about axes orthogonal to
// its turn axis has zero mean: pulling a frame's roll towards 0 costs at most a bounded share of
// the net roll change, while the window alone lets a systematic image error accumulate as roll on
// frames whose tracks do not constrain it (docs/backend.md, the roll of one-sided frames). Its
// influence is large only where the window's own information on an axis is small. The yaw axis
// is not the camera's y axis on a real rig (on the 0020 tracks the estimate ends 2.2 deg off),
// which is why it is estimated (BundleWindow::yawAxis) and the prior acts orthogonal to it, not
// about the camera's x and z.
class RotationRatePriorResidual {
 public:
  explicit RotationRatePriorResidual(const RotationRatePriorData* prior) : prior_(prior) {}

  template <typename T>
  bool operator()(const T* q_km1_b, const T* q_k_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_km1(q_km1_b);
    const Eigen::Map<const Eigen::Quaternion<T>> q_k(q_k_b);
    const Eigen::Quaternion<T> q_rel = q_k * q_km1.conjugate();
    const T two_sign = q_rel.w() < T(0.0) ? T(-2.0) : T(2.0);
    const T phi[3] = {two_sign * q_rel.x(), two_sign * q_rel.y(), two_sign * q_rel.z()};
    for (int i = 0; i < 3; ++i) {
      const double* b = prior_->basis + 3 * i;
      residual[i] =
          T(prior_->sqrt_info[i]) * (T(b[0]) * phi[0] + T(b[1]) * phi[1] + T(b[2]) * phi[2]);
    }
    return true;
  }

  static ceres::CostFunction* Create(const RotationRatePriorData* prior) {
    return new ceres::AutoDiffCostFunction<RotationRatePriorResidual, 3, 4, 4>(
        new RotationRatePriorResidual(prior));
  }

 private:
  const RotationRatePriorData* prior_;
};

}  // namespace sunvo::backend
