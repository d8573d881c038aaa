#pragma once
// Top-view trajectory plot drawn with OpenCV: the ground truth (black) and each estimate in its
// own colour, a legend, a metric grid with a scale bar, one scale for both axes, and axis labels
// naming the plane ("East [m]" / "North [m]", or "x [m] (right)" / "z [m] (forward)").
//
// The horizontal axis is the plane's a-axis (East or camera x), growing to the right; the
// vertical axis is its b-axis (North or camera z), growing upwards. For the camera x-z plane this
// is the view from above (looking along +y, which points down), right-handed on screen.
// Estimates are drawn re-anchored on the ground truth's first pose, exactly as Table 1 compares
// them: T'_est,k = T_gt,0 T_est,0^-1 T_est,k.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/metrics/metrics.hpp"

namespace sunvo::report {

struct PlotOptions {
  int plot_size_px = 900;     // side of the square plotting area [px], 200..8000
  int margin_px = 70;         // margin around the plotting area for tick labels [px], 30..500
  int legend_width_px = 260;  // width of the legend panel right of the plot [px], 100..2000
  int line_width_px = 2;      // trajectory line width [px], 1..20
  Status validate() const;
};

struct PlotSeries {
  std::string name;
  std::vector<Isometry3> T_w_c;
};

// Maps plane coordinates (a, b) [m] to pixels: u = u0 + (a - a0) * px_per_m,
// v = v0 - (b - b0) * px_per_m (one scale for both axes).
struct TopViewLayout {
  double px_per_m = 1.0;
  double a0 = 0.0;  // plane coordinate at the plot's lower-left corner [m]
  double b0 = 0.0;
  double u0 = 0.0;  // pixel of that corner
  double v0 = 0.0;
  double grid_step_m = 1.0;  // grid spacing (1, 2 or 5 × 10^n m)
  cv::Point toPixel(double a, double b) const;
};

// The layout that fits every point of every series (ground truth and re-anchored estimates).
TopViewLayout computeTopViewLayout(const std::vector<Isometry3>& T_w_c_gt,
                                   const std::vector<PlotSeries>& estimates,
                                   metrics::HorizontalPlane plane, const PlotOptions& options);

// Colours (BGR): ground truth, then estimate i uses estimateColor(i).
cv::Scalar groundTruthColor();
cv::Scalar estimateColor(std::size_t i);

// Renders the plot (CV_8UC3). Fails on invalid options, an empty ground truth, or a series whose
// first pose cannot anchor it (empty).
Expected<cv::Mat> renderTopView(const std::vector<Isometry3>& T_w_c_gt,
                                const std::vector<PlotSeries>& estimates,
                                metrics::HorizontalPlane plane, const PlotOptions& options = {});

// Writes an image as PNG; kIoError names the path when OpenCV cannot write it.
Status writePng(const std::string& path, const cv::Mat& image);

}  // namespace sunvo::report
