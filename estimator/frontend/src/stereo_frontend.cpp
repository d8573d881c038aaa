#include "sunvo/frontend/stereo_frontend.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#endif

namespace sunvo {
namespace {

static_assert(std::endian::native == std::endian::little,
              "detect() reads flag bytes as little-endian 64-bit words");

// CPU time of the calling thread (POSIX), ns; the stages are single-threaded.
std::int64_t threadCpuNs() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Status badKey(const char* key, const std::string& what) {
  return invalidArgument(std::string("frontend option '") + key + "': " + what);
}

// Sum of absolute differences of two 32-byte descriptors.
inline int sad32(const std::uint8_t* a, const std::uint8_t* b) {
#if defined(__SSE2__)
  const __m128i a0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a));
  const __m128i a1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + 16));
  const __m128i b0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b));
  const __m128i b1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + 16));
  // psadbw leaves two 16-bit partial sums, in the low and the high 64-bit lane.
  const __m128i s = _mm_add_epi64(_mm_sad_epu8(a0, b0), _mm_sad_epu8(a1, b1));
  return _mm_cvtsi128_si32(_mm_add_epi64(s, _mm_unpackhi_epi64(s, s)));
#elif defined(__ARM_NEON) && defined(__aarch64__)
  // |a - b| per byte (vabdq_u8); vpaddlq_u8 adds neighbouring bytes into eight 16-bit lanes and
  // vpadalq_u8 adds the second half's pairs on top (at most 4 x 255 per lane); vaddvq_u16 sums
  // the lanes (at most 32 x 255 = 8160 < 2^16, so no lane or the total overflows).
  const uint8x16_t d0 = vabdq_u8(vld1q_u8(a), vld1q_u8(b));
  const uint8x16_t d1 = vabdq_u8(vld1q_u8(a + 16), vld1q_u8(b + 16));
  return static_cast<int>(vaddvq_u16(vpadalq_u8(vpaddlq_u8(d0), d1)));
#else
  int s = 0;
  for (int i = 0; i < StereoFrontend::kDescriptorBytes; ++i) s += std::abs(int{a[i]} - int{b[i]});
  return s;
#endif
}

// Descriptor sample offsets: a 4x4 grid spanning 13x13 px around the keypoint.
constexpr std::array<int, 4> kGrid = {-6, -2, 2, 6};
constexpr int kDescriptorReach = 6;  // px, largest |offset|

// Vertex offset of a parabola through (-1, rm), (0, r0), (1, rp):
// r(x) = a x^2 + b x + c with a = (rm + rp)/2 - r0, b = (rp - rm)/2; extremum at -b/(2a)
// = (rm - rp) / (2 (rm - 2 r0 + rp)). Clamped to the pixel it belongs to.
float parabolaPeak(std::int64_t rm, std::int64_t r0, std::int64_t rp) {
  const std::int64_t den = rm - 2 * r0 + rp;
  if (den == 0) return 0.0F;
  const float d = 0.5F * static_cast<float>(rm - rp) / static_cast<float>(den);
  return std::clamp(d, -0.5F, 0.5F);
}

// Sum of squared differences of n bytes.
inline std::int64_t rowSsd(const std::uint8_t* __restrict a, const std::uint8_t* __restrict b,
                           int n) {
  int sum = 0;  // n <= 17 samples of at most 255^2: fits in int
  for (int i = 0; i < n; ++i) {
    const int d = int{a[i]} - int{b[i]};
    sum += d * d;
  }
  return sum;
}

// out_max[i] = max(a[i], b[i]), out_min[i] = min(c[i], d[i]) for i in [0, count). Inputs may
// overlap each other (they are only read). noinline: the restrict qualifiers, and with them
// vectorisation without alias checks, survive only on parameters.
[[gnu::noinline]] void maxMinOf(const std::int16_t* __restrict a, const std::int16_t* __restrict b,
                                const std::int16_t* __restrict c, const std::int16_t* __restrict d,
                                std::int16_t* __restrict out_max, std::int16_t* __restrict out_min,
                                std::ptrdiff_t count) {
  for (std::ptrdiff_t i = 0; i < count; ++i) {
    out_max[i] = std::max(a[i], b[i]);
    out_min[i] = std::min(c[i], d[i]);
  }
}

