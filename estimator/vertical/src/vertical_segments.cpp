#include "sunvo/vertical/vertical_segments.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace sunvo::vertical {

Status VerticalSegmentDetector::init(int width, int height, int max_width, double min_gradient,
                                     int max_segments) {
  if (width < 8 || height < 8) {
    return invalidArgument("vertical segments: image " + std::to_string(width) + "x" +
                           std::to_string(height) + " is smaller than 8x8");
  }
  if (max_width < 8) return invalidArgument("vertical segments: max_width below 8");
  if (!(min_gradient > 0.0) || !std::isfinite(min_gradient)) {
    return invalidArgument("vertical segments: min_gradient must be positive");
  }
  if (max_segments < 1) return invalidArgument("vertical segments: max_segments below 1");
  width_ = width;
  height_ = height;
  factor_ = (width + max_width - 1) / max_width;
  ws_ = width / factor_;
  hs_ = height / factor_;
  if (ws_ < 3 || hs_ < 3) {
    return invalidArgument("vertical segments: downscaled image below 3x3 (factor " +
                           std::to_string(factor_) + ")");
  }
  min_gradient_ = min_gradient;
  max_segments_ = static_cast<std::size_t>(max_segments);
  const std::size_t pixels = static_cast<std::size_t>(ws_) * static_cast<std::size_t>(hs_);
  image_.assign(pixels, 0.0f);
  gx_.assign(pixels, 0.0f);
  gy_.assign(pixels, 0.0f);
  prev_row_.assign(static_cast<std::size_t>(ws_), -1);
  cur_row_.assign(static_cast<std::size_t>(ws_), -1);
  // At most one chain ends on each column of the row above and one starts on each column of
  // this row: 2 ws slots never run out (the count of misses is kept anyway).
  const std::size_t slots = 2 * static_cast<std::size_t>(ws_) + 2;
  chains_.assign(slots, Chain{});
  free_.clear();
  free_.reserve(slots);
  for (std::size_t i = slots; i-- > 0;) free_.push_back(static_cast<int>(i));
  active_.clear();
  active_.reserve(slots);
  still_active_.clear();
  still_active_.reserve(slots);
  return Status::ok();
}

void VerticalSegmentDetector::addPoint(Chain& c, double x, int y) const {
  // A chain has one point per row from y_first on, so a point's row is its index.
  const int i = y - c.y_first;
  if (i < kEndTrimRows) c.head[i] = x;
  c.tail[i % kEndTrimRows] = x;
  const double t = i;
  c.n += 1.0;
  c.st += t;
  c.sx += x;
  c.stt += t * t;
  c.stx += t * x;
  c.sxx += x * x;
  c.y_last = y;
}

void VerticalSegmentDetector::finish(int index, double min_length_px,
                                     std::vector<cv::Vec4f>* segments) {
  Chain& c = chains_[static_cast<std::size_t>(index)];
  ++stats_.chains;
  free_.push_back(index);
  const int rows = c.y_last - c.y_first;
  if (rows < 2 || c.n < 3.0) return;
  // Leave the end points out of the sums (header, step 5) when at least 3 remain; the segment
  // still spans the chain's rows.
  if (c.n >= 2 * kEndTrimRows + 3) {
    for (int i = 0; i < kEndTrimRows; ++i) {
      const double t_head = i, x_head = c.head[i];
      const double t_tail = rows - i, x_tail = c.tail[(rows - i) % kEndTrimRows];
      c.n -= 2.0;
      c.st -= t_head + t_tail;
      c.sx -= x_head + x_tail;
      c.stt -= t_head * t_head + t_tail * t_tail;
      c.stx -= t_head * x_head + t_tail * x_tail;
      c.sxx -= x_head * x_head + x_tail * x_tail;
    }
  }
  const double det = c.n * c.stt - c.st * c.st;
  if (!(det > 0.0)) return;
  const double b = (c.n * c.stx - c.st * c.sx) / det;
  const double a = (c.sx - b * c.st) / c.n;
  const double f = factor_;
  const double length = rows * f * std::sqrt(1.0 + b * b);
  if (!(length >= min_length_px)) return;
  // Residual sum of squares of the fit, from the sums.
  const double sxx_c = c.sxx - c.sx * c.sx / c.n;
  const double stx_c = c.stx - c.st * c.sx / c.n;
  const double rss = std::max(0.0, sxx_c - b * stx_c);
  if (!(rss <= kMaxRmsPx * kMaxRmsPx * c.n)) return;
  if (segments->size() >= max_segments_) {
    ++stats_.dropped_full;
    return;
  }
  const auto full = [f](double p) { return static_cast<float>((p + 0.5) * f - 0.5); };
  segments->emplace_back(full(a), full(c.y_first), full(a + b * rows), full(c.y_last));
  ++stats_.segments;
}

