#pragma once
// The persistence test of the attitude walk's adaptation (sun_window_term.hpp, kPersistence).
//
// Whitened innovations r_i ~ N(H_i dtheta, I) of measurements taken while the filter ignores a
// constant attitude error dtheta are summed (with forgetting) into I = sum H_i^T H_i and
// g = sum H_i^T r_i. The least-squares estimate of the error is e = I^+ g, with covariance I^+
// under noise alone (dtheta = 0).

#include <Eigen/Core>
#include <cstddef>

namespace sunvo::sunfusion {

// T = g^T I^+ g, chi-square with rank(I) dof under noise alone; directions with less than 1e-3 of
// the strongest information count as unobserved (one sun direction never informs the rotation
// about itself).
double persistenceStatistic(const Eigen::Matrix3d& I, const Eigen::Vector3d& g, std::size_t* rank);

// The same test on the tilt alone (the plane normal to up, a unit vector): e_t and C, the tilt
// components of e and I^+, give T_t = e_t^T C^+ e_t, chi-square with rank(C) (0-2) dof under
// noise alone. A channel that informs only the heading neither dilutes nor raises it.
double tiltPersistenceStatistic(const Eigen::Matrix3d& I, const Eigen::Vector3d& g,
                                const Eigen::Vector3d& up, std::size_t* rank);

// x with P(chi-square(dof) <= x) = p, for dof 1-3 and p in (0, 1) (closed-form CDFs, bisection).
double chiSquareQuantile(double p, int dof);

}  // namespace sunvo::sunfusion
