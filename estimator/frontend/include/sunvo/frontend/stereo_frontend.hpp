#pragma once
// The image front end: keypoints in rectified stereo pairs, left<->right and previous<->current
// matching with a circular consistency check, and landmark ids that persist while a feature is
// tracked. Output: core's FrameFeatures, consumed by the back end.
//
// Method (own implementation of the scheme described in Geiger, Ziegler, Stiller, "StereoScan:
// Dense 3d reconstruction in real-time", IV 2011):
//  1. Per image: binomial 3x3 smoothing, 3x3 Sobel gradients (stored as saturated uint8), a blob
//     and a corner response from small masks, non-maximum suppression -> candidates of four
//     classes (blob max/min, corner max/min), each with a 32-byte descriptor of gradient samples
//     on a 4x4 grid over 13x13 px around it; a grid index per image for window searches.
//  2. Tracks: every feature output in the previous frame is followed around the circle
//     prev-left -> prev-right -> cur-right -> cur-left -> prev-left; it keeps its id only if the
//     circle closes within circular_tolerance_px. A feature tracked before is first searched
//     around the position predicted by its last image motion (small radius); otherwise, or if
//     that circle does not close, around the pixel-shift hint with the full radius.
//  3. New features: the strongest unused current-left candidates of each bucket (grid of buckets,
//     at most max_per_bucket features per bucket including tracked ones) that have a left-right
//     consistent stereo match; they get new ids.
//  4. Subpixel: the left keypoint by a parabola on its response, the right match by a parabola
//     on a dense gradient SSD along the row.
//
// Memory: every buffer is allocated in init() from the options (max image size, max candidates,
// max features). process() performs no heap allocation once `out.observations` has capacity for
// max_features (reserveOutput() does that; otherwise process() reserves it on its first call).
// Deterministic: no randomness; ties are broken by candidate order. Not thread-safe: one
// instance per thread; process() is single-threaded and makes no OpenCV calls that could
// start threads.

#include <array>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo {

struct FrontendOptions {
  int max_width = 1242;                // px, [32, 8192]: largest image width process() accepts
  int max_height = 376;                // px, [32, 8192]: largest image height process() accepts
  int nms_radius = 3;                  // px, [1, 8]: a candidate is the extremum of its
                                       //   (2r+1)^2 neighbourhood
  int blob_threshold = 100;            // response units (8*I - ring of 8 pixels, [-2040, 2040]),
                                       //   [1, 2040]: |blob response| needed for a candidate
  int corner_threshold = 100;          // response units (saddle mask, [-1530, 1530]), [1, 1530]
  int max_candidates = 16384;          // per image, [64, 1<<20]: candidates kept (row-major order)
  int max_features = 2048;             // per frame, [16, 1<<20]: output observations at most
  int bucket_width = 50;               // px, [8, 1024]: bucket size for spreading features
  int bucket_height = 50;              // px, [8, 1024]
  int max_per_bucket = 4;              // features per bucket, [1, 1000] (tracked ones count)
  double min_disparity = 1.0;          // px, [0, max_disparity): smallest accepted disparity
  double max_disparity = 250.0;        // px, (min_disparity, max_width): largest disparity
  int stereo_row_tolerance = 1;        // px, [0, 4]: |v_left - v_right| allowed for a candidate
  int search_radius = 100;             // px, [4, 1000]: half size of the square temporal window
                                       //   for features without motion history (centred on the
                                       //   pixel-shift hint)
  int predicted_search_radius = 20;    // px, [4, search_radius]: the same for tracked features,
                                       //   centred on the position predicted from their last
                                       //   image motion (constant image velocity)
  int max_sad = 1200;                  // SAD of 32 uint8 samples, [1, 8160]: worse matches rejected
  double circular_tolerance_px = 1.5;  // px, [0, 100]: the circle must close this close
  int lr_tolerance = 1;                // px, [0, 10]: left->right->left check for new features
  bool measure_v_right = false;        // subpixel right row of every match whose window
                                       //   determines it (v_right_measured; else v_right =
                                       //   v_left), and its column from the same 2-D step;
                                       //   what stereo self-calibration needs
  bool correct_edge_columns = false;   // needs measure_v_right: a match along an edge (its row
                                       //   not measured) gets its column moved along the edge
                                       //   by the rig's row offset there, from a plane fitted to
                                       //   the measured rows of recent frames (correctEdgeColumns)
  int row_offset_memory_frames = 20;   // frames, [1, 10000]: the plane's memory (each frame's
                                       //   rows weigh 1 - 1/N less per later frame)

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("max_width", s.max_width);
    v("max_height", s.max_height);
    v("nms_radius", s.nms_radius);
    v("blob_threshold", s.blob_threshold);
    v("corner_threshold", s.corner_threshold);
    v("max_candidates", s.max_candidates);
    v("max_features", s.max_features);
    v("bucket_width", s.bucket_width);
    v("bucket_height", s.bucket_height);
    v("max_per_bucket", s.max_per_bucket);
    v("min_disparity", s.min_disparity);
    v("max_disparity", s.max_disparity);
    v("stereo_row_tolerance", s.stereo_row_tolerance);
    v("search_radius", s.search_radius);
    v("predicted_search_radius", s.predicted_search_radius);
    v("max_sad", s.max_sad);
    v("circular_tolerance_px", s.circular_tolerance_px);
    v("lr_tolerance", s.lr_tolerance);
    v("measure_v_right", s.measure_v_right);
    v("correct_edge_columns", s.correct_edge_columns);
    v("row_offset_memory_frames", s.row_offset_memory_frames);
  }
};