Status VerticalSegmentDetector::detect(const cv::Mat& gray, double min_length_px,
                                       std::vector<cv::Vec4f>* segments) {
  if (image_.empty()) return failedPrecondition("VerticalSegmentDetector::detect before init");
  if (gray.type() != CV_8UC1 || gray.cols != width_ || gray.rows != height_) {
    return invalidArgument("vertical segments: image must be CV_8UC1 " + std::to_string(width_) +
                           "x" + std::to_string(height_));
  }
  segments->clear();
  if (segments->capacity() < max_segments_) segments->reserve(max_segments_);
  stats_ = {};

  // 1. Box downscale by factor_ into float.
  const int f = factor_;
  const float inv_area = 1.0f / static_cast<float>(f * f);
  for (int y = 0; y < hs_; ++y) {
    float* out = &image_[static_cast<std::size_t>(y) * ws_];
    std::fill(out, out + ws_, 0.0f);
    for (int dy = 0; dy < f; ++dy) {
      const std::uint8_t* in = gray.ptr<std::uint8_t>(y * f + dy);
      for (int x = 0; x < ws_; ++x) {
        int sum = 0;
        for (int dx = 0; dx < f; ++dx) sum += in[x * f + dx];
        out[x] += static_cast<float>(sum);
      }
    }
    for (int x = 0; x < ws_; ++x) out[x] *= inv_area;
  }
  // 2. Sobel / 8 on the interior (the border stays 0 from init).
  for (int y = 1; y < hs_ - 1; ++y) {
    const float* up = &image_[static_cast<std::size_t>(y - 1) * ws_];
    const float* mid = up + ws_;
    const float* down = mid + ws_;
    float* gx = &gx_[static_cast<std::size_t>(y) * ws_];
    float* gy = &gy_[static_cast<std::size_t>(y) * ws_];
    for (int x = 1; x < ws_ - 1; ++x) {
      gx[x] = 0.125f * ((up[x + 1] + 2.0f * mid[x + 1] + down[x + 1]) -
                        (up[x - 1] + 2.0f * mid[x - 1] + down[x - 1]));
      gy[x] = 0.125f * ((down[x - 1] + 2.0f * down[x] + down[x + 1]) -
                        (up[x - 1] + 2.0f * up[x] + up[x + 1]));
    }
  }
  // 3-4. Edgels, chained row by row.
  const float tan_lean = static_cast<float>(std::tan(kMaxLeanDeg * std::numbers::pi / 180.0));
  const float min_g = static_cast<float>(min_gradient_);
  std::fill(prev_row_.begin(), prev_row_.end(), -1);
  active_.clear();
  for (int y = 1; y < hs_ - 1; ++y) {
    std::fill(cur_row_.begin(), cur_row_.end(), -1);
    const float* gx = &gx_[static_cast<std::size_t>(y) * ws_];
    const float* gy = &gy_[static_cast<std::size_t>(y) * ws_];
    for (int x = 2; x < ws_ - 2; ++x) {
      const float m0 = std::abs(gx[x]);
      if (m0 < min_g || std::abs(gy[x]) > m0 * tan_lean) continue;
      const float ml = std::abs(gx[x - 1]), mr = std::abs(gx[x + 1]);
      if (m0 < ml || m0 <= mr) continue;
      ++stats_.edgels;
      const int sign = gx[x] > 0.0f ? 1 : -1;
      const float curvature = ml - 2.0f * m0 + mr;
      double xs = x;
      if (curvature < 0.0f)
        xs += std::clamp(0.5 * static_cast<double>((ml - mr) / curvature), -0.5, 0.5);
      int c = -1;
      for (const int dx : {0, -1, 1}) {
        const int k = prev_row_[static_cast<std::size_t>(x + dx)];
        if (k < 0) continue;
        const Chain& ch = chains_[static_cast<std::size_t>(k)];
        if (ch.sign == sign && ch.y_last == y - 1 && !ch.ended) {
          c = k;
          break;
        }
      }
      if (c >= 0) {
        const Chain& ch = chains_[static_cast<std::size_t>(c)];
        if (ch.n >= kMinFitPoints) {
          const double det = ch.n * ch.stt - ch.st * ch.st;
          const double b = det > 0.0 ? (ch.n * ch.stx - ch.st * ch.sx) / det : 0.0;
          const double a = (ch.sx - b * ch.st) / ch.n;
          if (std::abs(xs - (a + b * (y - ch.y_first))) > kMaxStepResidualPx) {
            // Ends on the row above; taken off the active list when this row is done.
            chains_[static_cast<std::size_t>(c)].ended = true;
            c = -1;
          }
        }
      }
      if (c < 0) {
        if (free_.empty()) {
          ++stats_.chains_full;
          continue;
        }
        c = free_.back();
        free_.pop_back();
        Chain& ch = chains_[static_cast<std::size_t>(c)];
        ch = Chain{};
        ch.y_first = y;
        ch.sign = sign;
        active_.push_back(c);
      }
      addPoint(chains_[static_cast<std::size_t>(c)], xs, y);
      cur_row_[static_cast<std::size_t>(x)] = c;
    }
    // 5. Chains with no point on this row end.
    still_active_.clear();
    for (const int k : active_) {
      if (chains_[static_cast<std::size_t>(k)].y_last == y) {
        still_active_.push_back(k);
      } else {
        finish(k, min_length_px, segments);
      }
    }
    active_.swap(still_active_);
    prev_row_.swap(cur_row_);
  }
  for (const int k : active_) finish(k, min_length_px, segments);
  active_.clear();
  return Status::ok();
}

}  // namespace sunvo::vertical
