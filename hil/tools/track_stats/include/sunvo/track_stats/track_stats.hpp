#pragma once
// The error of a set of stereo feature tracks, measured against ground-truth camera poses
// (issue 15, deliverable 1). Everything is computed from the tracks and the poses alone; no
// estimator runs. Frames: camera k = rectified left camera at frame k (x right, y down, z forward);
// T_0_k maps camera k into camera 0 (the ground truth's world).
//
//  - Motion residuals: each landmark seen in frames k-1 and k is triangulated from its stereo pair
//    in k-1 (Eq. 1), moved by the true motion T_k_km1 = T_0_k^-1 T_0_km1 and projected into k:
//    r = (uL, vL, d)_k,observed - project(T_k_km1 p_km1). Their per-frame mean is the image shift
//    a two-frame estimator absorbs as rotation: du/fu about the camera's y axis (yaw), dv/fv
//    about its x axis (pitch).
//  - Left/right vertical offset: vL - vR over every observation, fitted as the plane
//    a + b (uL - cu) + c (vL - cv) (robust: residuals beyond 4 MAD-sigmas dropped, refitted), over
//    the whole drive and per block of frames. A right camera rolled by theta about its optical
//    axis gives b ~ -theta (vR ~ vL + theta (u - cu)); a pitch offset gives a ~ fv delta; a
//    vertical scale difference gives c.
//  - Disparity bias vs depth: landmarks seen in >= 3 frames are triangulated from their LEFT
//    observations only with the true poses (least-squares midpoint of the rays), which gives a
//    depth z_k independent of the disparity; the disparity error is d_observed - fu b / z_k,
//    binned by z_k. Only landmarks whose rays span >= min_parallax_deg and reproject within
//    max_mono_reproj_px into every left image.
//  - By track age: the motion residual and vL - vR against the age of the track (a tracker that
//    drifts shows residuals or an offset growing with age), and the residual against the true
//    image motion (a tracker that lags shows a negative gain).
//  - Conditioning per frame: tracks, share left of cu, occupied cells of a grid_cols x grid_rows
//    grid over the image.
//  - Jumps: frames whose mean motion residual is more than jump_sigmas robust sigmas (1.4826 MAD
//    over the drive) and at least jump_min_px from the drive's median; with an estimate, frames
//    whose relative rotation error exceeds jump_rotation_mdeg.

#include <optional>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::track_stats {

struct TrackStatsOptions {
  double min_disparity_px = 1.0;      // px, [0, 100]: smaller disparities are not triangulated
  double max_residual_px = 5.0;       // px, (0, 100]: larger motion residuals are outliers
  double max_offset_px = 3.0;         // px, (0, 100]: |vL - vR| beyond this is a mismatch
  int block_frames = 250;             // frames, [10, 100000]: block of the per-block plane fits
  double min_parallax_deg = 3.0;      // deg, (0, 90): ray span of a monocular triangulation
  double max_mono_reproj_px = 1.0;    // px, (0, 10]: its reprojection bound in every left image
  int grid_cols = 4;                  // cells, [1, 64]
  int grid_rows = 3;                  // cells, [1, 64]
  double jump_sigmas = 4.0;           // robust sigmas, (0, 100]
  double jump_min_px = 0.1;           // px, [0, 100]: and at least this far from the median
  double jump_rotation_mdeg = 100.0;  // mdeg, (0, 1e6]: per-frame rotation error of a "jump"

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("min_disparity_px", s.min_disparity_px);
    v("max_residual_px", s.max_residual_px);
    v("max_offset_px", s.max_offset_px);
    v("block_frames", s.block_frames);
    v("min_parallax_deg", s.min_parallax_deg);
    v("max_mono_reproj_px", s.max_mono_reproj_px);
    v("grid_cols", s.grid_cols);
    v("grid_rows", s.grid_rows);
    v("jump_sigmas", s.jump_sigmas);
    v("jump_min_px", s.jump_min_px);
    v("jump_rotation_mdeg", s.jump_rotation_mdeg);
  }
};