// What the last process() call did. *_ns: wall time (monotonic clock); *_cpu_ns: CPU time of the
// calling thread (differs from wall time when the core is shared with other work).
struct FrontendStats {
  std::int64_t detect_ns = 0;    // smoothing, gradients, responses, NMS, descriptors, grid index
                                 //   (both images)
  std::int64_t temporal_ns = 0;  // track following around the circle incl. circular check
  std::int64_t stereo_ns = 0;    // new features: bucketing, left<->right matching, subpixel
  std::int64_t detect_cpu_ns = 0;
  std::int64_t temporal_cpu_ns = 0;
  std::int64_t stereo_cpu_ns = 0;
  int candidates_left = 0;
  int candidates_right = 0;
  int tracks_in = 0;                  // features of the previous frame
  int tracks_kept = 0;                // of those, passed the circular check (id kept)
  int lost_temporal = 0;              // prev-right -> cur-right found no match
  int lost_stereo = 0;                // cur-right -> cur-left found no (free) match
  int lost_circle = 0;                // cur-left -> prev-left found none or another point
  int lost_range = 0;                 // refined disparity outside [min_disparity, max_disparity]
  int new_features = 0;               // got a new id
  bool candidates_truncated = false;  // max_candidates was reached in one of the images
  // correct_edge_columns: the row-offset plane v_right - v_left = a + b (u - cu) / fu +
  // c (v - cv) / fv after this frame (px), the measured rows it took from this frame, and the
  // edge matches whose column it moved.
  double row_offset_a_px = 0.0;
  double row_offset_b_px = 0.0;
  double row_offset_c_px = 0.0;
  int row_offset_rows_used = 0;
  int edge_columns_moved = 0;
  bool row_offset_restarted = false;  // most of this frame's rows missed the plane: refitted
                                      //   from this frame alone
};

class StereoFrontend {
 public:
  // Allocates every buffer. May be called again to re-initialise (forgets all tracks).
  Status init(const FrontendOptions& options, const StereoCamera& camera);

  // left/right: rectified CV_8UC1 images of equal size <= (max_width, max_height).
  // Fills out (cleared first) with the features that have a valid stereo match.
  Status process(const cv::Mat& left, const cv::Mat& right, TimeNs t, std::uint64_t seq,
                 FrameFeatures& out);

