#pragma once
// A bounded sliding window of N stereo poses (the paper's back end).
//
// The window holds the last N frames (N = window_size, default 2). Its base frame b is the oldest
// frame; the base's world pose T_w_b is fixed (it came from the previous windows). Unknowns: the
// other poses T_k_b (unit quaternion, local update as ceres::EigenQuaternionManifold, +
// translation) and the positions p_b of the landmarks seen in at least two window frames,
// initialised by stereo triangulation in the first frame that sees them with enough disparity.
//
// Memory: everything is sized in init(); nothing grows with the run length. The default solver
// (WindowSolver::kSchurLm, schur_lm_solver.hpp) keeps its buffers from init() and allocates nothing
// per solve. The reference solver (kCeres) keeps a ceres::Problem for the window's life (fast
// removal, pose and landmark blocks added once); each solve() removes the previous residual
// blocks and adds the new ones from a pool of stereo cost functions bound to fixed measurement
// slots, and ceres::Solve allocates its own bookkeeping per call.
//
// Extension hook: a caller may add one more residual type per pose (e.g. an absolute direction,
// the sun: s_hat_k = C_k_b C_b_w s_w) through setPoseResidualHook(); the hook is called in solve()
// after the stereo blocks are in, may read T_w_b(), frame times and sequences, and calls
// addPoseResidual() for any slot. Its cost functions and losses stay owned by the caller.

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "sunvo/backend/rate_spread.hpp"
#include "sunvo/backend/schur_lm_solver.hpp"
#include "sunvo/backend/stereo_residual.hpp"
#include "sunvo/backend/travel_direction.hpp"
#include "sunvo/core/camera.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::backend {

// Which solver minimises the window: the fixed-memory Schur-complement Levenberg-Marquardt of
// schur_lm_solver.hpp (no heap allocation per solve), or ceres::Solve (DENSE_SCHUR), the reference.
enum class WindowSolver { kSchurLm, kCeres };
inline std::span<const std::string_view> enumNames(WindowSolver) {
  static constexpr std::string_view kNames[] = {"schur_lm", "ceres"};
  return kNames;
}

enum class RobustLoss { kNone, kHuber, kCauchy };
inline std::span<const std::string_view> enumNames(RobustLoss) {
  static constexpr std::string_view kNames[] = {"none", "huber", "cauchy"};
  return kNames;
}