struct FrameStats {
  int tracks = 0;             // observations in the frame
  int pairs = 0;              // of them, residuals kept (seen in k-1 too, inlier)
  double mean_du = 0.0;       // px, motion residual of uL, mean over the pairs (0 when none)
  double mean_dv = 0.0;       // px
  double median_du = 0.0;     // px
  double median_dv = 0.0;     // px
  double mean_dd = 0.0;       // px, disparity residual
  double mean_offset = 0.0;   // px, mean vL - vR of the frame's observations
  double left_share = 0.0;    // share of tracks with uL < cu
  int cells = 0;              // occupied grid cells
  double rot_err_mdeg = 0.0;  // with an estimate: |relative rotation error| of (k-1, k)
  Eigen::Vector3d rot_err_c_mdeg = Eigen::Vector3d::Zero();  // its rotation vector, camera k
};

// vL - vR = a + b (uL - cu) + c (vL - cv).
struct OffsetPlane {
  double a_px = 0.0;
  double b = 0.0;       // px/px
  double c = 0.0;       // px/px
  double rms_px = 0.0;  // of the kept observations about the plane
  std::size_t used = 0;
  std::size_t rejected = 0;
  int first_frame = 0, last_frame = 0;
};

struct DepthBin {
  double z_min_m = 0.0, z_max_m = 0.0;
  std::size_t n = 0;
  double mean_px = 0.0, median_px = 0.0;  // d_observed - fu b / z
};

// The same disparity error by the measured disparity's fractional part f = d - round(d) in
// [f_min, f_max): a subpixel estimator drawn towards whole or half pixels errs by a pattern in f.
struct FractionBin {
  double f_min = 0.0, f_max = 0.0;
  std::size_t n = 0;
  double mean_px = 0.0, median_px = 0.0;  // d_observed - fu b / z
};

// Statistics of the observations whose track is `age` frames old (frames since its first
// observation), age in [age_min, age_max].
struct AgeBin {
  int age_min = 0, age_max = 0;
  std::size_t n = 0;                    // motion-residual pairs
  double mean_du = 0.0, mean_dv = 0.0;  // px, motion residual
  std::size_t n_offset = 0;             // observations
  double mean_offset = 0.0;             // px, vL - vR
};

// Motion residual fitted as r = g * flow + (o_u, o_v): flow = predicted(k) - observed(k-1), the
// true image motion. g < 0: the tracker undershoots the motion (lags).
struct FlowFit {
  double gain = 0.0;
  double offset_u_px = 0.0, offset_v_px = 0.0;
  std::size_t n = 0;
};

// Motion residuals of the pairs whose stereo depth in k-1 is in [z_min_m, z_max_m): a rotation
// error shifts every depth alike; a translation-direction or principal-point error shifts near
// points more (~ 1/z).
struct ResidualDepthBin {
  double z_min_m = 0.0, z_max_m = 0.0;
  std::size_t n = 0;
  double mean_du = 0.0, mean_dv = 0.0;  // px
};

struct Jump {
  int frame = 0;
  bool residual = false;  // the mean motion residual jumps
  bool rotation = false;  // the estimate's rotation error jumps
};

struct TrackStats {
  std::vector<FrameStats> frames;
  OffsetPlane plane;                // whole drive
  std::vector<OffsetPlane> blocks;  // per block_frames
  std::vector<DepthBin> depth_bins;
  std::vector<FractionBin> fraction_bins;  // 10 bins of 0.1 px over [-0.5, 0.5)
  std::size_t mono_landmarks = 0;          // landmarks the disparity check could use
  std::vector<AgeBin> ages;
  std::vector<ResidualDepthBin> residual_depths;
  FlowFit flow;
  std::vector<Jump> jumps;
};

// gt_T_0_k: one pose per frame; estimate_T_0_k: empty or one pose per frame.
Expected<TrackStats> computeTrackStats(const StereoCamera& camera,
                                       const std::vector<FrameFeatures>& frames,
                                       const std::vector<Isometry3>& gt_T_0_k,
                                       const std::vector<Isometry3>& estimate_T_0_k,
                                       const TrackStatsOptions& options);

// Median of v (0 when empty); v is reordered.
double median(std::vector<double>& v);

}  // namespace sunvo::track_stats
