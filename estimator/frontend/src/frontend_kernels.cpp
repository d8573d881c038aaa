// The front end's image kernels (declared in frontend_kernels.hpp), each a simple loop over one
// row that the compiler vectorises. SUNVO_SIMD_CLONES builds an x86-64 kernel for the baseline
// ISA, for AVX2 and for x86-64-v4 (AVX-512) and lets the dynamic loader pick one by the CPU it
// runs on (an ifunc); other targets (aarch64 with NEON, sanitizer builds) get the one plain
// version.

#include "frontend_kernels.hpp"

#include <algorithm>
#include <cstdint>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SUNVO_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SUNVO_SANITIZED 1
#endif

#if defined(__x86_64__) && defined(__ELF__) && !defined(SUNVO_SANITIZED)
#define SUNVO_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define SUNVO_SIMD_CLONES
#endif

namespace sunvo::frontend_detail {

SUNVO_SIMD_CLONES void maxMinOf(const std::int16_t* __restrict a, const std::int16_t* __restrict b,
                                const std::int16_t* __restrict c, const std::int16_t* __restrict d,
                                std::int16_t* __restrict out_max, std::int16_t* __restrict out_min,
                                std::ptrdiff_t count) {
  for (std::ptrdiff_t i = 0; i < count; ++i) {
    out_max[i] = std::max(a[i], b[i]);
    out_min[i] = std::min(c[i], d[i]);
  }
}

// [1 2 1]^T [1 2 1] / 16, rounded.
SUNVO_SIMD_CLONES void smoothRow(const std::uint8_t* __restrict pm,
                                 const std::uint8_t* __restrict p0,
                                 const std::uint8_t* __restrict pp, std::uint8_t* __restrict out,
                                 int w) {
  for (int x = 1; x + 1 < w; ++x) {
    const int c = 4 * p0[x] + 2 * (p0[x - 1] + p0[x + 1] + pm[x] + pp[x]) + pm[x - 1] + pm[x + 1] +
                  pp[x - 1] + pp[x + 1];
    out[x] = static_cast<std::uint8_t>((c + 8) >> 4);
  }
}

// gx = [-1 0 1; -2 0 2; -1 0 1] * I, gy its transpose, stored as clamp(g / 2 + 128, 0, 255)
// (arithmetic shift, i.e. floor).
SUNVO_SIMD_CLONES void gradientRow(const std::uint8_t* __restrict pm,
                                   const std::uint8_t* __restrict p0,
                                   const std::uint8_t* __restrict pp, std::uint8_t* __restrict ox,
                                   std::uint8_t* __restrict oy, int w) {
  for (int x = 1; x + 1 < w; ++x) {
    const int dx =
        (pm[x + 1] + 2 * p0[x + 1] + pp[x + 1]) - (pm[x - 1] + 2 * p0[x - 1] + pp[x - 1]);
    const int dy = (pp[x - 1] + 2 * pp[x] + pp[x + 1]) - (pm[x - 1] + 2 * pm[x] + pm[x + 1]);
    ox[x] = static_cast<std::uint8_t>(std::clamp((dx >> 1) + 128, 0, 255));
    oy[x] = static_cast<std::uint8_t>(std::clamp((dy >> 1) + 128, 0, 255));
  }
}

// blob B = 8 I(x,y) - ring of 8 at distance 2; corner C = the saddle mask (see
// StereoFrontend::computeResponses()).
SUNVO_SIMD_CLONES void responseRow(const std::uint8_t* __restrict m2,
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

namespace {

// Flags of one row from the 2N + 1 rows of the horizontal max/min around it (row k at
// hmax + k stride, k = -N .. N): the window max is the max over those rows.
template <int N>
[[gnu::always_inline]] inline void windowFlagsN(const std::int16_t* __restrict r,
                                                const std::int16_t* __restrict hmax,
                                                const std::int16_t* __restrict hmin,
                                                std::ptrdiff_t stride, std::int16_t pos_thr,
                                                std::int16_t neg_thr,
                                                std::uint8_t* __restrict flags, int x0, int x1) {
  for (int x = x0; x < x1; ++x) {
    std::int16_t vmax = hmax[x - N * stride];
    std::int16_t vmin = hmin[x - N * stride];
    for (int k = -N + 1; k <= N; ++k) {
      vmax = std::max(vmax, hmax[x + k * stride]);
      vmin = std::min(vmin, hmin[x + k * stride]);
    }
    const int is_max = (r[x] == vmax) & (r[x] >= pos_thr);
    const int is_min = (r[x] == vmin) & (r[x] <= neg_thr);
    flags[x] = static_cast<std::uint8_t>(is_max | (is_min << 1));
  }
}

}  // namespace

SUNVO_SIMD_CLONES void windowFlags(const std::int16_t* __restrict r,
                                   const std::int16_t* __restrict hmax,
                                   const std::int16_t* __restrict hmin, std::ptrdiff_t stride,
                                   int n, std::int16_t pos_thr, std::int16_t neg_thr,
                                   std::uint8_t* __restrict flags, int x0, int x1) {
  switch (n) {
    case 1:
      windowFlagsN<1>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 2:
      windowFlagsN<2>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 3:
      windowFlagsN<3>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 4:
      windowFlagsN<4>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 5:
      windowFlagsN<5>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 6:
      windowFlagsN<6>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    case 7:
      windowFlagsN<7>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
    default:
      windowFlagsN<8>(r, hmax, hmin, stride, pos_thr, neg_thr, flags, x0, x1);
      break;
  }
}

}  // namespace sunvo::frontend_detail