  // Reserves out.observations for max_features so that process() never grows it.
  void reserveOutput(FrameFeatures& out) const;

  // Optional motion prior: expected pixel shift (current - previous) of the image content in
  // the next process() call; the temporal search window is centred on it. Reset to 0 after use.
  void setPixelShiftHint(float du, float dv) {
    hint_du_ = du;
    hint_dv_ = dv;
  }

  // Forgets all tracks (the next frame starts fresh; ids keep increasing).
  void reset();

  const FrontendStats& lastStats() const { return stats_; }
  const FrontendOptions& options() const { return options_; }

  // 32 bytes: 16 Sobel-x then 16 Sobel-y samples (Sobel / 2 + 128, saturated) around the point.
  static constexpr int kDescriptorBytes = 32;

 private:
  struct Keypoint {
    std::int16_t u = 0;  // px, integer pixel of the extremum
    std::int16_t v = 0;
    std::uint8_t cls = 0;       // 0 blob max, 1 blob min, 2 corner max, 3 corner min
    std::int32_t strength = 0;  // |response|
    float du = 0.0F;            // subpixel offset of the response peak, [-0.5, 0.5]
    float dv = 0.0F;
  };
  // Candidates of one image with their descriptors and a grid index (cells of kCell px, per
  // class): after buildIndex() the candidates are stored in cell order and cell c holds
  // candidates cell_start[c] .. cell_start[c+1]-1.
  struct CandidateSet {
    int count = 0;
    int width = 0;
    int height = 0;
    int cells_x = 0;
    int cells_y = 0;
    bool truncated = false;
    std::vector<Keypoint> kp;
    std::vector<std::uint8_t> desc;  // count * kDescriptorBytes
    std::vector<std::int32_t> cell_start;
    std::vector<std::int32_t> order;        // buildIndex scratch: cell-ordered source indices
    std::vector<Keypoint> kp_sorted;        // buildIndex scratch, swapped with kp
    std::vector<std::uint8_t> desc_sorted;  // buildIndex scratch, swapped with desc
  };
  // A feature output in a frame, remembered to follow it in the next one.
  struct Track {
    std::int64_t id = -1;
    std::int32_t left = -1;   // candidate index in that frame's left set
    std::int32_t right = -1;  // candidate index in that frame's right set
    float flow_u = 0.0F;      // px, left image motion over the frame before (if has_flow)
    float flow_v = 0.0F;
    bool has_flow = false;  // tracked over at least one frame pair
  };
  static constexpr int kCell = 16;         // px, grid index cell size
  static constexpr int kRefineRadius = 4;  // px, half size of the dense subpixel window
  static constexpr int kNmsStrip = 24;     // rows per NMS strip (cache blocking)
  static constexpr int kClasses = 4;
  // measure_v_right: a match's right row is kept when its window's gradient structure is not
  // an edge: the smaller eigenvalue of the Lucas-Kanade matrix at least this fraction of the
  // larger (the row then at most ~2x less certain than the best-determined direction); else
  // v_right_measured = false.
  static constexpr double kMinEigenvalueRatio = 0.25;

