#pragma once
// One stereo frame, whatever produced it (V4L2 + GPIO trigger, KITTI files, a renderer).
// Nothing downstream knows which source ran.

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "sunvo/core/time.hpp"

namespace sunvo {

struct StereoFrame {
  TimeNs trigger_time_ns = 0;  // UTC ns of the exposure trigger (or the recorded timestamp)
  std::uint64_t sequence = 0;  // frame index from the source, monotonically increasing
  cv::Mat left;                // rectified left image, CV_8UC1
  cv::Mat right;               // rectified right image, CV_8UC1
  cv::Mat left_color;          // optional rectified left colour image, CV_8UC3 (BGR); empty if none
  cv::Mat right_color;         // optional, as left_color
};

}  // namespace sunvo