// Running max and min over L = 2n+1 samples spaced `step` apart in flat arrays of `total`
// elements: out_max[i] = max over in_max[i + k step], out_min[i] = min over in_min[i + k step],
// k = -n .. n, for every i whose window lies inside the array. By doubling: M_1 = in,
// M_2j[i] = op(M_j[i], M_j[i + j step]) covers 2j samples; with p the largest power of two <= L,
// op(M_p[i - n step], M_p[i - n step + (L - p) step]) covers exactly [i - n step, i + n step]:
// log2(p) + 1 flat passes instead of 2n. Rows wrap in the flat array (step 1); the caller only
// reads outputs whose window lies in one row. tmp: four scratch arrays of `total` elements.
void windowMaxMin(const std::int16_t* in_max, const std::int16_t* in_min, std::int16_t* out_max,
                  std::int16_t* out_min, std::array<std::int16_t*, 4> tmp, std::ptrdiff_t step,
                  int n, std::ptrdiff_t total) {
  const int L = 2 * n + 1;
  const std::int16_t* cur_max = in_max;
  const std::int16_t* cur_min = in_min;
  int level = 0;
  int span = 1;  // cur[i] covers samples i .. i + (span - 1) step
  while (2 * span <= L) {
    std::int16_t* dst_max = tmp[static_cast<std::size_t>(2 * (level % 2))];
    std::int16_t* dst_min = tmp[static_cast<std::size_t>(2 * (level % 2) + 1)];
    maxMinOf(cur_max, cur_max + span * step, cur_min, cur_min + span * step, dst_max, dst_min,
             total - (2 * span - 1) * step);
    cur_max = dst_max;
    cur_min = dst_min;
    ++level;
    span *= 2;
  }
  maxMinOf(cur_max, cur_max + (L - span) * step, cur_min, cur_min + (L - span) * step,
           out_max + n * step, out_min + n * step, total - (L - 1) * step);
}

// One row of the binomial smoothing (see smooth()), x in [1, w-1).
[[gnu::noinline]] void smoothRow(const std::uint8_t* __restrict pm,
                                 const std::uint8_t* __restrict p0,
                                 const std::uint8_t* __restrict pp, std::uint8_t* __restrict out,
                                 int w) {
  for (int x = 1; x + 1 < w; ++x) {
    const int c = 4 * p0[x] + 2 * (p0[x - 1] + p0[x + 1] + pm[x] + pp[x]) + pm[x - 1] + pm[x + 1] +
                  pp[x - 1] + pp[x + 1];
    out[x] = static_cast<std::uint8_t>((c + 8) >> 4);
  }
}

// One row of the blob and corner responses (see computeResponses); restrict-qualified
// parameters let the compiler vectorise without alias checks.
[[gnu::noinline]] void responseRow(const std::uint8_t* __restrict m2,
                                   const std::uint8_t* __restrict m1,
                                   const std::uint8_t* __restrict p0,
                                   const std::uint8_t* __restrict p1,
                                   const std::uint8_t* __restrict p2, std::int16_t* __restrict ob,
                                   std::int16_t* __restrict oc, int w) {
  for (int x = 2; x + 2 < w; ++x) {
    const int ring =
        m2[x - 2] + m2[x] + m2[x + 2] + p0[x - 2] + p0[x + 2] + p2[x - 2] + p2[x] + p2[x + 2];
    ob[x] = static_cast<std::int16_t>(8 * p0[x] - ring);
    const int outer = m2[x - 2] + p2[x + 2] - m2[x + 2] - p2[x - 2];
    const int inner = m1[x - 1] + p1[x + 1] - m1[x + 1] - p1[x - 1];
    oc[x] = static_cast<std::int16_t>(outer + 2 * inner);
  }
}

}  // namespace

