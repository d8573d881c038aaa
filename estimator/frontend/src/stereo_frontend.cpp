#include "sunvo/frontend/stereo_frontend.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#endif

#include "frontend_kernels.hpp"

namespace sunvo {
using namespace frontend_detail;  // NOLINT: the private kernels of this folder

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
  if (correct_edge_columns && !measure_v_right) {
    return badKey("correct_edge_columns", "needs measure_v_right: true (the rows it fits)");
  }
  if (row_offset_memory_frames < 1 || row_offset_memory_frames > 10000) {
    return badKey("row_offset_memory_frames", "must be in [1, 10000] frames");
  }
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
  for (auto* buffer : {&nms_a_, &nms_b_, &nms_c_, &nms_d_, &nms_hmax_, &nms_hmin_}) {
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
  edge_slope_.assign(max_feat, 0.0F);
  row_ata_ = {};
  row_atb_ = {};
  row_weight_ = 0.0;
  row_sse_ = 0.0;
  row_plane_ = {};
  row_plane_valid_ = false;
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
// (2 kRefineRadius + 1)^2 window: left centred at (ul, v), right at (ur, v + dv_right).
std::int64_t StereoFrontend::denseCost(int ul, int ur, int v, int dv_right) const {
  std::int64_t sum = 0;
  const std::ptrdiff_t shift = static_cast<std::ptrdiff_t>(dv_right) * stride_;
  for (int dy = -kRefineRadius; dy <= kRefineRadius; ++dy) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(v + dy) * stride_;
    sum += rowSsd(gx_[0].data() + row + ul - kRefineRadius,
                  gx_[1].data() + row + shift + ur - kRefineRadius, 2 * kRefineRadius + 1);
    sum += rowSsd(gy_[0].data() + row + ul - kRefineRadius,
                  gy_[1].data() + row + shift + ur - kRefineRadius, 2 * kRefineRadius + 1);
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
// over to the right: u_right = u_r + s + delta + du. With measure_v_right the right row is
// measured too (measureRightRow); else v_right = v_left, as rectification promises. A rig whose
// rectification is off by a fraction of a pixel shows it there (what the stereo
// self-calibration estimates).
bool StereoFrontend::refineStereo(int li, int ri, StereoObservation& obs, float* edge_slope) const {
  *edge_slope = std::numeric_limits<float>::quiet_NaN();
  const CandidateSet& l = left_[static_cast<std::size_t>(cur_)];
  const CandidateSet& r = right_[static_cast<std::size_t>(cur_)];
  const Keypoint& lk = l.kp[static_cast<std::size_t>(li)];
  const Keypoint& rk = r.kp[static_cast<std::size_t>(ri)];
  std::array<std::int64_t, 5> cost{};
  for (int k = -2; k <= 2; ++k) {
    cost[static_cast<std::size_t>(k + 2)] = denseCost(lk.u, rk.u + k, lk.v, 0);
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
  obs.v_right_measured = false;
  if (options_.measure_v_right) {
    // The whole row to start from: the smallest dense cost of rows -1, 0, 1 (a rig off by more
    // than half a pixel, e.g. far from the centre under a small roll).
    const int ur = rk.u + s;
    const std::int64_t up = denseCost(lk.u, ur, lk.v, -1);
    const std::int64_t down = denseCost(lk.u, ur, lk.v, 1);
    int sv = 0;
    if (up < cost[c] && up <= down) sv = -1;
    if (down < cost[c] && down < up) sv = 1;
    measureRightRow(lk, ur, sv, obs, edge_slope);
  }
  return true;
}

// The right row of a match, for the stereo self-calibration. A parabola through the dense cost
// over rows is biased towards whole pixels on real images (their cost curves are sharper than a
// parabola: 0.23 px found for a 0.3 px shift of KITTI frames), so the row comes from one
// Lucas-Kanade step on the gradient images instead: with R the right channels (gx, gy) around
// the whole pixel (ur, v + sv) (sv: the best of rows -1, 0, 1) and L the left ones around the
// keypoint,
//   R(x + du, y + dv) ~ R + du R_x + dv R_y = L   over the (2 kRefineRadius + 1)^2 window,
// least squares: [S R_x^2, S R_x R_y; S R_x R_y, S R_y^2] (du, dv) = S (L - R) (R_x, R_y), with
// central differences averaged over both images for R_x, R_y (a symmetric step). Both offsets
// are solved: v_right = v + sv + dv + dv_left (the keypoint's own subpixel row) and, when
// |du| <= 1 px, u_right = ur + du + du_left in place of the parabola's. Both are kept only when
// the window determines them: the smaller eigenvalue of the 2x2 matrix at least
// kMinEigenvalueRatio of the larger (not along an edge) and |dv| <= 1 px.
void StereoFrontend::measureRightRow(const Keypoint& lk, int ur, int sv, StereoObservation& obs,
                                     float* edge_slope) const {
  const std::ptrdiff_t right_shift = static_cast<std::ptrdiff_t>(sv) * stride_;
  // A gradient stored at 0 or 255 was clipped (|g| > 255): not linear in the offset.
  auto clipped = [](std::uint8_t g) { return g == 0 || g == 255; };
  double a11 = 0.0, a12 = 0.0, a22 = 0.0, b1 = 0.0, b2 = 0.0;
  for (int ch = 0; ch < 2; ++ch) {
    const std::uint8_t* L = (ch == 0 ? gx_ : gy_)[0].data();
    const std::uint8_t* R = (ch == 0 ? gx_ : gy_)[1].data();
    for (int dy = -kRefineRadius; dy <= kRefineRadius; ++dy) {
      const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(lk.v + dy) * stride_;
      for (int dx = -kRefineRadius; dx <= kRefineRadius; ++dx) {
        const std::ptrdiff_t r = row + right_shift + ur + dx;
        const std::ptrdiff_t l = row + lk.u + dx;
        if (clipped(L[l]) || clipped(R[r]) || clipped(R[r + 1]) || clipped(R[r - 1]) ||
            clipped(R[r + stride_]) || clipped(R[r - stride_])) {
          continue;
        }
        // Derivatives averaged over both images (a symmetric step).
        const double rx = 0.25 * (int{R[r + 1]} - int{R[r - 1]} + int{L[l + 1]} - int{L[l - 1]});
        const double ry = 0.25 * (int{R[r + stride_]} - int{R[r - stride_]} + int{L[l + stride_]} -
                                  int{L[l - stride_]});
        const double e = int{L[l]} - int{R[r]};
        a11 += rx * rx;
        a12 += rx * ry;
        a22 += ry * ry;
        b1 += e * rx;
        b2 += e * ry;
      }
    }
  }
  const double det = a11 * a22 - a12 * a12;
  const double tr = a11 + a22;
  const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  const double lmin = 0.5 * tr - disc;
  const double lmax = 0.5 * tr + disc;
  if (!(lmin >= kMinEigenvalueRatio * lmax)) {
    // An edge: the row stays unmeasured; its slope is what correctEdgeColumns needs.
    if (a11 > 0.0) *edge_slope = static_cast<float>(a12 / a11);
    return;
  }
  if (!(det > 0.0)) return;
  const double dv = (a11 * b2 - a12 * b1) / det;
  const double du = (a22 * b1 - a12 * b2) / det;
  if (!std::isfinite(dv) || std::abs(dv) > 1.0) return;
  obs.v_right = lk.v + sv + dv + static_cast<double>(lk.dv);
  obs.v_right_measured = true;
  // The column from the same step: the parabola above is taken along row v, and where the right
  // row is off (a rig error; under 0.1 deg of roll up to 1 px at the image's corners) a slanted
  // edge moves sideways with the row, which biases the disparity (docs/selfcal.md, measured).
  const double u_right = ur + du + static_cast<double>(lk.du);
  const double disparity = obs.u_left - u_right;
  if (std::isfinite(du) && std::abs(du) <= 1.0 && disparity >= options_.min_disparity &&
      disparity <= options_.max_disparity) {
    obs.u_right = u_right;
  }
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
    float slope = 0.0F;
    if (!refineStereo(d, c, obs, &slope)) {
      ++stats_.lost_range;
      continue;
    }
    obs.landmark_id = tr.id;
    edge_slope_[out.observations.size()] = slope;
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
      float slope = 0.0F;
      if (!refineStereo(best, r, obs, &slope)) continue;
      obs.landmark_id = next_id_++;
      edge_slope_[out.observations.size()] = slope;
      out.observations.push_back(obs);
      left_used_[static_cast<std::size_t>(best)] = 1;
      tracks_cur_.push_back(Track{obs.landmark_id, best, r, 0.0F, 0.0F, false});
      ++filled;
      ++stats_.new_features;
    }
  }
  if (options_.correct_edge_columns) correctEdgeColumns(out);
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
