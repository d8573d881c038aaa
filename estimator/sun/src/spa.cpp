#include "sunvo/sun/spa.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <string>

#include "spa_tables.hpp"

namespace sunvo::sun {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kRadPerDeg = kPi / 180.0;
// Sun semi-diameter, deg (SPA report, sunrise/sunset section).
constexpr double kSunRadiusDeg = 0.26667;
// JD of J2000.0 (2000-01-01 12:00:00) and its Unix time, s.
constexpr double kJdJ2000 = 2451545.0;
constexpr std::int64_t kUnixJ2000S = 946728000;
constexpr std::int64_t kNsPerDay = 86400 * kNsPerSecond;

double rad(double deg) {
  return deg * kRadPerDeg;
}
double deg(double r) {
  return r * kDegPerRad;
}

// Reduces an angle in degrees to [0, 360).
double limitDegrees(double a) {
  double r = std::fmod(a, 360.0);
  if (r < 0.0) r += 360.0;
  return r >= 360.0 ? 0.0 : r;
}

// Sum over one VSOP87 series: sum_i A_i cos(B_i + C_i JME) (report Eq. 9).
template <std::size_t N>
double seriesSum(const std::array<detail::EarthTerm, N>& terms, double jme) {
  double s = 0.0;
  for (const auto& t : terms) s += t.a * std::cos(t.b + t.c * jme);
  return s;
}

// Horner evaluation of (S0 + S1 JME + S2 JME^2 + ...) / 1e8 (report Eq. 10-11), in radians or AU.
double earthValue(std::initializer_list<double> sums, double jme) {
  double v = 0.0;
  const double* begin = sums.begin();
  for (const double* p = sums.end(); p != begin;) {
    --p;
    v = v * jme + *p;
  }
  return v / 1e8;
}

// Third-order polynomial c0 + c1 x + c2 x^2 + x^3 / c3_inv (the forms of report Eq. 15-19).
double poly3(double c0, double c1, double c2, double c3_inverse_divisor, double x) {
  return c0 + x * (c1 + x * (c2 + x / c3_inverse_divisor));
}

// Yearly Delta T = TT - UT1 on 1 January, s (IERS/USNO published values, rounded to 0.01 s;
// 2024 and 2025 are the IERS values of those years to about 0.1 s).
constexpr int kDeltaTFirstYear = 1990;
constexpr std::array<double, 36> kDeltaTTable{
    56.86, 57.57, 58.31, 59.12, 59.98, 60.79, 61.63, 62.30, 62.97, 63.47,  // 1990-1999
    63.83, 64.09, 64.30, 64.47, 64.57, 64.69, 64.85, 65.15, 65.46, 65.78,  // 2000-2009
    66.07, 66.32, 66.60, 66.91, 67.28, 67.64, 68.10, 68.59, 68.97, 69.22,  // 2010-2019
    69.36, 69.36, 69.29, 69.20, 69.18, 69.14,                              // 2020-2025
};

}  // namespace

Status SpaOptions::validate() const {
  auto check = [](double v, double lo, double hi, const char* key, const char* unit) -> Status {
    if (!std::isfinite(v) || v < lo || v > hi) {
      return invalidArgument("SpaOptions." + std::string(key) + " = " + std::to_string(v) +
                             " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) +
                             "] " + unit);
    }
    return Status::ok();
  };
  SUNVO_RETURN_IF_ERROR(check(latitude_deg, -90.0, 90.0, "latitude_deg", "deg"));
  SUNVO_RETURN_IF_ERROR(check(longitude_deg, -180.0, 180.0, "longitude_deg", "deg"));
  SUNVO_RETURN_IF_ERROR(check(elevation_m, -1000.0, 100000.0, "elevation_m", "m"));
  SUNVO_RETURN_IF_ERROR(check(pressure_mbar, 0.0, 5000.0, "pressure_mbar", "mbar"));
  SUNVO_RETURN_IF_ERROR(check(temperature_c, -100.0, 100.0, "temperature_c", "deg C"));
  if (delta_t_s) SUNVO_RETURN_IF_ERROR(check(*delta_t_s, -8000.0, 8000.0, "delta_t_s", "s"));
  if (!std::isfinite(delta_ut1_s) || delta_ut1_s <= -1.0 || delta_ut1_s >= 1.0) {
    return invalidArgument("SpaOptions.delta_ut1_s = " + std::to_string(delta_ut1_s) +
                           " is outside (-1, 1) s");
  }
  SUNVO_RETURN_IF_ERROR(
      check(atmospheric_refraction_deg, -5.0, 5.0, "atmospheric_refraction_deg", "deg"));
  if (vector_zenith != SunVectorZenith::kUnrefracted &&
      vector_zenith != SunVectorZenith::kRefracted) {
    return invalidArgument("SpaOptions.vector_zenith has an unknown value");
  }
  return Status::ok();
}

