#include <algorithm>
#include <array>
#include <cstring>

#include "frontend_kernels.hpp"
#include "sunvo/frontend/stereo_frontend.hpp"

// Detection: smoothing, gradients, responses, non-maximum suppression, descriptors, grid index.

namespace sunvo {
using namespace frontend_detail;  // NOLINT: the private kernels of this folder

// Binomial 3x3 smoothing, [1 2 1]^T [1 2 1] / 16 rounded, before gradients and responses: the
// Sobel of the smoothed image is a 5x5 derivative filter, less sensitive to aliasing and to the
// sub-pixel position of the sampling grid than the bare 3x3 Sobel. The outer ring copies the input.
void StereoFrontend::smooth(const cv::Mat& img) {
  const int w = img.cols;
  const int h = img.rows;
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = smooth_.data() + static_cast<std::ptrdiff_t>(y) * stride_;
    const std::uint8_t* p0 = img.ptr<std::uint8_t>(y);
    if (y == 0 || y == h - 1) {
      std::memcpy(out, p0, static_cast<std::size_t>(w));
      continue;
    }
    smoothRow(img.ptr<std::uint8_t>(y - 1), p0, img.ptr<std::uint8_t>(y + 1), out, w);
    out[0] = p0[0];
    out[w - 1] = p0[w - 1];
  }
}

// Sobel 3x3: gx = [-1 0 1; -2 0 2; -1 0 1] * I, gy its transpose, each in [-1020, 1020];
// stored as clamp(g / 2 + 128, 0, 255) (arithmetic shift, i.e. floor) so that a descriptor
// sample is one byte and SAD runs on bytes. The outermost row/column stays 128 (zero gradient).
void StereoFrontend::computeGradients(const cv::Mat& img, int img_index) {
  const int w = img.cols;
  const int h = img.rows;
  std::uint8_t* gx = gx_[static_cast<std::size_t>(img_index)].data();
  std::uint8_t* gy = gy_[static_cast<std::size_t>(img_index)].data();
  for (int y = 1; y + 1 < h; ++y) {
    const std::uint8_t* pm = img.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* p0 = img.ptr<std::uint8_t>(y);
    const std::uint8_t* pp = img.ptr<std::uint8_t>(y + 1);
    gradientRow(pm, p0, pp, gx + static_cast<std::ptrdiff_t>(y) * stride_,
                gy + static_cast<std::ptrdiff_t>(y) * stride_, w);
  }
}

// Two small masks on the image, for pixels at least 2 px inside:
//  blob   B = 8 I(x,y) - sum of the 8 pixels at (x +- 2 | x, y +- 2 | y)   in [-2040, 2040]
//         (a centre-minus-ring Laplacian: extremal on bright / dark spots);
//  corner C = I(x-2,y-2) + I(x+2,y+2) - I(x+2,y-2) - I(x-2,y+2)
//         + 2 (I(x-1,y-1) + I(x+1,y+1) - I(x+1,y-1) - I(x-1,y+1))           in [-1530, 1530]
//         (a saddle mask: extremal where one diagonal pair of quadrants differs from the other,
//         i.e. at corners).
void StereoFrontend::computeResponses(const cv::Mat& img) {
  const int w = img.cols;
  const int h = img.rows;
  for (int y = 2; y + 2 < h; ++y) {
    responseRow(img.ptr<std::uint8_t>(y - 2), img.ptr<std::uint8_t>(y - 1),
                img.ptr<std::uint8_t>(y), img.ptr<std::uint8_t>(y + 1),
                img.ptr<std::uint8_t>(y + 2),
                blob_.data() + static_cast<std::ptrdiff_t>(y) * stride_,
                corner_.data() + static_cast<std::ptrdiff_t>(y) * stride_, w);
  }
}

void StereoFrontend::describeAt(int img_index, int u, int v, std::uint8_t* d) const {
  const std::uint8_t* gx = gx_[static_cast<std::size_t>(img_index)].data();
  const std::uint8_t* gy = gy_[static_cast<std::size_t>(img_index)].data();
  int k = 0;
  for (int oy : kGrid) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(v + oy) * stride_ + u;
    for (int ox : kGrid) {
      d[k] = gx[row + ox];
      d[k + 16] = gy[row + ox];
      ++k;
    }
  }
}