Status FrontendOptions::validate() const {
  if (max_width < 32 || max_width > 8192) return badKey("max_width", "must be in [32, 8192] px");
  if (max_height < 32 || max_height > 8192) {
    return badKey("max_height", "must be in [32, 8192] px");
  }
  if (nms_radius < 1 || nms_radius > 8) return badKey("nms_radius", "must be in [1, 8] px");
  if (blob_threshold < 1 || blob_threshold > 2040) {
    return badKey("blob_threshold", "must be in [1, 2040]");
  }
  if (corner_threshold < 1 || corner_threshold > 1530) {
    return badKey("corner_threshold", "must be in [1, 1530]");
  }
  if (max_candidates < 64 || max_candidates > (1 << 20)) {
    return badKey("max_candidates", "must be in [64, 1048576]");
  }
  if (max_features < 16 || max_features > (1 << 20)) {
    return badKey("max_features", "must be in [16, 1048576]");
  }
  if (bucket_width < 8 || bucket_width > 1024) {
    return badKey("bucket_width", "must be in [8, 1024] px");
  }
  if (bucket_height < 8 || bucket_height > 1024) {
    return badKey("bucket_height", "must be in [8, 1024] px");
  }
  if (max_per_bucket < 1 || max_per_bucket > 1000) {
    return badKey("max_per_bucket", "must be in [1, 1000]");
  }
  if (!(min_disparity >= 0.0) || !(min_disparity < max_disparity)) {
    return badKey("min_disparity", "must be in [0, max_disparity) px");
  }
  if (!(max_disparity < static_cast<double>(max_width))) {
    return badKey("max_disparity", "must be in (min_disparity, max_width) px");
  }
  if (stereo_row_tolerance < 0 || stereo_row_tolerance > 4) {
    return badKey("stereo_row_tolerance", "must be in [0, 4] px");
  }
  if (search_radius < 4 || search_radius > 1000) {
    return badKey("search_radius", "must be in [4, 1000] px");
  }
  if (predicted_search_radius < 4 || predicted_search_radius > search_radius) {
    return badKey("predicted_search_radius", "must be in [4, search_radius] px");
  }
  if (max_sad < 1 || max_sad > 255 * StereoFrontend::kDescriptorBytes) {
    return badKey("max_sad", "must be in [1, 8160]");
  }
  if (!(circular_tolerance_px >= 0.0) || !(circular_tolerance_px <= 100.0)) {
    return badKey("circular_tolerance_px", "must be in [0, 100] px");
  }
  if (lr_tolerance < 0 || lr_tolerance > 10) return badKey("lr_tolerance", "must be in [0, 10] px");
  return Status::ok();
}

Status StereoFrontend::init(const FrontendOptions& options, const StereoCamera& camera) {
  initialized_ = false;
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  if (camera.width > options.max_width || camera.height > options.max_height) {
    return invalidArgument("frontend: camera image " + std::to_string(camera.width) + "x" +
                           std::to_string(camera.height) + " exceeds max_width x max_height");
  }
  options_ = options;
  camera_ = camera;
  stride_ = options.max_width;
  // From a candidate, reads reach: descriptor kDescriptorReach + 1 (Sobel) px; the subpixel
  // window of the right match kRefineRadius + 2 (shift) + 1 (Sobel) px; the NMS window
  // nms_radius + 2 (response mask) px. One pixel spare.
  border_ = std::max({kDescriptorReach + 2, kRefineRadius + 4, options.nms_radius + 2});

  const auto pixels =
      static_cast<std::size_t>(options.max_width) * static_cast<std::size_t>(options.max_height);
  for (int i = 0; i < 2; ++i) {
    gx_[static_cast<std::size_t>(i)].assign(pixels, 128);
    gy_[static_cast<std::size_t>(i)].assign(pixels, 128);
  }
  smooth_.assign(pixels, 0);
  blob_.assign(pixels, 0);
  corner_.assign(pixels, 0);
  const auto strip_pixels = static_cast<std::size_t>(options.max_width) *
                            static_cast<std::size_t>(kNmsStrip + 2 * options.nms_radius);
  for (auto* buffer :
       {&nms_a_, &nms_b_, &nms_c_, &nms_d_, &nms_hmax_, &nms_hmin_, &nms_max_, &nms_min_}) {
    buffer->assign(strip_pixels, 0);
  }
  flag_row_.assign(static_cast<std::size_t>(options.max_width) + 8, 0);

  const auto max_cand = static_cast<std::size_t>(options.max_candidates);
  const int max_cells_x = (options.max_width + kCell - 1) / kCell;
  const int max_cells_y = (options.max_height + kCell - 1) / kCell;
  const auto cells = static_cast<std::size_t>(kClasses * max_cells_x * max_cells_y + 1);
  for (auto* sets : {&left_, &right_}) {
    for (CandidateSet& s : *sets) {
      s = CandidateSet{};
      s.kp.assign(max_cand, Keypoint{});
      s.desc.assign(max_cand * kDescriptorBytes, 0);
      s.kp_sorted.assign(max_cand, Keypoint{});
      s.desc_sorted.assign(max_cand * kDescriptorBytes, 0);
      s.cell_start.assign(cells, 0);
      s.order.assign(max_cand, 0);
    }
  }
  const auto max_feat = static_cast<std::size_t>(options.max_features);
  tracks_prev_.clear();
  tracks_prev_.reserve(max_feat);
  tracks_cur_.clear();
  tracks_cur_.reserve(max_feat);
  left_used_.assign(max_cand, 0);
  tried_.assign(max_cand, 0);
  const int max_buckets_x = (options.max_width + options.bucket_width - 1) / options.bucket_width;
  const int max_buckets_y =
      (options.max_height + options.bucket_height - 1) / options.bucket_height;
  const auto buckets = static_cast<std::size_t>(max_buckets_x * max_buckets_y + 1);
  bucket_count_.assign(buckets, 0);
  bucket_start_.assign(buckets + 1, 0);
  bucket_order_.assign(max_cand, 0);
  cur_ = 0;
  have_prev_ = false;
  next_id_ = 0;
  hint_du_ = 0.0F;
  hint_dv_ = 0.0F;
  stats_ = FrontendStats{};
  initialized_ = true;
  return Status::ok();
}

