#include "sunvo/core/geometry.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace sunvo {

double rotationAngle(const Eigen::Matrix3d& C) {
  const Eigen::Vector3d v(C(2, 1) - C(1, 2), C(0, 2) - C(2, 0), C(1, 0) - C(0, 1));
  const double s = 0.5 * v.norm();
  const double c = 0.5 * (C.trace() - 1.0);
  return std::atan2(s, c);
}

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double n = a.norm() * b.norm();
  if (n < 1e-12) return 0.0;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

Isometry3 isometryFrom3x4(const Eigen::Matrix<double, 3, 4>& Rt) {
  Isometry3 T = Isometry3::Identity();
  T.linear() = orthonormalize(Rt.leftCols<3>());
  T.translation() = Rt.col(3);
  return T;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-12) {
    Eigen::Matrix3d K;
    K << 0, -phi.z(), phi.y(), phi.z(), 0, -phi.x(), -phi.y(), phi.x(), 0;
    return Eigen::Matrix3d::Identity() + K;
  }
  return Eigen::AngleAxisd(theta, phi / theta).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& C) {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(C).normalized());
  double angle = aa.angle();
  Eigen::Vector3d axis = aa.axis();
  if (angle > M_PI) {  // keep the angle in [0, pi]
    angle = 2.0 * M_PI - angle;
    axis = -axis;
  }
  return angle * axis;
}

bool allFinite(const Isometry3& T) {
  return T.matrix().allFinite();
}

}  // namespace sunvo

#include "sunvo/core/camera.hpp"

namespace sunvo {

Status StereoCamera::validate() const {
  if (!(fu > 0.0) || !(fv > 0.0)) return invalidArgument("camera: fu and fv must be > 0 px");
  if (!(baseline_m > 0.0)) return invalidArgument("camera: baseline_m must be > 0 m");
  if (width <= 0 || height <= 0) return invalidArgument("camera: width and height must be > 0 px");
  return Status::ok();
}

}  // namespace sunvo
