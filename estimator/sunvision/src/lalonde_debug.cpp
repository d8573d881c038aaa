#include "sunvo/sunvision/lalonde_debug.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

namespace sunvo::sunvision {
namespace {
constexpr int kCellPx = 4;

// Grid column/row (fractional) of a direction.
cv::Point2d gridPoint(const LalondeEstimator& e, const Eigen::Vector3d& v_c) {
  const HorizonFrame& h = e.lastCues().horizon;
  const double az_deg = h.azimuthRad(v_c) * 180.0 / std::numbers::pi;
  const double zen_deg = h.zenithRad(v_c) * 180.0 / std::numbers::pi;
  return {(az_deg + 180.0) / 360.0 * e.azimuthBins() * kCellPx,
          zen_deg / 90.0 * e.zenithBins() * kCellPx};
}

// A log-likelihood (or probability) map drawn with the JET colour map, scaled to its maximum.
cv::Mat drawMap(const LalondeEstimator& e, const cv::Mat& values, bool is_log, const char* title,
                const sunfusion::ImageSunInput& input, const sunfusion::ImageSunEstimate& est,
                const std::optional<Eigen::Vector3d>& true_sun_c) {
  cv::Mat p;
  if (is_log) {
    double max_v = 0.0;
    cv::minMaxLoc(values, nullptr, &max_v);
    cv::subtract(values, cv::Scalar(max_v), p);
    cv::exp(p, p);
  } else {
    double max_v = 0.0;
    cv::minMaxLoc(values, nullptr, &max_v);
    p = values / std::max(max_v, 1e-300);
  }
  cv::Mat u8;
  p.convertTo(u8, CV_8U, 255.0);
  cv::Mat big;
  cv::resize(u8, big, cv::Size(), kCellPx, kCellPx, cv::INTER_NEAREST);
  cv::Mat colour;
  cv::applyColorMap(big, colour, cv::COLORMAP_JET);
  // Horizontal field of view: the azimuths of the left and right image borders on the horizon.
  const HorizonFrame& h = e.lastCues().horizon;
  for (double u : {0.0, static_cast<double>(input.camera.width)}) {
    const Eigen::Vector3d ray((u - input.camera.cu) / input.camera.fu, 0.0, 1.0);
    const Eigen::Vector3d flat =
        ray.dot(h.forward_c) * h.forward_c + ray.dot(h.right_c) * h.right_c;
    const double x = gridPoint(e, flat + 1e-6 * h.up_c).x;
    cv::line(colour, cv::Point2d(x, 0), cv::Point2d(x, colour.rows - 1), cv::Scalar(0, 0, 0), 2);
  }
  cv::circle(colour, gridPoint(e, est.measurement.sun_c), 7, cv::Scalar(0, 255, 255), 2);
  if (true_sun_c) {
    const cv::Point2d t = gridPoint(e, *true_sun_c);
    cv::drawMarker(colour, t, cv::Scalar(0, 255, 0), cv::MARKER_CROSS, 12, 2);
  }
  cv::putText(colour, title, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return colour;
}

bool projectPoint(const StereoCamera& cam, const Eigen::Vector3d& p_c, cv::Point2d* px) {
  if (p_c.z() < 0.1) return false;
  *px = cv::Point2d(cam.fu * p_c.x() / p_c.z() + cam.cu, cam.fv * p_c.y() / p_c.z() + cam.cv);
  return true;
}

// Shadow tip of a stick from base (on the ground) to top under a sun s: the top moved along -s
// until it meets the ground plane, top - s * (stick / (s . up)); capped at 6 stick lengths for a
// sun near the horizon.
Eigen::Vector3d shadowTip(const Eigen::Vector3d& base, const Eigen::Vector3d& up, double stick,
                          const Eigen::Vector3d& sun_c) {
  const Eigen::Vector3d s = sun_c.normalized();
  const double su = s.dot(up);
  const Eigen::Vector3d flat = s - su * up;
  if (flat.norm() < 1e-9) return base;
  const double length = su > 1e-6 ? std::min(stick * flat.norm() / su, 6.0 * stick) : 6.0 * stick;
  return base - flat.normalized() * length;
}
}  // namespace

Expected<LalondeDebugImages> renderLalondeDebug(const LalondeEstimator& estimator,
                                                const sunfusion::ImageSunInput& input,
                                                const sunfusion::ImageSunEstimate& estimate,
                                                const std::optional<Eigen::Vector3d>& true_sun_c) {
  const LalondeCues& cues = estimator.lastCues();
  if (cues.posterior.empty() || input.color.empty()) {
    return failedPrecondition("renderLalondeDebug: no estimate or no image");
  }
  LalondeDebugImages out;
  out.sky = drawMap(estimator, cues.sky_loglik, true, "sky", input, estimate, true_sun_c);
  out.shadow = drawMap(estimator, cues.shadow_loglik, true, "shadows", input, estimate, true_sun_c);
  out.prior = drawMap(estimator, cues.prior_loglik, true, "prior", input, estimate, true_sun_c);
  out.posterior =
      drawMap(estimator, cues.posterior, false, "combined", input, estimate, true_sun_c);

  if (input.color.type() == CV_8UC1) {
    cv::cvtColor(input.color, out.sundial, cv::COLOR_GRAY2BGR);
  } else {
    out.sundial = input.color.clone();
  }
  for (const ShadowLine& l : cues.shadow_lines) {
    cv::line(out.sundial, cv::Point2d(l.p0_px.x(), l.p0_px.y()),
             cv::Point2d(l.p1_px.x(), l.p1_px.y()), cv::Scalar(255, 128, 0), 1, cv::LINE_AA);
  }
  const HorizonFrame& h = cues.horizon;
  const double stick = 1.5, height = estimator.options().camera_height_m;
  const Eigen::Vector3d base = 8.0 * h.forward_c - height * h.up_c;
  const Eigen::Vector3d top = base + stick * h.up_c;
  cv::Point2d pb, pt, ps;
  if (projectPoint(input.camera, base, &pb) && projectPoint(input.camera, top, &pt)) {
    if (true_sun_c &&
        projectPoint(input.camera, shadowTip(base, h.up_c, stick, *true_sun_c), &ps)) {
      cv::line(out.sundial, pb, ps, cv::Scalar(0, 200, 0), 2, cv::LINE_AA);
    }
    if (projectPoint(input.camera, shadowTip(base, h.up_c, stick, estimate.measurement.sun_c),
                     &ps)) {
      cv::line(out.sundial, pb, ps, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
    }
    cv::line(out.sundial, pb, pt, cv::Scalar(0, 0, 255), 4, cv::LINE_AA);
  }
  const std::string label =
      std::string(estimator.name()) + (estimate.valid ? "" : " (invalid)") + "  az " +
      std::to_string(static_cast<int>(std::lround(estimate.azimuth_deg))) + "  zen " +
      std::to_string(static_cast<int>(std::lround(estimate.zenith_deg)));
  cv::putText(out.sundial, label, cv::Point(8, 22), cv::FONT_HERSHEY_SIMPLEX, 0.7,
              cv::Scalar(0, 255, 255), 2, cv::LINE_AA);

  cv::Mat top_row, bottom_row, maps;
  cv::hconcat(out.sky, out.shadow, top_row);
  cv::hconcat(out.prior, out.posterior, bottom_row);
  cv::vconcat(top_row, bottom_row, maps);
  cv::Mat dial;
  const double f = static_cast<double>(maps.cols) / out.sundial.cols;
  cv::resize(out.sundial, dial,
             cv::Size(maps.cols, std::max(1, static_cast<int>(out.sundial.rows * f))), 0, 0,
             cv::INTER_AREA);
  cv::vconcat(maps, dial, out.panel);
  return out;
}

}  // namespace sunvo::sunvision
