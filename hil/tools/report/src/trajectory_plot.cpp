#include "sunvo/report/trajectory_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::report {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

using Points2 = std::vector<Eigen::Vector2d>;

// Plane coordinates of a series, re-anchored on the ground truth's first pose.
Points2 planePoints(const std::vector<Isometry3>& T_w_c, const Isometry3& T_w_c_gt0,
                    metrics::HorizontalPlane plane) {
  Points2 out;
  if (T_w_c.empty()) return out;
  const auto [ia, ib] = metrics::planeAxes(plane);
  const Isometry3 anchor = T_w_c_gt0 * T_w_c.front().inverse(Eigen::Isometry);
  out.reserve(T_w_c.size());
  for (const Isometry3& T : T_w_c) {
    const Eigen::Vector3d p = anchor * T.translation();
    out.emplace_back(p(ia), p(ib));
  }
  return out;
}

// The smallest of 1, 2, 5 × 10^n that is >= raw.
double niceStep(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw * (1.0 - 1e-12)) return m * p;
  }
  return 10.0 * p;
}

std::string formatMetres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", std::abs(v) < 1e-9 ? 0.0 : v);
  return buf;
}

void drawPolyline(cv::Mat& img, const Points2& pts, const TopViewLayout& layout,
                  const cv::Scalar& color, int width) {
  std::vector<cv::Point> px;
  px.reserve(pts.size());
  for (const auto& p : pts) {
    const cv::Point q = layout.toPixel(p.x(), p.y());
    if (px.empty() || px.back() != q) px.push_back(q);
  }
  if (px.size() == 1) {
    cv::circle(img, px.front(), width, color, cv::FILLED, cv::LINE_AA);
    return;
  }
  cv::polylines(img, px, false, color, width, cv::LINE_AA);
}

}  // namespace

Status PlotOptions::validate() const {
  if (plot_size_px < 200 || plot_size_px > 8000) {
    return invalidArgument("plot.plot_size_px: must be in [200, 8000] px");
  }
  if (margin_px < 30 || margin_px > 500) {
    return invalidArgument("plot.margin_px: must be in [30, 500] px");
  }
  if (legend_width_px < 100 || legend_width_px > 2000) {
    return invalidArgument("plot.legend_width_px: must be in [100, 2000] px");
  }
  if (line_width_px < 1 || line_width_px > 20) {
    return invalidArgument("plot.line_width_px: must be in [1, 20] px");
  }
  return Status::ok();
}

cv::Point TopViewLayout::toPixel(double a, double b) const {
  return {static_cast<int>(std::lround(u0 + (a - a0) * px_per_m)),
          static_cast<int>(std::lround(v0 - (b - b0) * px_per_m))};
}

cv::Scalar groundTruthColor() {
  return {0, 0, 0};
}

cv::Scalar estimateColor(std::size_t i) {
  static const std::array<cv::Scalar, 8> kPalette = {
      cv::Scalar(40, 40, 220), cv::Scalar(200, 110, 0),  cv::Scalar(0, 150, 0),
      cv::Scalar(0, 140, 255), cv::Scalar(180, 0, 180),  cv::Scalar(150, 150, 0),
      cv::Scalar(90, 60, 140), cv::Scalar(120, 120, 120)};
  return kPalette[i % kPalette.size()];
}

