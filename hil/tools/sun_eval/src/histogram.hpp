#pragma once
// Error histogram PNGs in the style of Clement et al.'s Fig. 2 (counts per bin, OpenCV drawing).

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

namespace sunvo::suneval {

// Bars of `bin_deg` from lo_deg to hi_deg (values outside go to the end bins), with a zero line,
// axis ticks every 45 deg, the title and the count of values. CV_8UC3, 640 x 360.
cv::Mat drawErrorHistogram(const std::vector<double>& values_deg, double lo_deg, double hi_deg,
                           double bin_deg, const std::string& title);

}  // namespace sunvo::suneval
