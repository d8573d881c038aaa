#include "sunvo/sunvision/sky_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace sunvo::sunvision {

PerezParameters clearSkyLuminanceParameters(double turbidity) {
  // Preetham, Shirley, Smits 1999, Appendix A.2, luminance row.
  const double t = turbidity;
  PerezParameters p;
  p.a = 0.1787 * t - 1.4630;
  p.b = -0.3554 * t + 0.4275;
  p.c = -0.0227 * t + 5.3251;
  p.d = 0.1206 * t - 2.5771;
  p.e = -0.0670 * t + 0.3703;
  return p;
}

double perezGradation(const PerezParameters& p, double cos_theta) {
  return 1.0 + p.a * std::exp(p.b / std::max(cos_theta, 0.01));
}

double perezScattering(const PerezParameters& p, double gamma_rad) {
  const double cg = std::cos(gamma_rad);
  return 1.0 + p.c * std::exp(p.d * gamma_rad) + p.e * cg * cg;
}

void ScatteringTable::build(const PerezParameters& p) {
  for (int i = 0; i < kSize; ++i) {
    const double t = static_cast<double>(i) / (kSize - 1);  // sin(gamma / 2)
    values_[static_cast<std::size_t>(i)] = perezScattering(p, 2.0 * std::asin(t));
  }
}

Expected<HorizonFrame> HorizonFrame::fromUp(const Eigen::Vector3d& up_c) {
  if (!up_c.allFinite() || up_c.norm() < 1e-9) {
    return invalidArgument("prior.up_c must be a finite non-zero vector");
  }
  HorizonFrame h;
  h.up_c = up_c.normalized();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d f = z - z.dot(h.up_c) * h.up_c;
  if (f.norm() < std::sin(10.0 * std::numbers::pi / 180.0)) {
    return invalidArgument("prior.up_c within 10 deg of the optical axis: no horizon in view");
  }
  h.forward_c = f.normalized();
  h.right_c = h.forward_c.cross(h.up_c);
  return h;
}

Eigen::Vector3d HorizonFrame::direction(double azimuth_rad, double zenith_rad) const {
  const double st = std::sin(zenith_rad);
  return st * std::cos(azimuth_rad) * forward_c + st * std::sin(azimuth_rad) * right_c +
         std::cos(zenith_rad) * up_c;
}

double HorizonFrame::azimuthRad(const Eigen::Vector3d& v_c) const {
  return std::atan2(v_c.dot(right_c), v_c.dot(forward_c));
}

double HorizonFrame::zenithRad(const Eigen::Vector3d& v_c) const {
  const double n = v_c.norm();
  if (n < 1e-12) return 0.0;
  return std::acos(std::clamp(v_c.dot(up_c) / n, -1.0, 1.0));
}

double wrapPi(double angle_rad) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double a = std::fmod(angle_rad + std::numbers::pi, kTwoPi);
  if (a <= 0.0) a += kTwoPi;
  return a - std::numbers::pi;
}

}  // namespace sunvo::sunvision