TopViewLayout computeTopViewLayout(const std::vector<Isometry3>& T_w_c_gt,
                                   const std::vector<PlotSeries>& estimates,
                                   metrics::HorizontalPlane plane, const PlotOptions& options) {
  TopViewLayout layout;
  if (T_w_c_gt.empty()) return layout;
  double a_min = INFINITY, a_max = -INFINITY, b_min = INFINITY, b_max = -INFINITY;
  auto extend = [&](const Points2& pts) {
    for (const auto& p : pts) {
      a_min = std::min(a_min, p.x());
      a_max = std::max(a_max, p.x());
      b_min = std::min(b_min, p.y());
      b_max = std::max(b_max, p.y());
    }
  };
  extend(planePoints(T_w_c_gt, T_w_c_gt.front(), plane));
  for (const auto& s : estimates) extend(planePoints(s.T_w_c, T_w_c_gt.front(), plane));
  // A square window (equal scale) around the centre of the bounding box, 5 % padding, >= 1 m.
  const double extent = std::max({a_max - a_min, b_max - b_min, 1.0}) * 1.05;
  layout.px_per_m = options.plot_size_px / extent;
  layout.a0 = 0.5 * (a_min + a_max) - 0.5 * extent;
  layout.b0 = 0.5 * (b_min + b_max) - 0.5 * extent;
  layout.u0 = options.margin_px;
  layout.v0 = options.margin_px + options.plot_size_px;
  layout.grid_step_m = niceStep(extent / 8.0);
  return layout;
}

