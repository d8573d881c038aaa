#pragma once
// The rectified stereo camera of the paper's Eq. 1: two ideal pinholes with focal lengths
// (fu, fv), principal point (cu, cv) and baseline b along the left camera's x axis.

#include <Eigen/Core>

#include "sunvo/core/status.hpp"

namespace sunvo {

struct StereoCamera {
  double fu = 0.0;          // px, > 0
  double fv = 0.0;          // px, > 0
  double cu = 0.0;          // px
  double cv = 0.0;          // px
  double baseline_m = 0.0;  // m, > 0: right camera centre at +baseline along left x
  int width = 0;            // px, > 0
  int height = 0;           // px, > 0

  Status validate() const;

  // p_c (left camera frame) -> (u, v, d); d = fu * b / z. Caller ensures z > 0.
  Eigen::Vector3d project(const Eigen::Vector3d& p_c) const {
    return {fu * p_c.x() / p_c.z() + cu, fv * p_c.y() / p_c.z() + cv, fu * baseline_m / p_c.z()};
  }
  // (u, v, d) -> p_c; caller ensures d > 0.
  Eigen::Vector3d triangulate(double u, double v, double d) const {
    const double z = fu * baseline_m / d;
    return {(u - cu) * z / fu, (v - cv) * z / fv, z};
  }
};

}  // namespace sunvo
