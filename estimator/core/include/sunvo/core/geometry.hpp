#pragma once
// Rigid-body helpers. Naming: T_a_b maps points from frame b into frame a (p_a = T_a_b * p_b);
// C_a_b is its rotation.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sunvo {

using Isometry3 = Eigen::Isometry3d;

// The rotation angle of C in [0, pi], from the numerically stable form
// theta = atan2(|vee(C - C^T)| / 2, (trace(C) - 1) / 2); accurate near 0 and near pi,
// where a bare arccos of the trace loses half the digits.
double rotationAngle(const Eigen::Matrix3d& C);

// Angle between two directions (need not be unit), rad, [0, pi]; 0 for a zero vector. atan2 of
// |a x b| and a.b: accurate for small and near-pi angles alike (an arccos of the dot product
// loses half the digits there).
double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// The nearest rotation matrix (in the Frobenius sense) to M, via SVD with det = +1.
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M);

// Builds an isometry from a 3x4 [R | t] block, re-orthonormalising R.
Isometry3 isometryFrom3x4(const Eigen::Matrix<double, 3, 4>& Rt);

// so(3) exponential / logarithm (axis-angle vectors).
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi);
Eigen::Vector3d logSO3(const Eigen::Matrix3d& C);

// True when every entry is finite.
bool allFinite(const Isometry3& T);

}  // namespace sunvo
