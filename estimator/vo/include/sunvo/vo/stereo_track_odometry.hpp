#pragma once
// Stereo track odometry (the back end): tracked stereo features (FrameFeatures: landmark id, left
// and right pixel) in, world pose out. Images go in through pipeline::StereoImageOdometry.
//
// Per frame k: associate observations with frame k-1 by landmark id, 3-point RANSAC for the
// initial motion T_k_km1 and outlier rejection, then the bounded Ceres window (base b = oldest
// window frame) refines the poses; the world pose is T_w_k = T_w_b T_k_b^-1 with T_w_b chained
// from the previous windows.
//
// Degenerate input (no or too few matches, all points at infinity / zero disparity, too few
// inliers, a non-finite or implausible result) never yields NaN: the frame is reported kLost, its
// pose is predicted with the last good inter-frame motion scaled to this frame's interval
// (constant velocity in time, or identity when VoOptions::constant_velocity_on_loss is false). The
// next frame is matched first with the last well-tracked frame (the lost frame's pose was only a
// prediction, and real tracks persist across a bad frame), then with the lost frame (the window
// then restarts there); the first frame that tracks again is reported kRecovered. Zero motion
// between two good frames is not degenerate for a stereo camera (depth is measured): it is tracked
// and gives T_k_km1 = identity.

#include <cstdint>
#include <span>
#include <vector>

#include "sunvo/backend/bundle_window.hpp"
#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/motion/stereo_ransac.hpp"

namespace sunvo::vo {

enum class TrackingStatus { kInitializing, kTracking, kLost, kRecovered };
const char* toString(TrackingStatus s);

struct VoOptions {
  motion::RansacOptions ransac;   // see stereo_ransac.hpp
  backend::WindowOptions window;  // see bundle_window.hpp
  int max_observations = 2000;    // count, >= 3: observations per frame (buffers sized once)
  bool use_window = true;         // false: RANSAC motion only (no Ceres refinement)
  bool constant_velocity_on_loss = true;      // on loss predict with the last motion, else identity
  double max_translation_per_frame_m = 10.0;  // m, > 0: a larger estimated motion is treated as
                                              // a failure (degenerate geometry), not as motion
  std::uint64_t seed = 0x5eed;                // RANSAC seed; frame k uses a hash of (seed, k)

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("ransac", s.ransac);
    v("window", s.window);
    v("max_observations", s.max_observations);
    v("use_window", s.use_window);
    v("constant_velocity_on_loss", s.constant_velocity_on_loss);
    v("max_translation_per_frame_m", s.max_translation_per_frame_m);
    v("seed", s.seed);
  }
};

struct VoResult {
  std::uint64_t sequence = 0;
  TimeNs time_ns = 0;
  Isometry3 T_w_c = Isometry3::Identity();    // camera k -> world
  Isometry3 T_k_km1 = Isometry3::Identity();  // the motion used for this frame
  TrackingStatus status = TrackingStatus::kInitializing;
  int num_matches = 0;  // observations associated with frame k-1
  int ransac_inliers = 0;
  int window_landmarks = 0;
  int window_residuals = 0;  // stereo residual blocks in the window
  int solver_iterations = 0;
  double solver_time_s = 0.0;  // Ceres' total time
  double ransac_ms = 0.0;      // wall time of association + RANSAC, ms
  double window_ms = 0.0;      // wall time of window update + solve, ms
  bool window_used = false;    // false when the RANSAC motion was kept (solver failure)
  int reference_gap = 0;       // frames from the motion reference (1 = previous frame; > 1 = a lost
                               // frame was bridged; 0 = none)
};

class StereoTrackOdometry {
 public:
  Status init(const VoOptions& options, const StereoCamera& camera, const Isometry3& T_w_c0);
  Expected<VoResult> process(const FrameFeatures& frame);

  backend::BundleWindow& window() { return window_; }  // e.g. to set the pose-residual hook
  // Turns every world pose kept here about the world point p_w (C_w_c <- C_w_w' C_w_c,
  // p_w_c <- p_w + C_w_w' (p_w_c - p_w)): a correction of the whole trajectory so far, e.g. a
  // start attitude found to be wrong. The next frame's motion is measured as before.
  void turnWorldAbout(const Eigen::Matrix3d& C_w_wnew, const Eigen::Vector3d& p_w);
  const VoOptions& options() const { return options_; }

 private:
  struct IdIndex {
    std::int64_t id;
    int index;
  };
  // A frame kept as a motion reference: its observations (sorted ids for association) and pose.
  struct RefFrame {
    std::vector<StereoObservation> obs;  // capacity max_observations
    std::vector<IdIndex> sorted;
    int count = 0;
    std::uint64_t sequence = 0;
    TimeNs time_ns = 0;
    Isometry3 T_w_c = Isometry3::Identity();
    bool valid = false;
  };
  void store(RefFrame& ref, const FrameFeatures& frame, const Isometry3& T_w_c);
  static double frameGap(const FrameFeatures& frame, const RefFrame& ref);
  // The constant-velocity prediction of the motion T_k_from from the reference `from` to `frame`:
  // the last measured motion scaled by the ratio of the two intervals.
  Isometry3 predictMotion(const FrameFeatures& frame, const RefFrame& from) const;
  int associate(const RefFrame& ref, const FrameFeatures& frame);
  int baseObservations(const RefFrame& ref);
  Status restartWindowAt(const RefFrame& ref);

  VoOptions options_;
  StereoCamera camera_;
  motion::StereoRansac ransac_;
  backend::BundleWindow window_;
  bool initialized_ = false;
  bool lost_ = false;
  bool have_motion_ = false;  // last_motion_ was measured (not the initial identity)
  Isometry3 T_w_c0_ = Isometry3::Identity();
  Isometry3 T_w_last_ = Isometry3::Identity();  // pose emitted for the previous frame
  // The last measured motion T_k_ref between two tracked frames, and the interval it spans: its
  // time (ns, 0 = unknown: the frames' times did not increase) and its frame count (>= 1).
  Isometry3 last_motion_ = Isometry3::Identity();
  TimeNs last_motion_dt_ns_ = 0;
  double last_motion_gap_ = 1.0;
  // The last well-tracked frame (the window's newest frame) and the most recent lost frame; the
  // previous frame is lost_frame_ while lost_, else good_.
  // After a loss the next frame is matched with `good_` first (bridging the lost frame, whose
  // pose was only predicted), then with `lost_frame_`.
  RefFrame good_;
  RefFrame lost_frame_;
  // Buffers sized by max_observations.
  std::vector<motion::StereoMatch> matches_;
  std::vector<int> match_cur_index_;
  std::vector<backend::WindowObservation> window_obs_;
};

}  // namespace sunvo::vo
