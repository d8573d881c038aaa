#include "histogram.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace sunvo::suneval {

cv::Mat drawErrorHistogram(const std::vector<double>& values_deg, double lo_deg, double hi_deg,
                           double bin_deg, const std::string& title) {
  constexpr int kW = 640, kH = 360, kLeft = 50, kRight = 20, kTop = 40, kBottom = 40;
  cv::Mat img(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  const int bins = std::max(1, static_cast<int>(std::lround((hi_deg - lo_deg) / bin_deg)));
  std::vector<int> counts(static_cast<std::size_t>(bins), 0);
  for (double v : values_deg) {
    if (!std::isfinite(v)) continue;
    const int b = std::clamp(static_cast<int>(std::floor((v - lo_deg) / bin_deg)), 0, bins - 1);
    ++counts[static_cast<std::size_t>(b)];
  }
  const int max_count = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const double plot_w = kW - kLeft - kRight, plot_h = kH - kTop - kBottom;
  auto xOf = [&](double deg) { return kLeft + (deg - lo_deg) / (hi_deg - lo_deg) * plot_w; };
  for (int b = 0; b < bins; ++b) {
    const double h = plot_h * counts[static_cast<std::size_t>(b)] / max_count;
    const cv::Point2d p0(xOf(lo_deg + b * bin_deg) + 1, kTop + plot_h - h);
    const cv::Point2d p1(xOf(lo_deg + (b + 1) * bin_deg) - 1, kTop + plot_h);
    if (h > 0.0) cv::rectangle(img, p0, p1, cv::Scalar(180, 110, 40), cv::FILLED);
  }
  const cv::Scalar black(0, 0, 0), grey(160, 160, 160);
  cv::line(img, cv::Point(kLeft, kTop + static_cast<int>(plot_h)),
           cv::Point(kW - kRight, kTop + static_cast<int>(plot_h)), black, 1);
  cv::line(img, cv::Point(kLeft, kTop), cv::Point(kLeft, kTop + static_cast<int>(plot_h)), black,
           1);
  for (double t = std::ceil(lo_deg / 45.0) * 45.0; t <= hi_deg + 1e-9; t += 45.0) {
    const int x = static_cast<int>(std::lround(xOf(t)));
    cv::line(img, cv::Point(x, kTop + static_cast<int>(plot_h)),
             cv::Point(x, kTop + static_cast<int>(plot_h) + 5), black, 1);
    if (std::abs(t) < 1e-9)
      cv::line(img, cv::Point(x, kTop), cv::Point(x, kTop + static_cast<int>(plot_h)), grey, 1);
    cv::putText(img, std::to_string(static_cast<int>(t)), cv::Point(x - 12, kH - 18),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, black, 1, cv::LINE_AA);
  }
  cv::putText(img, std::to_string(max_count), cv::Point(8, kTop + 10), cv::FONT_HERSHEY_SIMPLEX,
              0.4, black, 1, cv::LINE_AA);
  cv::putText(img, "0", cv::Point(30, kTop + static_cast<int>(plot_h)), cv::FONT_HERSHEY_SIMPLEX,
              0.4, black, 1, cv::LINE_AA);
  cv::putText(img, title + "  (n = " + std::to_string(values_deg.size()) + ")",
              cv::Point(kLeft, 24), cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
  cv::putText(img, "error, deg", cv::Point(kW - kRight - 70, kH - 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              black, 1, cv::LINE_AA);
  return img;
}

}  // namespace sunvo::suneval