double defaultDeltaTSeconds(TimeNs t_utc) {
  // Fractional year from the Unix time: 1970 + days / 365.2425 is within a day of the civil
  // year fraction, and Delta T changes < 0.01 s per day.
  const double year = 1970.0 + toSeconds(t_utc) / (86400.0 * 365.2425);
  const double x = year - kDeltaTFirstYear;
  const auto last = static_cast<double>(kDeltaTTable.size() - 1);
  if (x <= 0.0) return kDeltaTTable.front();
  if (x >= last) return kDeltaTTable.back();
  const auto i = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(i);
  return kDeltaTTable[i] + f * (kDeltaTTable[i + 1] - kDeltaTTable[i]);
}

Eigen::Vector3d enuFromZenithAzimuth(double zenith_deg, double azimuth_deg) {
  // Azimuth a from north toward east, zenith z from up: the horizontal part sin z splits into
  // north (cos a) and east (sin a); up is cos z.
  const double z = rad(zenith_deg);
  const double a = rad(azimuth_deg);
  return {std::sin(z) * std::sin(a), std::sin(z) * std::cos(a), std::cos(z)};
}

Expected<SolarPosition> computeSolarPosition(TimeNs t_utc, const SpaOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SolarPosition out;
  SpaIntermediate& m = out.intermediate;

  // --- 3.1 Time scales. JD (UT1) = 2451545 + days since J2000.0 (Unix time 946728000 s);
  // split into whole days and the rest so that the fraction keeps ns resolution.
  // JDE = JD + Delta T / 86400; JC, JCE: Julian centuries from J2000.0 (Eq. 5-6);
  // JME = JCE / 10 (Eq. 7).
  const std::int64_t since_j2000_ns = t_utc - kUnixJ2000S * kNsPerSecond;
  const double days_ut1 =
      static_cast<double>(since_j2000_ns / kNsPerDay) +
      (static_cast<double>(since_j2000_ns % kNsPerDay) * 1e-9 + options.delta_ut1_s) / 86400.0;
  const double delta_t = options.delta_t_s ? *options.delta_t_s : defaultDeltaTSeconds(t_utc);
  const double days_tt = days_ut1 + delta_t / 86400.0;
  m.delta_t_s = delta_t;
  m.julian_day = kJdJ2000 + days_ut1;
  m.julian_ephemeris_day = kJdJ2000 + days_tt;
  const double jc = days_ut1 / 36525.0;
  const double jce = days_tt / 36525.0;
  const double jme = jce / 10.0;

  // --- 3.2 Earth heliocentric longitude L, latitude B (rad -> deg) and radius R (AU):
  // X = (X0 + X1 JME + ... + Xn JME^n) / 1e8 with Xi the series sums (Eq. 9-11).
  const double L_rad = earthValue(
      {seriesSum(detail::kL0, jme), seriesSum(detail::kL1, jme), seriesSum(detail::kL2, jme),
       seriesSum(detail::kL3, jme), seriesSum(detail::kL4, jme), seriesSum(detail::kL5, jme)},
      jme);
  const double B_rad = earthValue({seriesSum(detail::kB0, jme), seriesSum(detail::kB1, jme)}, jme);
  const double R = earthValue(
      {seriesSum(detail::kR0, jme), seriesSum(detail::kR1, jme), seriesSum(detail::kR2, jme),
       seriesSum(detail::kR3, jme), seriesSum(detail::kR4, jme)},
      jme);
  m.L_deg = limitDegrees(deg(L_rad));
  m.B_deg = deg(B_rad);
  m.R_au = R;

  // --- 3.3 Geocentric longitude Theta = L + 180 deg, latitude beta = -B (Eq. 13-14).
  const double theta_deg = limitDegrees(m.L_deg + 180.0);
  const double beta_deg = -m.B_deg;

  // --- 3.4 Nutation. Fundamental arguments (deg, Eq. 15-19):
  //   X0 = D  = 297.85036 + 445267.111480 JCE - 0.0019142 JCE^2 + JCE^3 / 189474
  //   X1 = M  = 357.52772 + 35999.050340 JCE - 0.0001603 JCE^2 - JCE^3 / 300000
  //   X2 = M' = 134.96298 + 477198.867398 JCE + 0.0086972 JCE^2 + JCE^3 / 56250
  //   X3 = F  = 93.27191 + 483202.017538 JCE - 0.0036825 JCE^2 + JCE^3 / 327270
  //   X4 = Om = 125.04452 - 1934.136261 JCE + 0.0020708 JCE^2 + JCE^3 / 450000
  // Delta psi = sum (a + b JCE) sin(sum_j X_j Y_ij) / 36e6 deg, Delta eps likewise with
  // (c + d JCE) cos(...) (Eq. 20-23; coefficients in 0.0001").
  const std::array<double, 5> x{
      poly3(297.85036, 445267.111480, -0.0019142, 189474.0, jce),
      poly3(357.52772, 35999.050340, -0.0001603, -300000.0, jce),
      poly3(134.96298, 477198.867398, 0.0086972, 56250.0, jce),
      poly3(93.27191, 483202.017538, -0.0036825, 327270.0, jce),
      poly3(125.04452, -1934.136261, 0.0020708, 450000.0, jce),
  };
  double sum_psi = 0.0;
  double sum_eps = 0.0;
  for (const auto& t : detail::kNutation) {
    const double arg = rad(x[0] * t.y0 + x[1] * t.y1 + x[2] * t.y2 + x[3] * t.y3 + x[4] * t.y4);
    sum_psi += (t.a + t.b * jce) * std::sin(arg);
    sum_eps += (t.c + t.d * jce) * std::cos(arg);
  }
  m.delta_psi_deg = sum_psi / 36000000.0;
  m.delta_epsilon_deg = sum_eps / 36000000.0;

  // --- 3.5 True obliquity: eps0 (arcsec) = 84381.448 - 4680.93 U - 1.55 U^2 + 1999.25 U^3
  //   - 51.38 U^4 - 249.67 U^5 - 39.05 U^6 + 7.12 U^7 + 27.87 U^8 + 5.79 U^9 + 2.45 U^10,
  //   U = JME / 10; eps = eps0 / 3600 + Delta eps (Eq. 24-25).
  static constexpr std::array<double, 11> kEps0{
      84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67, -39.05, 7.12, 27.87, 5.79, 2.45};
  const double u = jme / 10.0;
  double eps0 = 0.0;
  for (auto it = kEps0.rbegin(); it != kEps0.rend(); ++it) eps0 = eps0 * u + *it;
  m.epsilon_deg = eps0 / 3600.0 + m.delta_epsilon_deg;

  // --- 3.6-3.7 Aberration Delta tau = -20.4898" / (3600 R) and apparent sun longitude
  // lambda = Theta + Delta psi + Delta tau (Eq. 26-27).
  const double delta_tau_deg = -20.4898 / (3600.0 * R);
  m.lambda_deg = limitDegrees(theta_deg + m.delta_psi_deg + delta_tau_deg);

  // --- 3.8 Apparent sidereal time at Greenwich: nu0 = 280.46061837 + 360.98564736629 (JD -
  // 2451545) + 0.000387933 JC^2 - JC^3 / 38710000, nu = nu0 + Delta psi cos eps (Eq. 28-29).
  const double eps = rad(m.epsilon_deg);
  const double nu0 = limitDegrees(280.46061837 + 360.98564736629 * days_ut1 +
                                  jc * jc * (0.000387933 - jc / 38710000.0));
  m.nu_deg = limitDegrees(nu0 + m.delta_psi_deg * std::cos(eps));

  // --- 3.9-3.10 Geocentric right ascension and declination of (lambda, beta) (Eq. 30-31):
  // alpha = atan2(sin lambda cos eps - tan beta sin eps, cos lambda),
  // delta = asin(sin beta cos eps + cos beta sin eps sin lambda).
  const double lambda = rad(m.lambda_deg);
  const double beta = rad(beta_deg);
  const double alpha = std::atan2(std::sin(lambda) * std::cos(eps) - std::tan(beta) * std::sin(eps),
                                  std::cos(lambda));
  const double delta =
      std::asin(std::sin(beta) * std::cos(eps) + std::cos(beta) * std::sin(eps) * std::sin(lambda));
  m.alpha_deg = limitDegrees(deg(alpha));
  m.delta_deg = deg(delta);

  // --- 3.11 Local hour angle H = nu + sigma - alpha, sigma east-positive longitude (Eq. 32).
  m.H_deg = limitDegrees(m.nu_deg + options.longitude_deg - m.alpha_deg);
  const double H = rad(m.H_deg);

  // --- 3.12 Topocentric correction (parallax). Equatorial horizontal parallax
  // xi = 8.794" / (3600 R); u = atan(0.99664719 tan phi) (reduced latitude, 0.99664719 = b/a of
  // the report's ellipsoid); x = cos u + E/6378140 cos phi; y = 0.99664719 sin u + E/6378140
  // sin phi; Delta alpha = atan2(-x sin xi sin H, cos delta - x sin xi cos H);
  // delta' = atan2((sin delta - y sin xi) cos Delta alpha, cos delta - x sin xi cos H)
  // (Eq. 33-38). The reduced latitude is formed with sin/cos instead of tan so that phi = +-90
  // stays finite.
  const double phi = rad(options.latitude_deg);
  const double xi = rad(8.794 / (3600.0 * R));
  const double u_lat = std::atan2(0.99664719 * std::sin(phi), std::cos(phi));
  const double e_ratio = options.elevation_m / 6378140.0;
  const double xx = std::cos(u_lat) + e_ratio * std::cos(phi);
  const double yy = 0.99664719 * std::sin(u_lat) + e_ratio * std::sin(phi);
  const double denom = std::cos(delta) - xx * std::sin(xi) * std::cos(H);
  const double delta_alpha = std::atan2(-xx * std::sin(xi) * std::sin(H), denom);
  const double delta_topo =
      std::atan2((std::sin(delta) - yy * std::sin(xi)) * std::cos(delta_alpha), denom);
  m.alpha_topo_deg = limitDegrees(m.alpha_deg + deg(delta_alpha));
  m.delta_topo_deg = deg(delta_topo);
  // H' = H - Delta alpha (Eq. 39).
  const double H_topo = H - delta_alpha;
  m.H_topo_deg = limitDegrees(deg(H_topo));

  // --- 3.13 Topocentric elevation without refraction (Eq. 41):
  // e0 = asin(sin phi sin delta' + cos phi cos delta' cos H').
  const double e0_deg =
      deg(std::asin(std::clamp(std::sin(phi) * std::sin(delta_topo) +
                                   std::cos(phi) * std::cos(delta_topo) * std::cos(H_topo),
                               -1.0, 1.0)));
  // Refraction (Eq. 42): Delta e = P/1010 * 283/(273 + T) * 1.02 / (60 tan(e0 + 10.3/(e0 +
  // 5.11))) deg, with e0 in deg inside the tangent's argument. Applied only while the sun's
  // upper limb can be above the horizon, e0 >= -(semi-diameter + horizon refraction); below
  // that the formula's pole at e0 = -5.11 deg would make it meaningless.
  double delta_e_deg = 0.0;
  if (e0_deg >= -(kSunRadiusDeg + options.atmospheric_refraction_deg)) {
    delta_e_deg = (options.pressure_mbar / 1010.0) * (283.0 / (273.0 + options.temperature_c)) *
                  1.02 / (60.0 * std::tan(rad(e0_deg + 10.3 / (e0_deg + 5.11))));
  }
  // Zenith theta = 90 - e (Eq. 43-44).
  out.zenith_deg = 90.0 - e0_deg;
  out.zenith_refracted_deg = 90.0 - (e0_deg + delta_e_deg);

  // --- 3.14 Azimuth. Astronomers' azimuth (from south, westward) Gamma = atan2(sin H',
  // cos H' sin phi - tan delta' cos phi); navigators' azimuth Phi = Gamma + 180 (from north,
  // eastward) (Eq. 45-46). tan delta' cos phi is written sin delta' cos phi / cos delta' and the
  // whole atan2 is multiplied by cos delta' > 0 to stay finite for any delta'.
  const double gamma = std::atan2(std::sin(H_topo) * std::cos(delta_topo),
                                  std::cos(H_topo) * std::sin(phi) * std::cos(delta_topo) -
                                      std::sin(delta_topo) * std::cos(phi));
  out.azimuth_deg = limitDegrees(deg(gamma) + 180.0);

  out.sun_enu = enuFromZenithAzimuth(options.vector_zenith == SunVectorZenith::kRefracted
                                         ? out.zenith_refracted_deg
                                         : out.zenith_deg,
                                     out.azimuth_deg);
  return out;
}

}  // namespace sunvo::sun