// Non-maximum suppression with a separable (2n+1)^2 max/min filter: a horizontal running max
// per row (flat doubling passes over the strip, windowMaxMin), then per candidate row the max over
// the 2n+1 rows of it around, fused with the flag test (windowFlags: nothing of the vertical pass
// is stored); likewise the min. A pixel is a candidate when r == M and |r| >= threshold. Equal
// values in one window (plateaus) are resolved exactly afterwards: the earliest pixel in
// row-major order wins, so exactly one pixel of a plateau survives. All loops are simple passes
// over rows that the compiler vectorises. (Measured and not kept: checking only the horizontal
// extrema against the other rows, a sparse read of about 7 % of the pixels, was slower than the
// vertical pass; so were a direct (2n+1)-tap horizontal max and row-by-row doubling.)
void StereoFrontend::detect(const cv::Mat& img_in, int img_index, CandidateSet& set) {
  smooth(img_in);
  const cv::Mat img(img_in.rows, img_in.cols, CV_8UC1, smooth_.data(),
                    static_cast<std::size_t>(stride_));  // a header on smooth_, no allocation
  computeGradients(img, img_index);
  computeResponses(img);
  const int w = img.cols;
  const int h = img.rows;
  const int n = options_.nms_radius;
  const int b = border_;
  set.count = 0;
  set.truncated = false;
  set.width = w;
  set.height = h;
  const std::int16_t* responses[2] = {blob_.data(), corner_.data()};
  const int thresholds[2] = {options_.blob_threshold, options_.corner_threshold};

  // true if no pixel of the window beats r(x, y) (sign +1: max, -1: min) or equals it earlier.
  // Called where r(x, y) equals the window max (or min), i.e. nothing in the window beats it;
  // true unless an equal value comes earlier in row-major order: in one of the n rows above
  // (2n+1 pixels each) or left of it in its own row (n pixels), 8 pixels per compare.
  auto isFirstExtremum = [&](const std::int16_t* r, int x, int y) {
    const std::int16_t c = r[static_cast<std::ptrdiff_t>(y) * stride_ + x];
    for (int yy = y - n; yy <= y; ++yy) {
      const std::int16_t* row = r + static_cast<std::ptrdiff_t>(yy) * stride_ + x - n;
      const int len = yy < y ? 2 * n + 1 : n;
      for (int k = 0; k < len; k += 8) {
        if (anyEqual8(row + k, std::min(8, len - k), c)) return false;
      }
    }
    return true;
  };

  const int x0 = b;
  const int x1 = w - b;  // exclusive
  std::uint8_t* flags = flag_row_.data();
  const std::array<std::int16_t*, 4> tmp = {nms_a_.data(), nms_b_.data(), nms_c_.data(),
                                            nms_d_.data()};
  // Candidate rows b .. h-b-1 in strips of kNmsStrip rows, so that the filter passes of a strip
  // (rows ys-n .. ye+n-1) stay in cache; within a strip type 0 then type 1, each row-major.
  for (int ys = b; ys < h - b; ys += kNmsStrip) {
    const int ye = std::min(ys + kNmsStrip, h - b);
    const std::ptrdiff_t first = static_cast<std::ptrdiff_t>(ys - n) * stride_;
    const std::ptrdiff_t total = static_cast<std::ptrdiff_t>(ye - ys + 2 * n) * stride_;
    for (int type = 0; type < 2; ++type) {
      const std::int16_t* r = responses[type];
      // Horizontal (2n+1) max and min of the strip's rows and their n-row margins; the
      // vertical max/min over 2n+1 of those rows is taken per row inside windowFlags().
      // The NMS buffers hold one strip: their row 0 is image row ys - n.
      windowMaxMin(r + first, r + first, nms_hmax_.data(), nms_hmin_.data(), tmp, 1, n, total);
      const int thr = thresholds[type];
      const auto pos_thr = static_cast<std::int16_t>(thr);
      const auto neg_thr = static_cast<std::int16_t>(-thr);
      for (int y = ys; y < ye; ++y) {
        const std::ptrdiff_t off = static_cast<std::ptrdiff_t>(y) * stride_;
        const std::int16_t* row = r + off;
        const std::ptrdiff_t strip_off = off - first;
        windowFlags(row, nms_hmax_.data() + strip_off, nms_hmin_.data() + strip_off, stride_, n,
                    pos_thr, neg_thr, flags, x0, x1);
        std::memset(flags + x1, 0, 8);  // so that the last 8-byte word reads no stale flags
        // Visit the non-zero flag bytes, 8 at a time (little-endian: byte i = bits 8i .. 8i+7).
        // (Skipping 32-byte blocks without a flag first was measured: no gain.)
        for (int xw = x0; xw < x1; xw += 8) {
          std::uint64_t word = 0;
          std::memcpy(&word, flags + xw, sizeof(word));
          while (word != 0) {
            const int byte = std::countr_zero(word) / 8;
            word &= ~(std::uint64_t{0xFF} << (8 * byte));
            const int x = xw + byte;
            const int f = flags[x];
            for (int sign = 1; sign >= -1; sign -= 2) {
              if ((f & (sign > 0 ? 1 : 2)) == 0) continue;
              if (!isFirstExtremum(r, x, y)) continue;
              if (set.count >= options_.max_candidates) {
                set.truncated = true;
                continue;
              }
              Keypoint& kp = set.kp[static_cast<std::size_t>(set.count)];
              kp.u = static_cast<std::int16_t>(x);
              kp.v = static_cast<std::int16_t>(y);
              kp.cls = static_cast<std::uint8_t>(2 * type + (sign > 0 ? 0 : 1));
              kp.strength = sign * row[x];
              kp.du = parabolaPeak(row[x - 1], row[x], row[x + 1]);
              kp.dv = parabolaPeak(row[x - stride_], row[x], row[x + stride_]);
              describeAt(
                  img_index, x, y,
                  set.desc.data() + static_cast<std::ptrdiff_t>(set.count) * kDescriptorBytes);
              ++set.count;
            }
          }
        }
      }
    }
  }
  buildIndex(set);
}

