#pragma once
// Physical clear-sky model for the renderer: the Perez all-weather sky luminance distribution
// (R. Perez, R. Seals, J. Michalsky, "All-weather model for sky luminance distribution",
// Solar Energy 50(3), 1993) with the turbidity-dependent coefficients, zenith luminance and
// zenith chromaticity of A. J. Preetham, P. Shirley, B. Smits, "A practical analytic model for
// daylight", SIGGRAPH 1999. Directions are unit vectors in local ENU (x east, y north, z up).

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "sunvo/core/status.hpp"

namespace sunvo::render {

// The five Perez coefficients of one channel (Y, x or y).
struct PerezCoefficients {
  double A = 0.0, B = 0.0, C = 0.0, D = 0.0, E = 0.0;
};

// Perez et al. Eq.: F(theta, gamma) = (1 + A e^{B / cos theta}) (1 + C e^{D gamma} + E cos^2 gamma)
// with theta the zenith angle of the sky element and gamma its angle to the sun (rad).
// cos theta is clamped to >= 0.01 (the formula diverges at and below the horizon).
double perezF(const PerezCoefficients& c, double theta, double gamma);

// Preetham et al. 1999, Appendix A.2, for turbidity T.
PerezCoefficients preethamLuminanceCoefficients(double turbidity);
PerezCoefficients preethamChromaXCoefficients(double turbidity);
PerezCoefficients preethamChromaYCoefficients(double turbidity);

// Zenith luminance Y_z in kcd/m^2: (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192 with
// chi = (4/9 - T/120)(pi - 2 theta_s).
double preethamZenithLuminanceKcd(double turbidity, double sun_zenith_rad);

struct SkyOptions {
  // Atmospheric turbidity (Preetham's T). Valid [1.7, 10]; 2 = very clear, 3 = clear, 6 = hazy.
  double turbidity = 3.0;
  Status validate() const;
};

// Linear sRGB radiance (luminance units cd/m^2 per channel, Y = luminance).
struct SkyRadiance {
  double Y_cd = 0.0;                              // luminance, cd/m^2
  double x = 0.3127, y = 0.329;                   // CIE chromaticity
  Eigen::Vector3d rgb = Eigen::Vector3d::Zero();  // linear sRGB, scaled so that luminance = Y_cd
};

class PerezSky {
 public:
  // sun_enu: unit vector toward the sun (its zenith angle is clamped to <= 89.5 deg for the
  // model, which Preetham fitted for the sun above the horizon).
  PerezSky(const Eigen::Vector3d& sun_enu, const SkyOptions& options);

  // Ratio L(dir) / L(zenith) = F(theta, gamma) / F(0, theta_s)  (Perez Eq. normalised at the
  // zenith, so the ratio is 1 there by construction).
  double luminanceRatio(const Eigen::Vector3d& dir_enu) const;
  // Luminance and colour of the sky element in direction dir_enu (z >= 0 expected; below the
  // horizon the horizon value is returned).
  SkyRadiance radiance(const Eigen::Vector3d& dir_enu) const;

  // Illuminance of a horizontal surface by the whole sky, lx: integral of L cos(theta) d omega,
  // by the midpoint rule on a (zenith 90 x azimuth 180) grid. rgb_out gets the same integral
  // per linear sRGB channel (luminance-scaled).
  double horizontalIlluminanceLux(Eigen::Vector3d* rgb_out = nullptr) const;

  // Equirectangular sky image (CV_32FC3, BGR, linear, value = scale * radiance rgb) laid out as
  // POV-Ray's spherical image map (map_type 1) expects with the scene's POV axes
  // <east, up, north>: column j covers longitude theta = 2 pi (j + 0.5) / width measured from
  // east toward north; row i covers elevation pi/2 - pi (i + 0.5) / height. Below the horizon
  // the value is ground_rgb * scale.
  cv::Mat equirectangular(int width, int height, double scale,
                          const Eigen::Vector3d& ground_rgb) const;

  double sunZenithRad() const { return theta_s_; }

 private:
  Eigen::Vector3d sun_enu_;
  double theta_s_ = 0.0;
  PerezCoefficients cY_, cx_, cy_;
  double Yz_cd_ = 0.0, xz_ = 0.0, yz_ = 0.0;
  double FY0_ = 1.0, Fx0_ = 1.0, Fy0_ = 1.0;
};

// Direct normal illuminance of the sun, lx, from Kasten's pyrheliometric formula with the Linke
// turbidity taken as Preetham's T: E = 128000 exp(-0.8662 T m deltaR(m)), m the Kasten-Young
// relative air mass; 0 below the horizon.
double directSunIlluminanceLux(double sun_zenith_rad, double turbidity);

// Relative colour of direct sunlight (linear sRGB, G = 1): Rayleigh (0.008735 lambda^-4.08) and
// Angstrom aerosol (beta lambda^-1.3, beta = 0.04608 T - 0.04586, Preetham) transmittance along
// the air mass at 610/550/465 nm.
Eigen::Vector3d sunColour(double sun_zenith_rad, double turbidity);

}  // namespace sunvo::render