  // img_index 0 = left, 1 = right: which gradient buffers are written / read.
  void smooth(const cv::Mat& img);
  void computeGradients(const cv::Mat& img, int img_index);
  void computeResponses(const cv::Mat& img);
  void detect(const cv::Mat& img, int img_index, CandidateSet& set);
  void buildIndex(CandidateSet& set);
  void describeAt(int img_index, int u, int v, std::uint8_t* d) const;
  // Best candidate of `set` of class cls in u in [u0,u1], v in [v0,v1]; -1 if none under
  // max_sad. cost gets its SAD.
  int searchWindow(const CandidateSet& set, const std::uint8_t* d, int cls, int u0, int u1, int v0,
                   int v1, int* cost) const;
  int matchLeftToRight(int li, int* cost) const;
  int matchRightToLeft(int ri) const;
  // Best candidate of `to` for candidate idx of `from` in the square window of half size r
  // centred on the candidate's position + (shift_u, shift_v).
  int matchTemporal(const CandidateSet& from, int idx, const CandidateSet& to, float shift_u,
                    float shift_v, int r) const;
  std::int64_t denseCost(int ul, int ur, int v, int dv_right) const;
  // Subpixel u of the right match ri of left candidate li (in the current frame); false if the
  // disparity falls outside the range.
  // edge_slope: g_v / g_u of the right window (the Lucas-Kanade matrix's a12 / a11) when it is
  // an edge whose row is not measured (measure_v_right), else NaN.
  bool refineStereo(int li, int ri, StereoObservation& obs, float* edge_slope) const;
  // measure_v_right: obs.v_right (and v_right_measured) of left keypoint lk matched at right
  // column ur and row lk.v + sv (whole pixels), from the current gradient images; obs.u_right
  // from the same step when its disparity stays in range.
  void measureRightRow(const Keypoint& lk, int ur, int sv, StereoObservation& obs,
                       float* edge_slope) const;
  // correct_edge_columns: updates the row-offset plane from out's measured rows and moves the
  // column of every edge match (edge_slope_ finite) along its edge (frontend_rows.cpp).
  void correctEdgeColumns(FrameFeatures& out);

  FrontendOptions options_;
  StereoCamera camera_;
  bool initialized_ = false;

  // Current images: gradients [0] left, [1] right (Sobel / 2 + 128, saturated; row stride
  // max_width), and responses (scratch, reused for left then right).
  std::array<std::vector<std::uint8_t>, 2> gx_;
  std::array<std::vector<std::uint8_t>, 2> gy_;
  std::vector<std::uint8_t> smooth_;  // the smoothed current image
  std::vector<std::int16_t> blob_;
  std::vector<std::int16_t> corner_;
  // NMS buffers of one strip (kNmsStrip + 2 nms_radius rows): doubling scratch and the
  // horizontal (2n+1) window max/min (the vertical max/min is taken per row, not stored).
  std::vector<std::int16_t> nms_a_;
  std::vector<std::int16_t> nms_b_;
  std::vector<std::int16_t> nms_c_;
  std::vector<std::int16_t> nms_d_;
  std::vector<std::int16_t> nms_hmax_;
  std::vector<std::int16_t> nms_hmin_;
  std::vector<std::uint8_t> flag_row_;  // NMS: bit 0 max, bit 1 min candidate
  int stride_ = 0;
  int border_ = 0;  // px: candidates lie at least this far inside the image

  std::array<CandidateSet, 2> left_;  // [cur_], [1 - cur_]
  std::array<CandidateSet, 2> right_;
  int cur_ = 0;
  bool have_prev_ = false;

  std::vector<Track> tracks_prev_;
  std::vector<Track> tracks_cur_;
  std::vector<std::int32_t> left_used_;     // per current-left candidate: 1 if taken
  std::vector<std::int32_t> bucket_count_;  // features per bucket
  std::vector<std::int32_t> bucket_start_;  // counting sort of current-left candidates by bucket
  std::vector<std::int32_t> bucket_order_;
  std::vector<std::uint8_t> tried_;  // per current-left candidate in bucket selection
  std::int64_t next_id_ = 0;
  float hint_du_ = 0.0F;
  float hint_dv_ = 0.0F;
  FrontendStats stats_;
  // correct_edge_columns: per output observation its edge slope (NaN: not an edge), and the
  // row-offset plane's decayed normal equations over (1, x, y), x = (u - cu) / fu,
  // y = (v - cv) / fv, with its weighted squared residuals.
  std::vector<float> edge_slope_;
  std::array<double, 6> row_ata_{};  // upper triangle: 11 12 13 22 23 33
  std::array<double, 3> row_atb_{};
  double row_weight_ = 0.0;
  double row_sse_ = 0.0;
  std::array<double, 3> row_plane_{};
  bool row_plane_valid_ = false;
};

}  // namespace sunvo