struct WindowOptions {
  int window_size = 2;                    // poses, [2, kMaxWindowSize]
  int max_observations_per_frame = 2000;  // count, >= 3: observations kept per window frame
  int max_landmarks = 2000;               // count, >= 3: landmarks per window (extra ones skipped)
  double sigma_u_px = 1.0;                // px, > 0: std of the u measurement
  double sigma_v_px = 1.0;                // px, > 0: std of the v measurement
  double sigma_d_px = 1.0;                // px, > 0: std of the disparity measurement
  RobustLoss loss = RobustLoss::kCauchy;  // robust loss on the whitened residual
  double loss_scale = 2.0;                // whitened units (sigmas), > 0: Huber/Cauchy scale
  double min_disparity_px = 1.0;  // px, > 0: smallest disparity used to triangulate a landmark
  WindowSolver solver = WindowSolver::kSchurLm;  // schur_lm | ceres
  int max_num_iterations = 10;                   // count, [1, 1000]: solver iterations per solve
  double max_solver_time_in_seconds = 0.05;      // s, > 0: solver time limit per solve
  // Soft prior on each frame's motion relative to the previous window frame, when addFrame() is
  // given a predicted motion (e.g. constant velocity). A std of 0 leaves that part free.
  double motion_prior_sigma_rot_deg = 0.0;  // deg, >= 0: std of the rotation deviation
  double motion_prior_sigma_trans_m = 0.0;  // m, >= 0: std of the translation deviation
  // The translation part in terms of the vehicle's acceleration (issue 15; docs/motion_prior.md):
  // a frame's translation differs from the prediction's by (v_k - v_k-1) dt = a dt^2, so its std
  // is sigma_a dt^2, dt from the frame times (no term when dt <= 0). Exclusive with
  // motion_prior_sigma_trans_m; the rotation stays free unless motion_prior_sigma_rot_deg > 0. A
  // car's acceleration rarely exceeds 1 g, and a weakly tracked frame, whose tracks leave its yaw
  // and sideways step trading against each other, is held to the last step; it does not hold the
  // rotation to the last rotation, whose error a rotation prior would repeat frame after frame.
  double motion_prior_sigma_accel_m_s2 = 7.0;  // m/s^2, [0, 1000]: 0 = off
  // Non-holonomic prior (docs/lateral_prior.md; MotionPriorResidual's lateral row): a wheeled
  // vehicle that does not skid steps sideways only as much as its own turn and the camera's lever
  // arm ahead of the rear axle imply. Each frame's sideways step is held to that with std
  //   hypot(lateral_prior_sigma_m_s dt, |t_z| mount_sigma, |psi| lateral_lever_sigma_m)
  // (t_z, psi: the frame's initial guess): the vehicle's own sideways velocity, a camera whose
  // axis is aligned with the vehicle's to within lateral_mount_sigma_deg, and a lever arm known to
  // within its std. The lever arm is the vehicle's geometry, measured on it like any extrinsic.
  // Off for a vehicle that moves sideways (crab or skid steering, a legged robot).
  double lateral_prior_sigma_m_s = 0.0;  // m/s, [0, 100]: 0 = off
  double lateral_lever_m = 0.0;          // m, [-10, 10]: the camera ahead of the rear axle
  double lateral_lever_sigma_m = 0.1;    // m, [0, 10]: the lever arm's std
  double lateral_mount_sigma_deg = 2.0;  // deg, [0, 45]: the camera axis against the vehicle's
  // Conditioning: the row only on frames none of whose tracks is nearer than this. A near track's
  // parallax separates the sideways step from the yaw, and there the row, whose model error is
  // correlated over hundreds of frames (docs/lateral_prior.md), would only add its bias.
  double lateral_prior_near_m = 0.0;  // m, [0, 1000]: 0 = the row on every frame
  // The direction of travel beta (the row's t_z slope, TravelDirection) as the median over the
  // last N solved steps long enough for the mount angle to show above the sideways velocity
  // (|t_z| >= lateral_prior_sigma_m_s dt / tan(lateral_mount_sigma_deg)); 0 = beta stays 0.
  // The row waits until beta is learnt (TravelDirection::ready(): 16 samples), so that the steps it
  // is learnt from are not pulled towards a slope of 0.
  int lateral_beta_frames = 200;  // steps, [0, TravelDirection::kMaxFrames]
  // The same prior in the camera's vertical plane (MotionPriorResidual's vertical row): a vehicle
  // on the road steps along its body axis as it pitches, t_y = gamma t_z - theta t_z / 2, with std
  //   hypot(vertical_prior_sigma_m_s dt, |t_z| mount_sigma)
  // (its own vertical velocity against the body: suspension, bumps; the mount as above). gamma,
  // the camera's pitch against the direction of travel, is learnt like beta over the last
  // vertical_gamma_frames steps (0 = gamma stays 0; the row waits for it as for beta). On by
  // default for a wheeled vehicle (with vertical_prior_near_m, docs/vertical_prior.md); set 0 for a
  // vehicle that leaves the ground.
  double vertical_prior_sigma_m_s = 0.1;  // m/s, [0, 100]: 0 = off
  int vertical_gamma_frames = 200;        // steps, [0, TravelDirection::kMaxFrames]
  // As lateral_prior_near_m, for the vertical step against the pitch.
  double vertical_prior_near_m = 8.0;  // m, [0, 1000]: 0 = the row on every frame
  // Zero-mean prior on each window frame's rotation relative to the previous window frame
  // (issue 15; RotationRatePriorResidual) along the pitch-like and roll-like directions
  // orthogonal to the vehicle's yaw axis: std = rate std x dt, dt from the frame times (no prior
  // when dt <= 0, dt taken as at least 1 ms). A ground vehicle's roll and pitch stay bounded;
  // typical passenger-car body rates in normal driving are a few deg/s (roll gradient 3-6 deg/g
  // with lateral jerk < 0.5 g/s; body modes at 1-1.5 Hz of 0.2-0.5 deg). It matters only on an axis
  // the tracks constrain weakly (tracks on one side of the image leave roll weak). The yaw axis in
  // the camera frame is the principal axis of the window's own per-frame rotations (turns dominate
  // it), exponentially forgotten, starting at and regularised towards the camera's y axis (a camera
  // looking along the direction of travel, x right, y down).
  bool rotation_rate_prior = true;      // on/off
  double rate_prior_pitch_deg_s = 2.0;  // deg/s, [0, 1000]: 0 = no prior on pitch
  double rate_prior_yaw_deg_s = 0.0;    // deg/s, [0, 1000]: 0 = none (turns are the motion)
  double rate_prior_roll_deg_s = 2.0;   // deg/s, [0, 1000]: 0 = no prior on roll
  // The stds above are for a car on a paved road. On rough ground the vehicle itself pitches and
  // rolls at 10+ deg/s and a 2 deg/s prior pulls every frame's true rotation towards 0: each
  // axis's std is raised to the robust spread of the window's own solved rates about it over the
  // last N frames (RateSpread: 1.4826 x median |rate|), never lowered below the value above.
  int rate_prior_adapt_frames = 50;  // count, [0, 256]: 0 = the fixed stds above
  // Yaw-axis estimate: memory tau spans a few turns of urban driving; the regulariser outweighs
  // what the body-rate wobble adds over tau on a straight road ((rate std x dt)^2 x tau / dt =
  // (0.2 deg)^2 x 200 frames = 8 deg^2 at 2 deg/s and 10 Hz < 9 deg^2), so a long straight
  // cannot tilt the axis, while one frame of a 3 deg/frame turn already weighs 9 deg^2.
  double yaw_axis_memory_s = 20.0;  // s, (0, 1e6]: time constant of the yaw-axis estimate
  double yaw_axis_prior_deg = 3.0;  // deg, (0, 180]: turning the camera's y axis counts as in the
                                    // yaw-axis estimate (its weight against observed turns)

  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("window_size", s.window_size);
    v("max_observations_per_frame", s.max_observations_per_frame);
    v("max_landmarks", s.max_landmarks);
    v("sigma_u_px", s.sigma_u_px);
    v("sigma_v_px", s.sigma_v_px);
    v("sigma_d_px", s.sigma_d_px);
    v("loss", s.loss);
    v("loss_scale", s.loss_scale);
    v("min_disparity_px", s.min_disparity_px);
    v("solver", s.solver);
    v("max_num_iterations", s.max_num_iterations);
    v("max_solver_time_in_seconds", s.max_solver_time_in_seconds);
    v("motion_prior_sigma_rot_deg", s.motion_prior_sigma_rot_deg);
    v("motion_prior_sigma_trans_m", s.motion_prior_sigma_trans_m);
    v("motion_prior_sigma_accel_m_s2", s.motion_prior_sigma_accel_m_s2);
    v("lateral_prior_sigma_m_s", s.lateral_prior_sigma_m_s);
    v("lateral_lever_m", s.lateral_lever_m);
    v("lateral_lever_sigma_m", s.lateral_lever_sigma_m);
    v("lateral_mount_sigma_deg", s.lateral_mount_sigma_deg);
    v("lateral_prior_near_m", s.lateral_prior_near_m);
    v("lateral_beta_frames", s.lateral_beta_frames);
    v("vertical_prior_sigma_m_s", s.vertical_prior_sigma_m_s);
    v("vertical_gamma_frames", s.vertical_gamma_frames);
    v("vertical_prior_near_m", s.vertical_prior_near_m);
    v("rotation_rate_prior", s.rotation_rate_prior);
    v("rate_prior_pitch_deg_s", s.rate_prior_pitch_deg_s);
    v("rate_prior_yaw_deg_s", s.rate_prior_yaw_deg_s);
    v("rate_prior_roll_deg_s", s.rate_prior_roll_deg_s);
    v("rate_prior_adapt_frames", s.rate_prior_adapt_frames);
    v("yaw_axis_memory_s", s.yaw_axis_memory_s);
    v("yaw_axis_prior_deg", s.yaw_axis_prior_deg);
  }
};