// Counting sort of the candidates into grid cells per class.
void StereoFrontend::buildIndex(CandidateSet& set) {
  set.cells_x = (set.width + kCell - 1) / kCell;
  set.cells_y = (set.height + kCell - 1) / kCell;
  const int cells = kClasses * set.cells_x * set.cells_y;
  std::fill(set.cell_start.begin(), set.cell_start.begin() + cells + 1, 0);
  auto cellOf = [&](const Keypoint& kp) {
    return (kp.cls * set.cells_y + kp.v / kCell) * set.cells_x + kp.u / kCell;
  };
  for (int i = 0; i < set.count; ++i) {
    ++set.cell_start[static_cast<std::size_t>(cellOf(set.kp[static_cast<std::size_t>(i)]) + 1)];
  }
  for (int c = 0; c < cells; ++c) {
    set.cell_start[static_cast<std::size_t>(c + 1)] += set.cell_start[static_cast<std::size_t>(c)];
  }
  // After the prefix sum cell_start[c + 1] is the end of cell c; walking backwards and
  // decrementing it places each candidate and leaves cell_start[c + 1] at the start of cell c.
  for (int i = set.count - 1; i >= 0; --i) {
    const int c = cellOf(set.kp[static_cast<std::size_t>(i)]);
    const int pos = --set.cell_start[static_cast<std::size_t>(c + 1)];
    set.order[static_cast<std::size_t>(pos)] = i;
  }
  // Now cell_start[c + 1] holds the start of cell c; shift down by one.
  for (int c = 0; c < cells; ++c) {
    set.cell_start[static_cast<std::size_t>(c)] = set.cell_start[static_cast<std::size_t>(c + 1)];
  }
  set.cell_start[static_cast<std::size_t>(cells)] = set.count;
  // Reorder keypoints and descriptors into cell order, so that a window search reads contiguous
  // memory; candidate indices are cell-ordered from here on.
  for (int k = 0; k < set.count; ++k) {
    const auto from = static_cast<std::size_t>(set.order[static_cast<std::size_t>(k)]);
    set.kp_sorted[static_cast<std::size_t>(k)] = set.kp[from];
    std::memcpy(set.desc_sorted.data() + static_cast<std::size_t>(k) * kDescriptorBytes,
                set.desc.data() + from * kDescriptorBytes, kDescriptorBytes);
  }
  std::swap(set.kp, set.kp_sorted);
  std::swap(set.desc, set.desc_sorted);
}

}  // namespace sunvo
