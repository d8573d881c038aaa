#pragma once
// The front end's inner loops, shared by its detection (frontend_detect.cpp) and matching
// (stereo_frontend.cpp) translation units. Private to estimator/frontend.

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
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

#include "sunvo/core/status.hpp"

namespace sunvo::frontend_detail {

static_assert(std::endian::native == std::endian::little,
              "detect() reads flag bytes as little-endian 64-bit words");

// CPU time of the calling thread (POSIX), ns; the stages are single-threaded.
inline std::int64_t threadCpuNs() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

inline std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline Status badKey(const char* key, const std::string& what) {
  return invalidArgument(std::string("frontend.") + key + ": " + what);
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

// True if one of r[0], ..., r[count - 1] equals c; count in [0, 8]. Reads r[0..7] whatever
// count is (the caller keeps that inside the buffer).
inline bool anyEqual8(const std::int16_t* r, int count, std::int16_t c) {
#if defined(__SSE2__)
  const __m128i eq =
      _mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(r)), _mm_set1_epi16(c));
  // movemask gives two bits per 16-bit lane; keep the first count lanes.
  const auto bits = static_cast<unsigned>(_mm_movemask_epi8(eq));
  return (bits & ((1U << (2 * count)) - 1U)) != 0;
#elif defined(__ARM_NEON) && defined(__aarch64__)
  static constexpr std::int16_t kLane[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  const uint16x8_t eq = vceqq_s16(vld1q_s16(r), vdupq_n_s16(c));
  const uint16x8_t keep =
      vcltq_s16(vld1q_s16(kLane), vdupq_n_s16(static_cast<std::int16_t>(count)));
  return vmaxvq_u16(vandq_u16(eq, keep)) != 0;
#else
  for (int k = 0; k < count; ++k) {
    if (r[k] == c) return true;
  }
  return false;
#endif
}

// Descriptor sample offsets: a 4x4 grid spanning 13x13 px around the keypoint.
constexpr std::array<int, 4> kGrid = {-6, -2, 2, 6};
constexpr int kDescriptorReach = 6;  // px, largest |offset|

// Vertex offset of a parabola through (-1, rm), (0, r0), (1, rp):
// r(x) = a x^2 + b x + c with a = (rm + rp)/2 - r0, b = (rp - rm)/2; extremum at -b/(2a)
// = (rm - rp) / (2 (rm - 2 r0 + rp)). Clamped to the pixel it belongs to.
inline float parabolaPeak(std::int64_t rm, std::int64_t r0, std::int64_t rp) {
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

// The image kernels below are defined in frontend_kernels.cpp. On x86-64 (GCC) each is compiled
// three times, for the baseline (SSE2), AVX2 and x86-64-v4, and the loader picks one per CPU
// (function multiversioning): the package stays runnable on any x86-64 while a newer CPU does
// more lanes per instruction. They are integer-only, so every version gives bit-identical results.
// restrict-qualified parameters let the compiler vectorise without alias checks.

// out_max[i] = max(a[i], b[i]), out_min[i] = min(c[i], d[i]) for i in [0, count). Inputs may
// overlap each other (they are only read).
void maxMinOf(const std::int16_t* __restrict a, const std::int16_t* __restrict b,
              const std::int16_t* __restrict c, const std::int16_t* __restrict d,
              std::int16_t* __restrict out_max, std::int16_t* __restrict out_min,
              std::ptrdiff_t count);

// One row of the binomial smoothing (see StereoFrontend::smooth()), x in [1, w-1).
void smoothRow(const std::uint8_t* __restrict pm, const std::uint8_t* __restrict p0,
               const std::uint8_t* __restrict pp, std::uint8_t* __restrict out, int w);

// One row of the Sobel gradients (see StereoFrontend::computeGradients()), x in [1, w-1).
void gradientRow(const std::uint8_t* __restrict pm, const std::uint8_t* __restrict p0,
                 const std::uint8_t* __restrict pp, std::uint8_t* __restrict ox,
                 std::uint8_t* __restrict oy, int w);

// One row of the blob and corner responses (see StereoFrontend::computeResponses()),
// x in [2, w-2).
void responseRow(const std::uint8_t* __restrict m2, const std::uint8_t* __restrict m1,
                 const std::uint8_t* __restrict p0, const std::uint8_t* __restrict p1,
                 const std::uint8_t* __restrict p2, std::int16_t* __restrict ob,
                 std::int16_t* __restrict oc, int w);

// Candidate flags of one row, x in [x0, x1), from the horizontal max/min (hmax, hmin point at
// this row; rows -n .. n at multiples of stride): with M the max over those 2n+1 rows (the
// (2n+1)^2 window max) and m the min, bit 0 where r == M and r >= pos_thr, bit 1 where r == m
// and r <= neg_thr. n in [1, 8].
void windowFlags(const std::int16_t* __restrict r, const std::int16_t* __restrict hmax,
                 const std::int16_t* __restrict hmin, std::ptrdiff_t stride, int n,
                 std::int16_t pos_thr, std::int16_t neg_thr, std::uint8_t* __restrict flags, int x0,
                 int x1);

// Running max and min over L = 2n+1 samples spaced `step` apart in flat arrays of `total`
// elements: out_max[i] = max over in_max[i + k step], out_min[i] = min over in_min[i + k step],
// k = -n .. n, for every i whose window lies inside the array. By doubling: M_1 = in,
// M_2j[i] = op(M_j[i], M_j[i + j step]) covers 2j samples; with p the largest power of two <= L,
// op(M_p[i - n step], M_p[i - n step + (L - p) step]) covers exactly [i - n step, i + n step]:
// log2(p) + 1 flat passes instead of 2n. Rows wrap in the flat array (step 1); the caller only
// reads outputs whose window lies in one row. tmp: four scratch arrays of `total` elements.
inline void windowMaxMin(const std::int16_t* in_max, const std::int16_t* in_min,
                         std::int16_t* out_max, std::int16_t* out_min,
                         std::array<std::int16_t*, 4> tmp, std::ptrdiff_t step, int n,
                         std::ptrdiff_t total) {
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

}  // namespace sunvo::frontend_detail