// One measurement of the window: landmark id and (u, v, d) in px.
struct WindowObservation {
  std::int64_t landmark_id = -1;
  StereoMeasurement y;
};

struct WindowSolveSummary {
  int num_landmarks = 0;
  int num_stereo_residuals = 0;
  int num_prior_residuals = 0;
  int num_rate_prior_residuals = 0;  // rotation-rate priors (WindowOptions::rotation_rate_prior)
  // Their stds along the pitch-like direction, the yaw axis and the roll-like direction, deg/s
  // (after WindowOptions::rate_prior_adapt_frames; 0 = no prior on that axis).
  std::array<double, 3> rate_prior_std_deg_s{0.0, 0.0, 0.0};
  int num_extra_residuals = 0;
  int iterations = 0;
  double solver_time_s = 0.0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;  // a tolerance was met (else the iteration or time limit ended it)
};

class BundleWindow {
 public:
  static constexpr int kMaxWindowSize = 8;

  BundleWindow();
  ~BundleWindow();
  BundleWindow(const BundleWindow&) = delete;
  BundleWindow& operator=(const BundleWindow&) = delete;

  Status init(const WindowOptions& options, const StereoCamera& camera);

  // Empties the window and makes the next addFrame() the base frame at world pose T_w_b.
  void reset(const Isometry3& T_w_b);