Expected<cv::Mat> renderTopView(const std::vector<Isometry3>& T_w_c_gt,
                                const std::vector<PlotSeries>& estimates,
                                metrics::HorizontalPlane plane, const PlotOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  if (T_w_c_gt.empty()) return invalidArgument("plot: empty ground truth");
  for (const auto& s : estimates) {
    if (s.T_w_c.empty()) return invalidArgument("plot: estimate '" + s.name + "' is empty");
  }
  const TopViewLayout L = computeTopViewLayout(T_w_c_gt, estimates, plane, options);
  const int m = options.margin_px;
  const int size = options.plot_size_px;
  cv::Mat img(2 * m + size, 2 * m + size + options.legend_width_px, CV_8UC3,
              cv::Scalar(255, 255, 255));
  const cv::Scalar grid_color(225, 225, 225);
  const cv::Scalar text_color(40, 40, 40);
  const double extent = size / L.px_per_m;

  // Metric grid with tick labels.
  const double step = L.grid_step_m;
  for (double a = std::ceil(L.a0 / step) * step; a <= L.a0 + extent; a += step) {
    const int u = L.toPixel(a, L.b0).x;
    cv::line(img, {u, m}, {u, m + size}, grid_color, 1);
    const std::string label = formatMetres(a);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, kFont, 0.4, 1, &base);
    cv::putText(img, label, {u - ts.width / 2, m + size + 16}, kFont, 0.4, text_color, 1,
                cv::LINE_AA);
  }
  for (double b = std::ceil(L.b0 / step) * step; b <= L.b0 + extent; b += step) {
    const int v = L.toPixel(L.a0, b).y;
    cv::line(img, {m, v}, {m + size, v}, grid_color, 1);
    const std::string label = formatMetres(b);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, kFont, 0.4, 1, &base);
    cv::putText(img, label, {m - 6 - ts.width, v + ts.height / 2}, kFont, 0.4, text_color, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, {m, m}, {m + size, m + size}, text_color, 1);

  // Trajectories: estimates first, the ground truth on top; a circle at the common start.
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    const Points2 pts = planePoints(estimates[i].T_w_c, T_w_c_gt.front(), plane);
    drawPolyline(img, pts, L, estimateColor(i), options.line_width_px);
    cv::circle(img, L.toPixel(pts.back().x(), pts.back().y()), 4, estimateColor(i), cv::FILLED,
               cv::LINE_AA);
  }
  const Points2 gt = planePoints(T_w_c_gt, T_w_c_gt.front(), plane);
  drawPolyline(img, gt, L, groundTruthColor(), options.line_width_px);
  cv::circle(img, L.toPixel(gt.front().x(), gt.front().y()), 6, groundTruthColor(), 2, cv::LINE_AA);
  cv::circle(img, L.toPixel(gt.back().x(), gt.back().y()), 4, groundTruthColor(), cv::FILLED,
             cv::LINE_AA);

  // Scale bar (one grid step) in the lower-left corner of the plot.
  {
    const int len = static_cast<int>(std::lround(step * L.px_per_m));
    const cv::Point p0(m + 15, m + size - 18);
    const cv::Point p1(p0.x + len, p0.y);
    cv::rectangle(img, {p0.x - 6, p0.y - 30}, {p1.x + 6, p0.y + 10}, cv::Scalar(255, 255, 255),
                  cv::FILLED);
    cv::line(img, p0, p1, text_color, 3);
    cv::line(img, {p0.x, p0.y - 6}, {p0.x, p0.y + 6}, text_color, 2);
    cv::line(img, {p1.x, p1.y - 6}, {p1.x, p1.y + 6}, text_color, 2);
    cv::putText(img, formatMetres(step) + " m", {p0.x, p0.y - 12}, kFont, 0.5, text_color, 1,
                cv::LINE_AA);
  }

  // Axis labels naming the plane; the vertical one is drawn rotated.
  const bool en = plane == metrics::HorizontalPlane::kEastNorth;
  const std::string a_label = en ? "East [m]" : "x [m] (right)";
  const std::string b_label = en ? "North [m]" : "z [m] (forward)";
  {
    int base = 0;
    const cv::Size ts = cv::getTextSize(a_label, kFont, 0.6, 1, &base);
    cv::putText(img, a_label, {m + size / 2 - ts.width / 2, m + size + 45}, kFont, 0.6, text_color,
                1, cv::LINE_AA);
    const cv::Size tb = cv::getTextSize(b_label, kFont, 0.6, 1, &base);
    cv::Mat label(tb.height + base + 4, tb.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(label, b_label, {2, tb.height + 2}, kFont, 0.6, text_color, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x = 4;
    const int y = std::max(0, m + size / 2 - rotated.rows / 2);
    if (x + rotated.cols <= img.cols && y + rotated.rows <= img.rows) {
      rotated.copyTo(img(cv::Rect(x, y, rotated.cols, rotated.rows)));
    }
  }
  const std::string title =
      std::string("Top view, ") + metrics::planeName(plane) + " (equal axis scale)";
  cv::putText(img, title, {m, m - 20}, kFont, 0.7, text_color, 1, cv::LINE_AA);

  // Legend panel right of the plot.
  {
    const int x = 2 * m + size - m / 2;
    int y = m + 20;
    auto entry = [&](const std::string& name, const cv::Scalar& color) {
      cv::line(img, {x, y - 5}, {x + 30, y - 5}, color, 3, cv::LINE_AA);
      cv::putText(img, name, {x + 40, y}, kFont, 0.5, text_color, 1, cv::LINE_AA);
      y += 26;
    };
    entry("ground truth", groundTruthColor());
    for (std::size_t i = 0; i < estimates.size(); ++i) entry(estimates[i].name, estimateColor(i));
    y += 10;
    cv::circle(img, {x + 15, y - 5}, 6, groundTruthColor(), 2, cv::LINE_AA);
    cv::putText(img, "start", {x + 40, y}, kFont, 0.5, text_color, 1, cv::LINE_AA);
    y += 26;
    cv::circle(img, {x + 15, y - 5}, 4, groundTruthColor(), cv::FILLED, cv::LINE_AA);
    cv::putText(img, "end", {x + 40, y}, kFont, 0.5, text_color, 1, cv::LINE_AA);
  }
  return img;
}

Status writePng(const std::string& path, const cv::Mat& image) {
  if (image.empty()) return invalidArgument(path + ": empty image");
  std::vector<unsigned char> png;
  bool ok = false;
  try {  // OpenCV reports some failures by throwing; library code must not let that escape
    ok = cv::imencode(".png", image, png);
  } catch (const cv::Exception& e) {
    return ioError(path + ": cannot encode PNG: " + e.what());
  }
  if (!ok) return ioError(path + ": cannot encode PNG");
  return files::writeWholeFile(
      path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace sunvo::report
