#include "sunvo/render/perez_sky.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>

namespace sunvo::render {
namespace {
constexpr double kPi = std::numbers::pi;

// CIE xyY -> linear sRGB (D65): X = x/y Y, Z = (1-x-y)/y Y, then the sRGB matrix.
Eigen::Vector3d xyYToRgb(double x, double y, double Y) {
  if (y <= 1e-9) return Eigen::Vector3d::Zero();
  const double X = x / y * Y;
  const double Z = (1.0 - x - y) / y * Y;
  Eigen::Vector3d rgb(3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
                      0.0557 * X - 0.2040 * Y + 1.0570 * Z);
  return rgb.cwiseMax(0.0);
}

double zenithChroma(const double (&m)[3][4], double T, double ts) {
  const double t[3] = {T * T, T, 1.0};
  const double s[4] = {ts * ts * ts, ts * ts, ts, 1.0};
  double v = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) v += t[i] * m[i][j] * s[j];
  return v;
}
}  // namespace

double perezF(const PerezCoefficients& c, double theta, double gamma) {
  const double cos_t = std::max(std::cos(theta), 0.01);
  const double cos_g = std::cos(gamma);
  return (1.0 + c.A * std::exp(c.B / cos_t)) *
         (1.0 + c.C * std::exp(c.D * gamma) + c.E * cos_g * cos_g);
}

PerezCoefficients preethamLuminanceCoefficients(double T) {
  return {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251, 0.1206 * T - 2.5771,
          -0.0670 * T + 0.3703};
}
PerezCoefficients preethamChromaXCoefficients(double T) {
  return {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125, -0.0641 * T - 0.8989,
          -0.0033 * T + 0.0452};
}
PerezCoefficients preethamChromaYCoefficients(double T) {
  return {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102, -0.0441 * T - 1.6537,
          -0.0109 * T + 0.0529};
}

double preethamZenithLuminanceKcd(double T, double ts) {
  const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * ts);
  return (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
}

Status SkyOptions::validate() const {
  if (!(turbidity >= 1.7 && turbidity <= 10.0)) {
    return invalidArgument("sky.turbidity out of range [1.7, 10]");
  }
  return Status::ok();
}

PerezSky::PerezSky(const Eigen::Vector3d& sun_enu, const SkyOptions& options)
    : sun_enu_(sun_enu.normalized()) {
  const double T = options.turbidity;
  theta_s_ = std::min(std::acos(std::clamp(sun_enu_.z(), -1.0, 1.0)), 89.5 * kPi / 180.0);
  // Re-point the sun vector to the clamped zenith at the same azimuth for gamma.
  const double h = std::hypot(sun_enu_.x(), sun_enu_.y());
  const Eigen::Vector2d dir_h =
      h > 1e-12 ? Eigen::Vector2d(sun_enu_.x() / h, sun_enu_.y() / h) : Eigen::Vector2d(0.0, 1.0);
  sun_enu_ = Eigen::Vector3d(std::sin(theta_s_) * dir_h.x(), std::sin(theta_s_) * dir_h.y(),
                             std::cos(theta_s_));
  cY_ = preethamLuminanceCoefficients(T);
  cx_ = preethamChromaXCoefficients(T);
  cy_ = preethamChromaYCoefficients(T);
  Yz_cd_ = std::max(preethamZenithLuminanceKcd(T, theta_s_), 0.0) * 1000.0;
  static constexpr double kX[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                                      {-0.02903, 0.06377, -0.03202, 0.00394},
                                      {0.11693, -0.21196, 0.06052, 0.25886}};
  static constexpr double kY[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                                      {-0.04214, 0.08970, -0.04153, 0.00516},
                                      {0.15346, -0.26756, 0.06670, 0.26688}};
  xz_ = zenithChroma(kX, T, theta_s_);
  yz_ = zenithChroma(kY, T, theta_s_);
  FY0_ = perezF(cY_, 0.0, theta_s_);
  Fx0_ = perezF(cx_, 0.0, theta_s_);
  Fy0_ = perezF(cy_, 0.0, theta_s_);
}

double PerezSky::luminanceRatio(const Eigen::Vector3d& dir_enu) const {
  const Eigen::Vector3d d = dir_enu.normalized();
  const double theta = std::acos(std::clamp(d.z(), 0.0, 1.0));
  const double gamma = std::acos(std::clamp(d.dot(sun_enu_), -1.0, 1.0));
  return perezF(cY_, theta, gamma) / FY0_;
}

