#pragma once
// The compact sky and sun-direction geometry the image sun estimators work in.
//
// Horizon frame: built from the camera's "up" vector up_c. forward_c is the camera's optical axis
// (z) with its up component removed, right_c = forward_c x up_c (the camera's x for a level
// camera). A sun direction is (azimuth phi, zenith theta) with phi measured from forward_c toward
// right_c and theta from up_c:
//   s_c = sin(theta) cos(phi) forward_c + sin(theta) sin(phi) right_c + cos(theta) up_c.
//
// Sky: the Perez et al. (1993) all-weather luminance distribution with the clear-sky luminance
// coefficients Preetham et al. (1999) give as linear functions of the turbidity T:
//   L(theta_p, gamma_p) / L_zenith = G(theta_p) S(gamma_p) / (G(0) S(theta_s))
//   G(theta) = 1 + a exp(b / cos theta)              (gradation: darker toward the zenith)
//   S(gamma) = 1 + c exp(d gamma) + e cos^2(gamma)   (scattering: bright around the sun)
// theta_p: zenith angle of the sky element, gamma_p: its angle to the sun, theta_s: the sun's
// zenith. The estimator fits an unknown exposure scale, so only G(theta_p) S(gamma_p) matters.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>

#include "sunvo/core/status.hpp"

namespace sunvo::sunvision {

struct PerezParameters {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0, e = 0.0;
};

// Preetham's luminance (Y) coefficients for turbidity T, valid for T in [1.7, 10].
PerezParameters clearSkyLuminanceParameters(double turbidity);

// G(theta) with cos(theta) clamped to >= 0.01 (the formula diverges at the horizon).
double perezGradation(const PerezParameters& p, double cos_theta);
// S(gamma), gamma in rad.
double perezScattering(const PerezParameters& p, double gamma_rad);

// S(gamma) tabulated over t = sin(gamma / 2) = sqrt((1 - cos gamma) / 2) in [0, 1], which is
// linear in gamma near the sun where S is steepest (the estimator evaluates it for every sky
// pixel and every candidate sun, where acos and exp would dominate the cost). Linear
// interpolation; relative error < 1e-3 for the default size.
class ScatteringTable {
 public:
  static constexpr int kSize = 2048;
  void build(const PerezParameters& p);
  double operator()(double cos_gamma) const {
    const double t = std::sqrt(std::max(0.0, 0.5 - 0.5 * cos_gamma));
    const double x = t * (kSize - 1);
    const int i = x >= kSize - 1 ? kSize - 2 : static_cast<int>(x);
    const double f = x - i;
    return values_[static_cast<std::size_t>(i)] * (1.0 - f) +
           values_[static_cast<std::size_t>(i) + 1] * f;
  }

 private:
  std::array<double, kSize> values_{};
};

struct HorizonFrame {
  Eigen::Vector3d up_c = -Eigen::Vector3d::UnitY();
  Eigen::Vector3d forward_c = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d right_c = Eigen::Vector3d::UnitX();

  // Fails when up_c is not finite, is ~0, or is within 10 deg of the optical axis (looking
  // straight up or down: no horizon, no forward direction).
  static Expected<HorizonFrame> fromUp(const Eigen::Vector3d& up_c);

  Eigen::Vector3d direction(double azimuth_rad, double zenith_rad) const;
  double azimuthRad(const Eigen::Vector3d& v_c) const;  // (-pi, pi]
  double zenithRad(const Eigen::Vector3d& v_c) const;   // [0, pi]
};

// Wraps an angle to (-pi, pi].
double wrapPi(double angle_rad);

}  // namespace sunvo::sunvision
