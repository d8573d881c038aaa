#pragma once
// Near-vertical straight edges of a gray image, found with no heap allocation after init(): the
// vertical cue's own segment detector. It looks only for what the cue uses (edges within
// kMaxLeanDeg of the image's columns), in one pass over a downscaled copy; OpenCV's general line
// segment detector, which it replaced as the default, allocates about 40 times per call
// (docs/vertical.md).
//
// 1. Downscale: the image is box-averaged by the smallest integer factor f that brings it to at
//    most max_width columns (float, so no rounding).
// 2. Gradient: Sobel / 8, i.e. gray levels per pixel across a ramp.
// 3. Edgels: pixels where |gx| >= min_gradient, the gradient is within kMaxLeanDeg of the row
//    (|gy| <= |gx| tan kMaxLeanDeg), and |gx| is a maximum along the row (>= left, > right).
//    The edge's column is refined to a fraction of a pixel by a parabola through |gx| at
//    x - 1, x, x + 1.
// 4. Chains, row by row from the top: an edgel extends the chain that had a point on the row
//    above at column x, x - 1 or x + 1 (in that order) with the same sign of gx. A chain is a
//    running least-squares fit of x = a + b y; once it has kMinFitPoints points, an edgel more
//    than kMaxStepResidualPx from its line ends it and starts a new one (a corner, a branch).
//    A chain with no edgel on a row ends.
// 5. An ended chain becomes a segment when it is at least min_length_px long (full-resolution
//    pixels) and its points' RMS distance from the line is at most kMaxRmsPx: its fitted line
//    between its first and last rows, in full-resolution pixel coordinates (pixel centres are
//    integers, so small pixel p is full pixel (p + 0.5) f - 0.5). The line is fitted without the
//    chain's first and last kEndTrimRows points: an edge ends where it meets another (a window's
//    corner, a roof line), and its end edgels are pulled toward that edge; in perspective the
//    pull differs at the two ends, and on short segments it tilted the fit enough to put a
//    +0.03 ... +0.05 deg pitch bias on the up (docs/vertical_ends.md).

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sunvo/core/status.hpp"

namespace sunvo::vertical {

struct VerticalSegmentStats {
  int edgels = 0;        // edge pixels found
  int chains = 0;        // chains ended
  int segments = 0;      // segments returned
  int dropped_full = 0;  // segments beyond the output's capacity (not returned)
  int chains_full = 0;   // edgels not chained: every chain slot busy
};

class VerticalSegmentDetector {
 public:
  static constexpr double kMaxLeanDeg = 40.0;        // edge direction from the image's columns
  static constexpr int kMinFitPoints = 8;            // points before a chain's line is trusted
  static constexpr double kMaxStepResidualPx = 1.0;  // small-image px: a farther edgel ends it
  static constexpr double kMaxRmsPx = 0.5;           // small-image px: straightness of a segment
  static constexpr int kEndTrimRows = 1;             // points left out of the fit at each end

  // width, height: the full-resolution image; max_width: columns after downscaling (>= 8);
  // min_gradient: gray levels per pixel (> 0); max_segments: output capacity. Allocates.
  Status init(int width, int height, int max_width, double min_gradient, int max_segments);

  // gray: CV_8UC1 of the init size. segments: cleared, then filled with at most max_segments
  // segments (x0, y0, x1, y1) in full-resolution pixels, y0 < y1; the rest are counted in
  // stats().dropped_full. Reserved to max_segments on the first call if smaller; no allocation
  // after that.
  Status detect(const cv::Mat& gray, double min_length_px, std::vector<cv::Vec4f>* segments);

  const VerticalSegmentStats& stats() const { return stats_; }
  int factor() const { return factor_; }

 private:
  struct Chain {
    // Sums of the points (x, t) with t = y - y_first, for the fit x = a + b t.
    double n = 0, st = 0, sx = 0, stt = 0, stx = 0, sxx = 0;
    int y_first = 0, y_last = 0;
    int sign = 0;
    bool ended = false;  // an edgel off its line ended it (it takes no more points)
    // x of its first kEndTrimRows points, and of its last ones (a ring indexed by row).
    double head[kEndTrimRows] = {};
    double tail[kEndTrimRows] = {};
  };
  void addPoint(Chain& c, double x, int y) const;
  // Ends chain `index`: appends its segment when it qualifies, frees its slot.
  void finish(int index, double min_length_px, std::vector<cv::Vec4f>* segments);

  int width_ = 0, height_ = 0;  // full resolution
  int factor_ = 1;
  int ws_ = 0, hs_ = 0;  // downscaled
  double min_gradient_ = 0.0;
  std::size_t max_segments_ = 0;
  std::vector<float> image_, gx_, gy_;
  std::vector<int> prev_row_, cur_row_;  // chain index per column, -1 none
  std::vector<Chain> chains_;
  std::vector<int> free_, active_, still_active_;
  VerticalSegmentStats stats_;
};

}  // namespace sunvo::vertical