  // Appends a frame. T_k_km1_guess (initial guess, maps the previous newest frame into this one) is
  // ignored for the first frame after reset(). When the window is full the oldest frame leaves and
  // the next one becomes the base, its T_w_b chained from the current estimate.
  // Fails (kInvalidArgument) when observations exceed max_observations_per_frame.
  // motion_prior (optional): a predicted T_k_km1 used as a soft prior when the options enable it.
  Status addFrame(std::uint64_t sequence, TimeNs time_ns, std::span<const WindowObservation> obs,
                  const Isometry3& T_k_km1_guess, const Isometry3* motion_prior = nullptr);

  // Builds the problem from the current frames and solves it. On a solver failure or a non-finite
  // result the poses keep their initial guesses and an error is returned.
  Expected<WindowSolveSummary> solve();

  // Puts every pose back to the initial guess it had before the last solve() (e.g. when the
  // caller rejects the solution), and the yaw-axis estimate and the rate spread to what they were
  // before that solve.
  void restoreInitialGuess() {
    poses_ = saved_poses_;
    yaw_scatter_ = saved_yaw_scatter_;
    yaw_axis_c_ = saved_yaw_axis_c_;
    rate_spread_.undoLastPush();
    travel_x_.undoLastPush();
    travel_y_.undoLastPush();
  }

  int size() const { return size_; }
  const Isometry3& T_w_b() const { return T_w_b_; }
  // Pose of window slot i (0 = base = identity) relative to the base.
  Isometry3 T_k_b(int slot) const;
  Isometry3 T_w_newest() const;
  std::uint64_t sequence(int slot) const {
    return frames_[static_cast<std::size_t>(slot)].sequence;
  }
  TimeNs timeNs(int slot) const { return frames_[static_cast<std::size_t>(slot)].time_ns; }

  // Hook for one more residual type per pose; see the header comment.
  using PoseResidualHook = std::function<Status(BundleWindow& window)>;
  void setPoseResidualHook(PoseResidualHook hook) { hook_ = std::move(hook); }
  // Adds a residual on the rotation q_k_b (4 doubles, x y z w) of slot (1..size-1; the base is
  // fixed). Only valid from inside the hook. cost and loss (may be null) stay owned by the caller
  // and must live until the next solve().
  Status addPoseResidual(int slot, ceres::CostFunction* cost, ceres::LossFunction* loss);
  // As addPoseResidual, over the rotation of `slot` followed by caller-owned parameter blocks
  // (e.g. a correction of the base's world attitude), which must stay valid until the next
  // solve(). slot < 0: a residual on the caller's blocks alone (e.g. their prior).
  Status addResidual(int slot, ceres::CostFunction* cost, ceres::LossFunction* loss,
                     std::span<double* const> extra_blocks);

  // Called after a successful solve (not after a failed one), e.g. to apply a correction.
  using PostSolveHook = std::function<void(BundleWindow& window)>;
  void setPostSolveHook(PostSolveHook hook) { post_hook_ = std::move(hook); }
  // Rotates the base's world attitude about the base's own origin: C_w_b <- C_w_b * C_b_bnew.
  // Every world pose the window derives afterwards (newest pose, the next base) follows.
  void correctBaseAttitude(const Eigen::Matrix3d& C_b_bnew);
  // Turns the base's world pose about the world point p_w: C_w_b <- C_w_w' C_w_b,
  // p_w_b <- p_w + C_w_w' (p_w_b - p_w): a correction of everything VO built since it was at p_w
  // (e.g. a start attitude that was wrong).
  void turnWorldAbout(const Eigen::Matrix3d& C_w_wnew, const Eigen::Vector3d& p_w);

  const WindowOptions& options() const { return options_; }

  // The vehicle's yaw (turn) axis in the camera frame as estimated so far (unit, y >= 0); the
  // rotation-rate prior acts orthogonal to it. Kept across reset() (a property of the rig).
  const Eigen::Vector3d& yawAxis() const { return yaw_axis_c_; }
  // The direction of travel the non-holonomic row uses for the next frame, rad (0 until learnt;
  // lateral_beta_frames). Kept across reset() (a property of the rig).
  double lateralBeta() const { return travel_x_.beta(); }
  // The same for the vertical row's gamma (vertical_gamma_frames).
  double verticalGamma() const { return travel_y_.beta(); }

  // Time limit of the following solves, s: a real-time caller shrinks it when a frame is late.
  // Clamped to (0, options.max_solver_time_in_seconds]; a non-finite or non-positive value
  // restores the configured limit. init() also restores it.
  void setSolverTimeBudget(double seconds);
  double solverTimeBudget() const { return time_budget_s_; }

