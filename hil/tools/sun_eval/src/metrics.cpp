#include "metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sunvo::suneval {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

double ratio(int n, int d) {
  return d > 0 ? static_cast<double>(n) / d : kNaN;
}

std::vector<double> absolute(const std::vector<double>& v) {
  std::vector<double> a;
  a.reserve(v.size());
  for (double x : v) a.push_back(std::abs(x));
  return a;
}
}  // namespace

double quantile(std::vector<double> values, double q) {
  values.erase(
      std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
      values.end());
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  const double t = pos - static_cast<double>(lo);
  return values[lo] + t * (values[hi] - values[lo]);
}

double wrapDeg(double a_deg) {
  double a = std::fmod(a_deg, 360.0);
  if (a > 180.0) a -= 360.0;
  if (a <= -180.0) a += 360.0;
  return a;
}

double azimuthDeg(const Eigen::Vector3d& v_c) {
  return wrapDeg(std::atan2(v_c.x(), v_c.z()) / kDeg);
}

double azimuthSigmaDeg(sunfusion::SunMeasurementKind kind, double sigma,
                       const Eigen::Vector3d& true_sun_c) {
  if (!std::isfinite(sigma)) return kNaN;
  if (kind == sunfusion::SunMeasurementKind::kAzimuthOnly) return sigma / kDeg;
  const double n = true_sun_c.norm();
  const double rho = n > 0.0 ? std::hypot(true_sun_c.x(), true_sun_c.z()) / n : 0.0;
  return sigma / std::max(rho, 0.1) / kDeg;
}

EstimatorSummary summarize(const std::vector<FrameResult>& frames) {
  EstimatorSummary s;
  s.frames = static_cast<int>(frames.size());
  std::vector<double> az, zen, cpu, wall;
  for (const FrameResult& f : frames) {
    cpu.push_back(f.cpu_ms);
    wall.push_back(f.wall_ms);
    const bool finite = std::isfinite(f.azimuth_error_deg);
    const bool gross = finite && std::abs(f.azimuth_error_deg) > kGrossAzimuthDeg;
    if (gross) {
      ++s.gross_any;
      if (!f.valid) ++s.gross_invalid;
    }
    if (!f.valid) continue;
    ++s.valid;
    if (f.kept_by_gate) ++s.kept;
    if (std::isfinite(f.zenith_error_deg)) zen.push_back(f.zenith_error_deg);
    if (!finite) continue;
    az.push_back(f.azimuth_error_deg);
    if (gross) ++s.gross;
    if (std::isfinite(f.azimuth_sigma_deg)) {
      ++s.sigma_checked;
      if (std::abs(f.azimuth_error_deg) < 2.0 * f.azimuth_sigma_deg) ++s.within_2sigma;
    }
  }
  s.valid_share = ratio(s.valid, s.frames);
  s.azimuth_median_deg = quantile(absolute(az), 0.5);
  s.azimuth_p90_deg = quantile(absolute(az), 0.9);
  s.azimuth_bias_deg = quantile(az, 0.5);
  s.zenith_median_deg = quantile(absolute(zen), 0.5);
  s.zenith_p90_deg = quantile(absolute(zen), 0.9);
  s.gross_share = ratio(s.gross, static_cast<int>(az.size()));
  s.gross_flagged = ratio(s.gross_invalid, s.gross_any);
  s.within_2sigma_share = ratio(s.within_2sigma, s.sigma_checked);
  s.kept_share = ratio(s.kept, s.frames);
  s.cpu_ms_median = quantile(cpu, 0.5);
  s.cpu_ms_p90 = quantile(cpu, 0.9);
  s.wall_ms_median = quantile(wall, 0.5);
  s.wall_ms_p90 = quantile(wall, 0.9);
  return s;
}

CueSummary summarizeCue(const std::vector<double>& errors_deg) {
  CueSummary c;
  c.frames = static_cast<int>(errors_deg.size());
  std::vector<double> a;
  for (double e : errors_deg) {
    if (!std::isfinite(e)) continue;
    a.push_back(std::abs(e));
    if (std::abs(e) > kGrossAzimuthDeg) ++c.gross;
  }
  c.informative = static_cast<int>(a.size());
  c.informative_share = ratio(c.informative, c.frames);
  c.median_deg = quantile(a, 0.5);
  c.p90_deg = quantile(a, 0.9);
  c.gross_share = ratio(c.gross, c.informative);
  return c;
}

}  // namespace sunvo::suneval