void StereoFrontend::reserveOutput(FrameFeatures& out) const {
  out.observations.reserve(static_cast<std::size_t>(options_.max_features));
}

void StereoFrontend::reset() {
  tracks_prev_.clear();
  tracks_cur_.clear();
  have_prev_ = false;
}

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
    std::uint8_t* __restrict ox = gx + static_cast<std::ptrdiff_t>(y) * stride_;
    std::uint8_t* __restrict oy = gy + static_cast<std::ptrdiff_t>(y) * stride_;
    for (int x = 1; x + 1 < w; ++x) {
      const int dx =
          (pm[x + 1] + 2 * p0[x + 1] + pp[x + 1]) - (pm[x - 1] + 2 * p0[x - 1] + pp[x - 1]);
      const int dy = (pp[x - 1] + 2 * pp[x] + pp[x + 1]) - (pm[x - 1] + 2 * pm[x] + pm[x + 1]);
      ox[x] = static_cast<std::uint8_t>(std::clamp((dx >> 1) + 128, 0, 255));
      oy[x] = static_cast<std::uint8_t>(std::clamp((dy >> 1) + 128, 0, 255));
    }
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

// Non-maximum suppression with a separable (2n+1)^2 max/min filter: M = max over the window is
// computed as a horizontal running max per row followed by a vertical max over 2n+1 rows (and
// likewise the min); a pixel is a candidate when r == M and |r| >= threshold. Equal values in one
// window (plateaus) are resolved exactly afterwards: the earliest pixel in row-major order wins,
// so exactly one pixel of a plateau survives. All loops are simple passes over rows that the
// compiler vectorises.
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
  // true unless an equal value comes earlier in row-major order. Branch-free inner loop.
  auto isFirstExtremum = [&](const std::int16_t* r, int x, int y) {
    const std::int16_t c = r[static_cast<std::ptrdiff_t>(y) * stride_ + x];
    int equal = 0;
    for (int yy = y - n; yy < y; ++yy) {
      const std::int16_t* row = r + static_cast<std::ptrdiff_t>(yy) * stride_ + x - n;
      for (int k = 0; k <= 2 * n; ++k) equal |= (row[k] == c) ? 1 : 0;
    }
    const std::int16_t* row = r + static_cast<std::ptrdiff_t>(y) * stride_ + x - n;
    for (int k = 0; k < n; ++k) equal |= (row[k] == c) ? 1 : 0;
    return equal == 0;
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
      // (2n+1)^2 max and min: horizontal then vertical running max/min.
      // The NMS buffers hold one strip: their row 0 is image row ys - n.
      windowMaxMin(r + first, r + first, nms_hmax_.data(), nms_hmin_.data(), tmp, 1, n, total);
      windowMaxMin(nms_hmax_.data(), nms_hmin_.data(), nms_max_.data(), nms_min_.data(), tmp,
                   stride_, n, total);
      const int thr = thresholds[type];
      const auto pos_thr = static_cast<std::int16_t>(thr);
      const auto neg_thr = static_cast<std::int16_t>(-thr);
      for (int y = ys; y < ye; ++y) {
        const std::ptrdiff_t off = static_cast<std::ptrdiff_t>(y) * stride_;
        const std::int16_t* row = r + off;
        const std::ptrdiff_t strip_off = off - first;
        const std::int16_t* vmax = nms_max_.data() + strip_off;
        const std::int16_t* vmin = nms_min_.data() + strip_off;
        for (int x = x0; x < x1; ++x) {
          const int is_max = (row[x] == vmax[x]) & (row[x] >= pos_thr);
          const int is_min = (row[x] == vmin[x]) & (row[x] <= neg_thr);
          flags[x] = static_cast<std::uint8_t>(is_max | (is_min << 1));
        }
        std::memset(flags + x1, 0, 8);  // so that the last 8-byte word reads no stale flags
        // Visit the non-zero flag bytes, 8 at a time (little-endian: byte i = bits 8i .. 8i+7).
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

int StereoFrontend::searchWindow(const CandidateSet& set, const std::uint8_t* d, int cls, int u0,
                                 int u1, int v0, int v1, int* cost) const {
  u0 = std::max(u0, 0);
  v0 = std::max(v0, 0);
  u1 = std::min(u1, set.width - 1);
  v1 = std::min(v1, set.height - 1);
  if (u0 > u1 || v0 > v1 || set.count == 0) return -1;
  int best = -1;
  int best_cost = options_.max_sad + 1;
  const int cx0 = u0 / kCell;
  const int cx1 = u1 / kCell;
  for (int cy = v0 / kCell; cy <= v1 / kCell; ++cy) {
    const int row_base = (cls * set.cells_y + cy) * set.cells_x;
    const int begin = set.cell_start[static_cast<std::size_t>(row_base + cx0)];
    const int end = set.cell_start[static_cast<std::size_t>(row_base + cx1 + 1)];
    // Cells cx0..cx1 of one row are contiguous (candidates are stored in cell order).
    for (int i = begin; i < end; ++i) {
      const Keypoint& kp = set.kp[static_cast<std::size_t>(i)];
      if (kp.u < u0 || kp.u > u1 || kp.v < v0 || kp.v > v1) continue;
      const int c = sad32(d, set.desc.data() + static_cast<std::ptrdiff_t>(i) * kDescriptorBytes);
      if (c < best_cost) {
        best_cost = c;
        best = i;
      }
    }
  }
  if (cost != nullptr) *cost = best_cost;
  return best;
}

int StereoFrontend::matchLeftToRight(int li, int* cost) const {
  const CandidateSet& l = left_[static_cast<std::size_t>(cur_)];
  const Keypoint& kp = l.kp[static_cast<std::size_t>(li)];
  // One pixel of slack either side; refineStereo() applies the exact range.
  const int dmin = static_cast<int>(std::floor(options_.min_disparity)) - 1;
  const int dmax = static_cast<int>(std::ceil(options_.max_disparity)) + 1;
  const int tol = options_.stereo_row_tolerance;
  return searchWindow(right_[static_cast<std::size_t>(cur_)],
                      l.desc.data() + static_cast<std::ptrdiff_t>(li) * kDescriptorBytes, kp.cls,
                      kp.u - dmax, kp.u - dmin, kp.v - tol, kp.v + tol, cost);
}

int StereoFrontend::matchRightToLeft(int ri) const {
  const CandidateSet& r = right_[static_cast<std::size_t>(cur_)];
  const Keypoint& kp = r.kp[static_cast<std::size_t>(ri)];
  const int dmin = static_cast<int>(std::floor(options_.min_disparity)) - 1;
  const int dmax = static_cast<int>(std::ceil(options_.max_disparity)) + 1;
  const int tol = options_.stereo_row_tolerance;
  return searchWindow(left_[static_cast<std::size_t>(cur_)],
                      r.desc.data() + static_cast<std::ptrdiff_t>(ri) * kDescriptorBytes, kp.cls,
                      kp.u + dmin, kp.u + dmax, kp.v - tol, kp.v + tol, nullptr);
}

int StereoFrontend::matchTemporal(const CandidateSet& from, int idx, const CandidateSet& to,
                                  float shift_u, float shift_v, int r) const {
  const Keypoint& kp = from.kp[static_cast<std::size_t>(idx)];
  const int cu = kp.u + static_cast<int>(std::lround(shift_u));
  const int cv = kp.v + static_cast<int>(std::lround(shift_v));
  return searchWindow(to, from.desc.data() + static_cast<std::ptrdiff_t>(idx) * kDescriptorBytes,
                      kp.cls, cu - r, cu + r, cv - r, cv + r, nullptr);
}

// Sum of squared differences of the gradient images (gx and gy) over a dense
// (2 kRefineRadius + 1)^2 window: left centred at (ul, v), right at (ur, v).
std::int64_t StereoFrontend::denseCost(int ul, int ur, int v) const {
  std::int64_t sum = 0;
  for (int dy = -kRefineRadius; dy <= kRefineRadius; ++dy) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(v + dy) * stride_;
    sum += rowSsd(gx_[0].data() + row + ul - kRefineRadius,
                  gx_[1].data() + row + ur - kRefineRadius, 2 * kRefineRadius + 1);
    sum += rowSsd(gy_[0].data() + row + ul - kRefineRadius,
                  gy_[1].data() + row + ur - kRefineRadius, 2 * kRefineRadius + 1);
  }
  return sum;
}

// The right match is a candidate at whole pixels. Along the row of the left keypoint, the dense
// SSD of the gradients (denseCost) is sampled at the candidate and +-2 px; the smallest of the
// inner three is refined by a parabola through it and its neighbours (vertex at
// (c- - c+) / (2 (c- - 2 c0 + c+)), see parabolaPeak). A dense SSD is used here rather than the
// SAD of the sparse descriptor: for a dense window the cost of a shift by +1 and by -1 differ only
// by boundary terms, so the cost is symmetric about its minimum and the parabola is unbiased,
// whereas the sparse samples make it lopsided (0.2-0.3 px bias measured on exact shifts).
// The window is centred on the left keypoint's whole pixel, so its subpixel offset du carries
// over to the right: u_right = u_r + s + delta + du.
bool StereoFrontend::refineStereo(int li, int ri, StereoObservation& obs) const {
  const CandidateSet& l = left_[static_cast<std::size_t>(cur_)];
  const CandidateSet& r = right_[static_cast<std::size_t>(cur_)];
  const Keypoint& lk = l.kp[static_cast<std::size_t>(li)];
  const Keypoint& rk = r.kp[static_cast<std::size_t>(ri)];
  std::array<std::int64_t, 5> cost{};
  for (int k = -2; k <= 2; ++k) {
    cost[static_cast<std::size_t>(k + 2)] = denseCost(lk.u, rk.u + k, lk.v);
  }
  int s = 0;
  if (cost[1] < cost[2] && cost[1] <= cost[3]) s = -1;
  if (cost[3] < cost[2] && cost[3] < cost[1]) s = 1;
  const auto c = static_cast<std::size_t>(s + 2);
  const float delta = parabolaPeak(cost[c - 1], cost[c], cost[c + 1]);
  const double u_left = lk.u + static_cast<double>(lk.du);
  const double v_left = lk.v + static_cast<double>(lk.dv);
  const double u_right = rk.u + s + static_cast<double>(delta) + static_cast<double>(lk.du);
  const double disparity = u_left - u_right;
  if (!(disparity >= options_.min_disparity) || !(disparity <= options_.max_disparity)) {
    return false;
  }
  obs.u_left = u_left;
  obs.v_left = v_left;
  obs.u_right = u_right;
  obs.v_right = v_left;  // rectified: the same row
  return true;
}

Status StereoFrontend::process(const cv::Mat& left, const cv::Mat& right, TimeNs t,
                               std::uint64_t seq, FrameFeatures& out) {
  if (!initialized_) return failedPrecondition("frontend: process() before a successful init()");
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    return invalidArgument("frontend: images must be CV_8UC1");
  }
  if (left.size() != right.size()) {
    return invalidArgument("frontend: left and right images differ in size");
  }
  if (left.cols > options_.max_width || left.rows > options_.max_height) {
    return invalidArgument("frontend: image " + std::to_string(left.cols) + "x" +
                           std::to_string(left.rows) + " exceeds max_width x max_height");
  }
  if (left.cols < 2 * border_ + 2 || left.rows < 2 * border_ + 2) {
    return invalidArgument("frontend: image smaller than " + std::to_string(2 * border_ + 2) +
                           " px per side");
  }
  out.time_ns = t;
  out.sequence = seq;
  out.observations.clear();
  reserveOutput(out);  // no-op once the capacity is there

  stats_ = FrontendStats{};
  const std::int64_t t0 = nowNs();
  const std::int64_t c0 = threadCpuNs();
  if (have_prev_) cur_ = 1 - cur_;
  const auto cur = static_cast<std::size_t>(cur_);
  const auto prev = static_cast<std::size_t>(1 - cur_);
  CandidateSet& lc = left_[cur];
  CandidateSet& rc = right_[cur];
  detect(left, 0, lc);
  detect(right, 1, rc);
  stats_.candidates_left = lc.count;
  stats_.candidates_right = rc.count;
  stats_.candidates_truncated = lc.truncated || rc.truncated;
  std::fill(left_used_.begin(), left_used_.begin() + lc.count, 0);

  const int buckets_x = (left.cols + options_.bucket_width - 1) / options_.bucket_width;
  const int buckets_y = (left.rows + options_.bucket_height - 1) / options_.bucket_height;
  const int buckets = buckets_x * buckets_y;
  auto bucketOf = [&](double u, double v) {
    const int bx = std::clamp(static_cast<int>(u) / options_.bucket_width, 0, buckets_x - 1);
    const int by = std::clamp(static_cast<int>(v) / options_.bucket_height, 0, buckets_y - 1);
    return by * buckets_x + bx;
  };
  std::fill(bucket_count_.begin(), bucket_count_.begin() + buckets, 0);
  const auto max_out = static_cast<std::size_t>(options_.max_features);
  const std::int64_t t1 = nowNs();
  const std::int64_t c1 = threadCpuNs();

  // Tracks: prev-left a -> prev-right b (last frame's stereo match) -> cur-right c (temporal)
  // -> cur-left d (stereo) -> prev-left a2 (temporal); kept iff a2 lies within
  // circular_tolerance_px of a.
  std::swap(tracks_prev_, tracks_cur_);
  tracks_cur_.clear();
  if (!have_prev_) tracks_prev_.clear();
  stats_.tracks_in = static_cast<int>(tracks_prev_.size());
  const CandidateSet& lp = left_[prev];
  const CandidateSet& rp = right_[prev];
  const double tol2 = options_.circular_tolerance_px * options_.circular_tolerance_px;
  // One trip around the circle with temporal windows of half size `radius` centred on the
  // shift (su, sv); 0 and (c, d) on success, else 1 temporal, 2 stereo, 3 circle.
  auto circle = [&](const Track& tr, float su, float sv, int radius, int* c_out, int* d_out) {
    const int c = matchTemporal(rp, tr.right, rc, su, sv, radius);
    if (c < 0) return 1;
    const int d = matchRightToLeft(c);
    if (d < 0 || left_used_[static_cast<std::size_t>(d)] != 0) return 2;
    const int a2 = matchTemporal(lc, d, lp, -su, -sv, radius);
    if (a2 < 0) return 3;
    const Keypoint& ka = lp.kp[static_cast<std::size_t>(tr.left)];
    const Keypoint& kb = lp.kp[static_cast<std::size_t>(a2)];
    const double eu = ka.u - kb.u;
    const double ev = ka.v - kb.v;
    if (eu * eu + ev * ev > tol2) return 3;
    *c_out = c;
    *d_out = d;
    return 0;
  };
  for (const Track& tr : tracks_prev_) {
    if (out.observations.size() >= max_out) break;
    // First where the point would be if it kept its last image motion (a track seen in two
    // frames), with the small radius; failing that (or without history) around the caller's
    // hint with the full radius.
    int c = -1;
    int d = -1;
    int result = 1;
    if (tr.has_flow) {
      result = circle(tr, tr.flow_u, tr.flow_v, options_.predicted_search_radius, &c, &d);
    }
    if (result != 0) result = circle(tr, hint_du_, hint_dv_, options_.search_radius, &c, &d);
    if (result == 1) ++stats_.lost_temporal;
    if (result == 2) ++stats_.lost_stereo;
    if (result == 3) ++stats_.lost_circle;
    if (result != 0) continue;
    StereoObservation obs;
    if (!refineStereo(d, c, obs)) {
      ++stats_.lost_range;
      continue;
    }
    obs.landmark_id = tr.id;
    out.observations.push_back(obs);
    left_used_[static_cast<std::size_t>(d)] = 1;
    const Keypoint& ka = lp.kp[static_cast<std::size_t>(tr.left)];
    const Keypoint& kd = lc.kp[static_cast<std::size_t>(d)];
    tracks_cur_.push_back(
        Track{tr.id, d, c, static_cast<float>(kd.u - ka.u), static_cast<float>(kd.v - ka.v), true});
    ++bucket_count_[static_cast<std::size_t>(bucketOf(obs.u_left, obs.v_left))];
  }
  stats_.tracks_kept = static_cast<int>(tracks_cur_.size());
  const std::int64_t t2 = nowNs();
  const std::int64_t c2 = threadCpuNs();

  // New features: per bucket, the strongest unused current-left candidates with a left-right
  // consistent stereo match, until the bucket holds max_per_bucket features.
  std::fill(bucket_start_.begin(), bucket_start_.begin() + buckets + 1, 0);
  for (int i = 0; i < lc.count; ++i) {
    const Keypoint& kp = lc.kp[static_cast<std::size_t>(i)];
    ++bucket_start_[static_cast<std::size_t>(bucketOf(kp.u, kp.v) + 1)];
  }
  for (int k = 0; k < buckets; ++k) {
    bucket_start_[static_cast<std::size_t>(k + 1)] += bucket_start_[static_cast<std::size_t>(k)];
  }
  // Same counting sort as buildIndex(): afterwards bucket_start_[k + 1] is the start of bucket k.
  for (int i = lc.count - 1; i >= 0; --i) {
    const Keypoint& kp = lc.kp[static_cast<std::size_t>(i)];
    const auto bk = static_cast<std::size_t>(bucketOf(kp.u, kp.v) + 1);
    bucket_order_[static_cast<std::size_t>(--bucket_start_[bk])] = i;
  }
  std::fill(tried_.begin(), tried_.begin() + lc.count, 0);
  const int lr_tol = options_.lr_tolerance;
  for (int k = 0; k < buckets && out.observations.size() < max_out; ++k) {
    const int begin = bucket_start_[static_cast<std::size_t>(k + 1)];
    const int end = (k + 1 < buckets) ? bucket_start_[static_cast<std::size_t>(k + 2)] : lc.count;
    int& filled = bucket_count_[static_cast<std::size_t>(k)];
    while (filled < options_.max_per_bucket && out.observations.size() < max_out) {
      int best = -1;
      std::int32_t best_strength = -1;
      for (int j = begin; j < end; ++j) {
        const int i = bucket_order_[static_cast<std::size_t>(j)];
        if (tried_[static_cast<std::size_t>(i)] != 0 ||
            left_used_[static_cast<std::size_t>(i)] != 0) {
          continue;
        }
        const std::int32_t s = lc.kp[static_cast<std::size_t>(i)].strength;
        if (s > best_strength) {
          best_strength = s;
          best = i;
        }
      }
      if (best < 0) break;
      tried_[static_cast<std::size_t>(best)] = 1;
      const int r = matchLeftToRight(best, nullptr);
      if (r < 0) continue;
      const int back = matchRightToLeft(r);
      if (back < 0) continue;
      const Keypoint& kb = lc.kp[static_cast<std::size_t>(back)];
      const Keypoint& kl = lc.kp[static_cast<std::size_t>(best)];
      if (std::abs(kb.u - kl.u) > lr_tol || std::abs(kb.v - kl.v) > lr_tol) continue;
      StereoObservation obs;
      if (!refineStereo(best, r, obs)) continue;
      obs.landmark_id = next_id_++;
      out.observations.push_back(obs);
      left_used_[static_cast<std::size_t>(best)] = 1;
      tracks_cur_.push_back(Track{obs.landmark_id, best, r, 0.0F, 0.0F, false});
      ++filled;
      ++stats_.new_features;
    }
  }
  const std::int64_t t3 = nowNs();
  const std::int64_t c3 = threadCpuNs();
  stats_.detect_ns = t1 - t0;
  stats_.temporal_ns = t2 - t1;
  stats_.stereo_ns = t3 - t2;
  stats_.detect_cpu_ns = c1 - c0;
  stats_.temporal_cpu_ns = c2 - c1;
  stats_.stereo_cpu_ns = c3 - c2;
  have_prev_ = true;
  hint_du_ = 0.0F;
  hint_dv_ = 0.0F;
  return Status::ok();
}

}  // namespace sunvo