 private:
  struct Frame {
    std::uint64_t sequence = 0;
    TimeNs time_ns = 0;
    std::vector<WindowObservation> obs;  // capacity max_observations_per_frame
    int num_obs = 0;
    bool has_prior = false;
    MotionPriorData prior;             // relative to the previous slot
    RotationRatePriorData rate_prior;  // relative to the previous slot, set in solve()
  };
  struct PoseBlock {
    std::array<double, 4> q{0.0, 0.0, 0.0, 1.0};  // q_k_b, Eigen order x y z w
    std::array<double, 3> t{0.0, 0.0, 0.0};       // t_k_b, m
  };
  struct Entry {
    std::int64_t landmark_id;
    int slot;
    int obs;
  };

  void setPose(int slot, const Isometry3& T_k_b);
  Expected<WindowSolveSummary> solveSchur(WindowSolveSummary out);
  // Normalises the quaternions of slots 1..; false when a pose is not finite.
  bool normalizePoses();
  void clearResiduals();
  // Sets the rotation-rate priors' bases and weights from the frame times and the yaw axis.
  Status addRatePriors(WindowSolveSummary& out, bool use_ceres);
  // After a solve: the newest frame's step relative to the previous window frame (over dt_s > 0)
  // feeds the yaw-axis estimate and the rate spread (updateYawAxis, its rotation vector phi) and
  // the directions of travel (updateTravelDirection, its translation t and phi).
  void learnFromNewestStep();
  void updateYawAxis(double dt_s, const Eigen::Vector3d& phi);
  void updateTravelDirection(double dt_s, const Eigen::Vector3d& t, const Eigen::Vector3d& phi);
  // The non-holonomic rows of a frame dt_s after the previous one, observed as obs
  // (bundle_window_travel.cpp): their weights and learnt slopes into prior; false when neither
  // row is on.
  bool setTravelRows(double dt_s, const Isometry3& T_k_km1_guess,
                     std::span<const WindowObservation> obs, MotionPriorData& prior) const;

  WindowOptions options_;
  double time_budget_s_ = 0.0;  // limit of the next solve, (0, options_.max_solver_time_in_seconds]
  StereoCamera camera_;
  StereoModel model_;
  bool initialized_ = false;
  int size_ = 0;
  Isometry3 T_w_b_ = Isometry3::Identity();
  std::array<Frame, kMaxWindowSize> frames_;
  std::array<PoseBlock, kMaxWindowSize> poses_;
  std::array<PoseBlock, kMaxWindowSize> saved_poses_;
  std::vector<std::array<double, 3>> landmarks_;  // p_b, max_landmarks
  std::vector<Entry> entries_;                    // window_size * max_observations_per_frame
  std::vector<StereoMeasurement> measurements_;   // one per stereo cost function
  std::vector<std::unique_ptr<ceres::CostFunction>> cost_pool_;  // solver == kCeres only
  std::array<std::unique_ptr<ceres::CostFunction>, kMaxWindowSize> prior_pool_;
  std::array<std::unique_ptr<ceres::CostFunction>, kMaxWindowSize> rate_prior_pool_;
  std::vector<ceres::ResidualBlockId> residual_ids_;
  int num_residuals_ = 0;
  std::unique_ptr<ceres::LossFunction> loss_;
  std::unique_ptr<ceres::Manifold> quaternion_manifold_;
  std::unique_ptr<ceres::Problem> problem_;  // solver == kCeres only
  SchurLmSolver schur_;                      // solver == kSchurLm only
  PoseResidualHook hook_;
  PostSolveHook post_hook_;
  bool in_hook_ = false;
  Eigen::Matrix3d yaw_scatter_ = Eigen::Matrix3d::Zero();  // rad^2, sum of phi phi^T (forgotten)
  Eigen::Vector3d yaw_axis_c_ = Eigen::Vector3d::UnitY();
  Eigen::Matrix3d saved_yaw_scatter_ = Eigen::Matrix3d::Zero();  // before the last solve
  Eigen::Vector3d saved_yaw_axis_c_ = Eigen::Vector3d::UnitY();
  RateSpread rate_spread_;  // the solved rates about the prior's axes (rate_prior_adapt_frames)
  // The solved steps' direction of travel, x over z (lateral_beta_frames) and y over z
  // (vertical_gamma_frames).
  TravelDirection travel_x_;
  TravelDirection travel_y_;
  int num_extra_ = 0;
};

}  // namespace sunvo::backend