SkyRadiance PerezSky::radiance(const Eigen::Vector3d& dir_enu) const {
  const Eigen::Vector3d d = dir_enu.normalized();
  const double theta = std::acos(std::clamp(d.z(), 0.0, 1.0));
  const double gamma = std::acos(std::clamp(d.dot(sun_enu_), -1.0, 1.0));
  SkyRadiance r;
  r.Y_cd = Yz_cd_ * perezF(cY_, theta, gamma) / FY0_;
  r.x = xz_ * perezF(cx_, theta, gamma) / Fx0_;
  r.y = yz_ * perezF(cy_, theta, gamma) / Fy0_;
  r.rgb = xyYToRgb(r.x, r.y, r.Y_cd);
  return r;
}

double PerezSky::horizontalIlluminanceLux(Eigen::Vector3d* rgb_out) const {
  constexpr int kNt = 90, kNp = 180;
  const double dt = 0.5 * kPi / kNt, dp = 2.0 * kPi / kNp;
  double E = 0.0;
  Eigen::Vector3d E_rgb = Eigen::Vector3d::Zero();
  for (int i = 0; i < kNt; ++i) {
    const double th = (i + 0.5) * dt;
    // d omega = sin(theta) dtheta dphi; the horizontal surface weights by cos(theta).
    const double w = std::cos(th) * std::sin(th) * dt * dp;
    for (int j = 0; j < kNp; ++j) {
      const double ph = (j + 0.5) * dp;
      const Eigen::Vector3d d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph),
                              std::cos(th));
      const SkyRadiance r = radiance(d);
      E += r.Y_cd * w;
      E_rgb += r.rgb * w;
    }
  }
  if (rgb_out != nullptr) *rgb_out = E_rgb;
  return E;
}

cv::Mat PerezSky::equirectangular(int width, int height, double scale,
                                  const Eigen::Vector3d& ground_rgb) const {
  cv::Mat img(height, width, CV_32FC3);
  for (int i = 0; i < height; ++i) {
    const double el = 0.5 * kPi - kPi * (i + 0.5) / height;
    for (int j = 0; j < width; ++j) {
      const double th = 2.0 * kPi * (j + 0.5) / width;
      Eigen::Vector3d rgb = ground_rgb;
      if (el >= 0.0) {
        const Eigen::Vector3d d(std::cos(el) * std::cos(th), std::cos(el) * std::sin(th),
                                std::sin(el));
        rgb = radiance(d).rgb;
      }
      img.at<cv::Vec3f>(i, j) =
          cv::Vec3f(static_cast<float>(scale * rgb.z()), static_cast<float>(scale * rgb.y()),
                    static_cast<float>(scale * rgb.x()));
    }
  }
  return img;
}

double directSunIlluminanceLux(double zs, double T) {
  const double zdeg = zs * 180.0 / kPi;
  if (zdeg >= 90.0) return 0.0;
  // Kasten & Young (1989) relative optical air mass.
  const double m = 1.0 / (std::cos(zs) + 0.50572 * std::pow(96.07995 - zdeg, -1.6364));
  // Kasten (1996) integral Rayleigh optical thickness.
  const double dR = m <= 20.0 ? 1.0 / (6.6296 + 1.7513 * m - 0.1202 * m * m + 0.0065 * m * m * m -
                                       0.00013 * m * m * m * m)
                              : 1.0 / (10.4 + 0.718 * m);
  return 128000.0 * std::exp(-0.8662 * T * m * dR);
}

Eigen::Vector3d sunColour(double zs, double T) {
  const double zdeg = std::min(zs * 180.0 / kPi, 89.9);
  const double m =
      1.0 / (std::cos(zdeg * kPi / 180.0) + 0.50572 * std::pow(96.07995 - zdeg, -1.6364));
  const double beta = 0.04608 * T - 0.04586;
  const double lam[3] = {0.610, 0.550, 0.465};
  Eigen::Vector3d t;
  for (int c = 0; c < 3; ++c) {
    const double tau = 0.008735 * std::pow(lam[c], -4.08) + beta * std::pow(lam[c], -1.3);
    t[c] = std::exp(-m * tau);
  }
  return t / t.y();
}

}  // namespace sunvo::render
