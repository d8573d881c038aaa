#include "sunvo/backend/bundle_window.hpp"

#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

namespace sunvo::backend {

Status WindowOptions::validate() const {
  if (window_size < 2 || window_size > BundleWindow::kMaxWindowSize) {
    return invalidArgument("window.window_size must be in [2, " +
                           std::to_string(BundleWindow::kMaxWindowSize) + "]");
  }
  if (max_observations_per_frame < 3) {
    return invalidArgument("window.max_observations_per_frame must be >= 3");
  }
  if (max_landmarks < 3) return invalidArgument("window.max_landmarks must be >= 3");
  if (!(sigma_u_px > 0.0)) return invalidArgument("window.sigma_u_px must be > 0");
  if (!(sigma_v_px > 0.0)) return invalidArgument("window.sigma_v_px must be > 0");
  if (!(sigma_d_px > 0.0)) return invalidArgument("window.sigma_d_px must be > 0");
  if (!(loss_scale > 0.0)) return invalidArgument("window.loss_scale must be > 0");
  if (!(min_disparity_px > 0.0)) return invalidArgument("window.min_disparity_px must be > 0");
  if (max_num_iterations < 1 || max_num_iterations > 1000) {
    return invalidArgument("window.max_num_iterations must be in [1, 1000]");
  }
  if (!(max_solver_time_in_seconds > 0.0)) {
    return invalidArgument("window.max_solver_time_in_seconds must be > 0");
  }
  if (!(motion_prior_sigma_rot_deg >= 0.0)) {
    return invalidArgument("window.motion_prior_sigma_rot_deg must be >= 0");
  }
  if (!(motion_prior_sigma_trans_m >= 0.0)) {
    return invalidArgument("window.motion_prior_sigma_trans_m must be >= 0");
  }
  // Keys with a closed range; NaN fails every comparison and is refused too.
  for (const auto& [key, value, lo, hi, range] :
       {std::tuple{"motion_prior_sigma_accel_m_s2", motion_prior_sigma_accel_m_s2, 0.0, 1000.0,
                   "[0, 1000]"},
        std::tuple{"lateral_prior_sigma_m_s", lateral_prior_sigma_m_s, 0.0, 100.0, "[0, 100]"},
        std::tuple{"lateral_lever_m", lateral_lever_m, -10.0, 10.0, "[-10, 10]"},
        std::tuple{"lateral_lever_sigma_m", lateral_lever_sigma_m, 0.0, 10.0, "[0, 10]"},
        std::tuple{"lateral_mount_sigma_deg", lateral_mount_sigma_deg, 0.0, 45.0, "[0, 45]"},
        std::tuple{"vertical_prior_sigma_m_s", vertical_prior_sigma_m_s, 0.0, 100.0, "[0, 100]"},
        std::tuple{"lateral_prior_near_m", lateral_prior_near_m, 0.0, 1000.0, "[0, 1000]"},
        std::tuple{"vertical_prior_near_m", vertical_prior_near_m, 0.0, 1000.0, "[0, 1000]"},
        std::tuple{"rate_prior_pitch_deg_s", rate_prior_pitch_deg_s, 0.0, 1000.0, "[0, 1000]"},
        std::tuple{"rate_prior_yaw_deg_s", rate_prior_yaw_deg_s, 0.0, 1000.0, "[0, 1000]"},
        std::tuple{"rate_prior_roll_deg_s", rate_prior_roll_deg_s, 0.0, 1000.0, "[0, 1000]"}}) {
    if (!(value >= lo && value <= hi)) {
      return invalidArgument(std::string("window.") + key + " must be in " + range);
    }
  }
  if (motion_prior_sigma_trans_m > 0.0 && motion_prior_sigma_accel_m_s2 > 0.0) {
    return invalidArgument(
        "window.motion_prior_sigma_trans_m and window.motion_prior_sigma_accel_m_s2 are two forms "
        "of one std: set one of them to 0");
  }
  for (const auto& [key, frames] : {std::pair{"lateral_beta_frames", lateral_beta_frames},
                                    std::pair{"vertical_gamma_frames", vertical_gamma_frames}}) {
    if (frames < 0 || frames > TravelDirection::kMaxFrames) {
      return invalidArgument(std::string("window.") + key + " must be in [0, " +
                             std::to_string(TravelDirection::kMaxFrames) + "]");
    }
  }
  if (rate_prior_adapt_frames < 0 || rate_prior_adapt_frames > RateSpread::kMaxFrames) {
    return invalidArgument("window.rate_prior_adapt_frames must be in [0, " +
                           std::to_string(RateSpread::kMaxFrames) + "]");
  }
  if (!(yaw_axis_memory_s > 0.0 && yaw_axis_memory_s <= 1e6)) {
    return invalidArgument("window.yaw_axis_memory_s must be in (0, 1e6]");
  }
  if (!(yaw_axis_prior_deg > 0.0 && yaw_axis_prior_deg <= 180.0)) {
    return invalidArgument("window.yaw_axis_prior_deg must be in (0, 180]");
  }
  return Status::ok();
}

BundleWindow::BundleWindow() = default;

BundleWindow::~BundleWindow() {
  // The problem refers to the pools; destroy it first.
  problem_.reset();
}

Status BundleWindow::init(const WindowOptions& options, const StereoCamera& camera) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  problem_.reset();
  options_ = options;
  time_budget_s_ = options.max_solver_time_in_seconds;
  camera_ = camera;
  model_.fu = camera.fu;
  model_.fv = camera.fv;
  model_.cu = camera.cu;
  model_.cv = camera.cv;
  model_.baseline_m = camera.baseline_m;
  model_.sqrt_info_u = 1.0 / options.sigma_u_px;
  model_.sqrt_info_v = 1.0 / options.sigma_v_px;
  model_.sqrt_info_d = 1.0 / options.sigma_d_px;

  const auto n_obs = static_cast<std::size_t>(options.max_observations_per_frame);
  const auto n_pool = static_cast<std::size_t>(options.window_size) * n_obs;
  for (auto& f : frames_) {
    f.obs.assign(n_obs, WindowObservation{});
    f.num_obs = 0;
  }
  landmarks_.assign(static_cast<std::size_t>(options.max_landmarks), {0.0, 0.0, 1.0});
  entries_.assign(n_pool, Entry{});
  measurements_.assign(n_pool, StereoMeasurement{});
  cost_pool_.clear();
  for (std::size_t s = 0; s < frames_.size(); ++s) {
    frames_[s].has_prior = false;
    prior_pool_[s].reset(MotionPriorResidual::Create(&frames_[s].prior));
    rate_prior_pool_[s].reset(RotationRatePriorResidual::Create(&frames_[s].rate_prior));
  }
  residual_ids_.assign(n_pool + 10 * kMaxWindowSize, nullptr);
  yaw_axis_c_ = Eigen::Vector3d::UnitY();
  const double w0 = options.yaw_axis_prior_deg * M_PI / 180.0;
  yaw_scatter_ = w0 * w0 * yaw_axis_c_ * yaw_axis_c_.transpose();
  saved_yaw_scatter_ = yaw_scatter_;
  saved_yaw_axis_c_ = yaw_axis_c_;
  rate_spread_.setCapacity(options.rate_prior_adapt_frames);
  travel_x_.setCapacity(options.lateral_prior_sigma_m_s > 0.0 ? options.lateral_beta_frames : 0);
  travel_y_.setCapacity(options.vertical_prior_sigma_m_s > 0.0 ? options.vertical_gamma_frames : 0);
  num_residuals_ = 0;

  switch (options.loss) {
    case RobustLoss::kNone:
      loss_.reset();
      break;
    case RobustLoss::kHuber:
      loss_ = std::make_unique<ceres::HuberLoss>(options.loss_scale);
      break;
    case RobustLoss::kCauchy:
      loss_ = std::make_unique<ceres::CauchyLoss>(options.loss_scale);
      break;
  }

  if (options.solver == WindowSolver::kSchurLm) {
    // The stereo residuals are evaluated in closed form from measurements_: no cost functions.
    const int max_generic = static_cast<int>(residual_ids_.size()) - static_cast<int>(n_pool);
    SUNVO_RETURN_IF_ERROR(
        schur_.init(static_cast<int>(n_pool), options.max_landmarks, max_generic));
    schur_.setStereoModel(&model_);
    initialized_ = true;
    reset(Isometry3::Identity());
    return Status::ok();
  }
  // Ceres: one autodiff stereo cost function per measurement slot, the manifold, the problem.
  cost_pool_.reserve(n_pool);
  for (std::size_t i = 0; i < n_pool; ++i) {
    cost_pool_.emplace_back(StereoResidual::Create(&measurements_[i], &model_));
  }
  quaternion_manifold_ = std::make_unique<ceres::EigenQuaternionManifold>();
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(po);
  for (int s = 0; s < options.window_size; ++s) {
    PoseBlock& p = poses_[static_cast<std::size_t>(s)];
    p = PoseBlock{};
    problem_->AddParameterBlock(p.q.data(), 4, quaternion_manifold_.get());
    problem_->AddParameterBlock(p.t.data(), 3);
  }
  // The base pose is the gauge: identity, fixed.
  problem_->SetParameterBlockConstant(poses_[0].q.data());
  problem_->SetParameterBlockConstant(poses_[0].t.data());
  for (auto& l : landmarks_) problem_->AddParameterBlock(l.data(), 3);
  initialized_ = true;
  reset(Isometry3::Identity());
  return Status::ok();
}

void BundleWindow::reset(const Isometry3& T_w_b) {
  T_w_b_ = T_w_b;
  size_ = 0;
  for (auto& p : poses_) p = PoseBlock{};
}

void BundleWindow::setSolverTimeBudget(double seconds) {
  const double configured = options_.max_solver_time_in_seconds;
  time_budget_s_ =
      std::isfinite(seconds) && seconds > 0.0 ? std::min(seconds, configured) : configured;
}

void BundleWindow::setPose(int slot, const Isometry3& T_k_b) {
  PoseBlock& p = poses_[static_cast<std::size_t>(slot)];
  const Eigen::Quaterniond q(T_k_b.linear());
  p.q = {q.x(), q.y(), q.z(), q.w()};
  p.t = {T_k_b.translation().x(), T_k_b.translation().y(), T_k_b.translation().z()};
}

Isometry3 BundleWindow::T_k_b(int slot) const {
  const PoseBlock& p = poses_[static_cast<std::size_t>(slot)];
  Isometry3 T = Isometry3::Identity();
  T.linear() = Eigen::Quaterniond(p.q[3], p.q[0], p.q[1], p.q[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.t[0], p.t[1], p.t[2]);
  return T;
}

Isometry3 BundleWindow::T_w_newest() const {
  if (size_ == 0) return T_w_b_;
  return T_w_b_ * T_k_b(size_ - 1).inverse();
}

Status BundleWindow::addFrame(std::uint64_t sequence, TimeNs time_ns,
                              std::span<const WindowObservation> obs,
                              const Isometry3& T_k_km1_guess, const Isometry3* motion_prior) {
  if (!initialized_) return failedPrecondition("BundleWindow::addFrame before init");
  if (obs.size() > static_cast<std::size_t>(options_.max_observations_per_frame)) {
    return invalidArgument("window: " + std::to_string(obs.size()) +
                           " observations exceed window.max_observations_per_frame = " +
                           std::to_string(options_.max_observations_per_frame));
  }
  if (!allFinite(T_k_km1_guess)) return invalidArgument("window: non-finite T_k_km1_guess");
  Isometry3 T_new_b = Isometry3::Identity();
  if (size_ > 0) T_new_b = T_k_km1_guess * T_k_b(size_ - 1);
  if (size_ == options_.window_size) {
    // Slide: slot 1 becomes the base b'. T_w_b' = T_w_b T_b_b' = T_w_b T_1_b^-1 and every pose is
    // re-expressed as T_i_b' = T_i_b T_b_b'.
    const Isometry3 T_b_bnew = T_k_b(1).inverse();
    T_w_b_ = T_w_b_ * T_b_bnew;
    T_new_b = T_new_b * T_b_bnew;
    for (int i = 1; i < size_; ++i) {
      const Isometry3 T_i_bnew = T_k_b(i) * T_b_bnew;
      std::swap(frames_[static_cast<std::size_t>(i - 1)], frames_[static_cast<std::size_t>(i)]);
      if (i - 1 > 0) setPose(i - 1, T_i_bnew);
    }
    poses_[0] = PoseBlock{};
    --size_;
  }
  const int slot = size_;
  Frame& f = frames_[static_cast<std::size_t>(slot)];
  f.sequence = sequence;
  f.time_ns = time_ns;
  std::copy(obs.begin(), obs.end(), f.obs.begin());
  f.num_obs = static_cast<int>(obs.size());
  // The translation std: per frame, or from the acceleration std over this frame's interval.
  const double dt = slot > 0
                        ? 1e-9 * static_cast<double>(
                                     time_ns - frames_[static_cast<std::size_t>(slot - 1)].time_ns)
                        : 0.0;
  double s_trans = options_.motion_prior_sigma_trans_m;
  if (slot > 0 && options_.motion_prior_sigma_accel_m_s2 > 0.0) {
    s_trans = dt > 0.0 ? options_.motion_prior_sigma_accel_m_s2 * dt * dt : 0.0;
  }
  const bool predicted = slot > 0 && motion_prior != nullptr &&
                         (options_.motion_prior_sigma_rot_deg > 0.0 || s_trans > 0.0) &&
                         allFinite(*motion_prior);
  f.prior = MotionPriorData{};
  const bool travel = slot > 0 && setTravelRows(dt, T_k_km1_guess, obs, f.prior);
  f.has_prior = predicted || travel;
  if (predicted) {
    const Eigen::Quaterniond q(motion_prior->linear());
    f.prior.q_pred[0] = q.x();
    f.prior.q_pred[1] = q.y();
    f.prior.q_pred[2] = q.z();
    f.prior.q_pred[3] = q.w();
    for (int i = 0; i < 3; ++i) f.prior.t_pred[i] = motion_prior->translation()[i];
  }
  // A std of 0 leaves that part of the motion free (its rows weigh nothing).
  const double s_rot = options_.motion_prior_sigma_rot_deg * M_PI / 180.0;
  f.prior.sqrt_info_rot = predicted && s_rot > 0.0 ? 1.0 / s_rot : 0.0;
  f.prior.sqrt_info_trans = predicted && s_trans > 0.0 ? 1.0 / s_trans : 0.0;
  if (slot == 0) {
    poses_[0] = PoseBlock{};
  } else {
    setPose(slot, T_new_b);
  }
  ++size_;
  return Status::ok();
}

void BundleWindow::clearResiduals() {
  num_extra_ = 0;
  if (!problem_) {
    num_residuals_ = 0;
    return;
  }
  for (int i = 0; i < num_residuals_; ++i) {
    problem_->RemoveResidualBlock(residual_ids_[static_cast<std::size_t>(i)]);
  }
  num_residuals_ = 0;
  num_extra_ = 0;
}

Status BundleWindow::addPoseResidual(int slot, ceres::CostFunction* cost,
                                     ceres::LossFunction* loss) {
  if (!in_hook_) return failedPrecondition("window: addPoseResidual outside the pose hook");
  if (slot < 1 || slot >= size_) {
    return invalidArgument("window: addPoseResidual slot " + std::to_string(slot) + " not in [1, " +
                           std::to_string(size_) + ")");
  }
  if (cost == nullptr || cost->parameter_block_sizes().size() != 1 ||
      cost->parameter_block_sizes()[0] != 4) {
    return invalidArgument("window: a pose residual takes exactly one block, q_k_b (4)");
  }
  if (num_residuals_ >= static_cast<int>(residual_ids_.size())) {
    return invalidArgument("window: too many extra pose residuals");
  }
  if (!problem_) {
    const SchurLmSolver::BlockRef block{SchurLmSolver::BlockRef::Kind::kRotation, slot, nullptr};
    SUNVO_RETURN_IF_ERROR(schur_.addGeneric(cost, loss, {&block, 1}));
    ++num_residuals_;
    ++num_extra_;
    return Status::ok();
  }
  residual_ids_[static_cast<std::size_t>(num_residuals_++)] =
      problem_->AddResidualBlock(cost, loss, poses_[static_cast<std::size_t>(slot)].q.data());
  ++num_extra_;
  return Status::ok();
}

Status BundleWindow::addResidual(int slot, ceres::CostFunction* cost, ceres::LossFunction* loss,
                                 std::span<double* const> extra_blocks) {
  if (!in_hook_) return failedPrecondition("window: addResidual outside the pose hook");
  if (slot >= size_ || slot == 0) {
    return invalidArgument("window: addResidual slot " + std::to_string(slot) + " not in [1, " +
                           std::to_string(size_) + ") or < 0");
  }
  const std::size_t n_blocks = extra_blocks.size() + (slot > 0 ? 1u : 0u);
  if (cost == nullptr || cost->parameter_block_sizes().size() != n_blocks || n_blocks == 0 ||
      n_blocks > 4 || (slot > 0 && cost->parameter_block_sizes()[0] != 4)) {
    return invalidArgument("window: addResidual blocks do not match the cost function");
  }
  if (num_residuals_ >= static_cast<int>(residual_ids_.size())) {
    return invalidArgument("window: too many extra residuals");
  }
  if (!problem_) {
    std::array<SchurLmSolver::BlockRef, 4> refs{};
    std::size_t k = 0;
    if (slot > 0) refs[k++] = {SchurLmSolver::BlockRef::Kind::kRotation, slot, nullptr};
    for (double* b : extra_blocks) refs[k++] = {SchurLmSolver::BlockRef::Kind::kExtra, 0, b};
    SUNVO_RETURN_IF_ERROR(schur_.addGeneric(cost, loss, {refs.data(), k}));
    ++num_residuals_;
    ++num_extra_;
    return Status::ok();
  }
  std::array<double*, 4> blocks{};
  std::size_t i = 0;
  if (slot > 0) blocks[i++] = poses_[static_cast<std::size_t>(slot)].q.data();
  for (double* b : extra_blocks) blocks[i++] = b;
  residual_ids_[static_cast<std::size_t>(num_residuals_++)] =
      problem_->AddResidualBlock(cost, loss, blocks.data(), static_cast<int>(n_blocks));
  ++num_extra_;
  return Status::ok();
}

void BundleWindow::correctBaseAttitude(const Eigen::Matrix3d& C_b_bnew) {
  T_w_b_.linear() = orthonormalize(T_w_b_.linear() * C_b_bnew);
}

void BundleWindow::turnWorldAbout(const Eigen::Matrix3d& C_w_wnew, const Eigen::Vector3d& p_w) {
  T_w_b_.translation() = p_w + C_w_wnew * (T_w_b_.translation() - p_w);
  T_w_b_.linear() = orthonormalize(C_w_wnew * T_w_b_.linear());
}

Expected<WindowSolveSummary> BundleWindow::solve() {
  if (!initialized_) return failedPrecondition("BundleWindow::solve before init");
  if (size_ < 2) return failedPrecondition("window: solve needs at least 2 frames");
  clearResiduals();

  // Gather (landmark, slot, observation) entries and group them by landmark.
  int n_entries = 0;
  for (int s = 0; s < size_; ++s) {
    const Frame& f = frames_[static_cast<std::size_t>(s)];
    for (int i = 0; i < f.num_obs; ++i) {
      entries_[static_cast<std::size_t>(n_entries++)] =
          Entry{f.obs[static_cast<std::size_t>(i)].landmark_id, s, i};
    }
  }
  const auto begin = entries_.begin();
  const auto end = begin + n_entries;
  std::sort(begin, end, [](const Entry& a, const Entry& b) {
    return a.landmark_id != b.landmark_id ? a.landmark_id < b.landmark_id : a.slot < b.slot;
  });

  WindowSolveSummary out;
  const bool use_ceres = problem_ != nullptr;
  if (!use_ceres) {
    std::array<double*, kMaxWindowSize> q{};
    std::array<double*, kMaxWindowSize> t{};
    for (int s = 0; s < size_; ++s) {
      q[static_cast<std::size_t>(s)] = poses_[static_cast<std::size_t>(s)].q.data();
      t[static_cast<std::size_t>(s)] = poses_[static_cast<std::size_t>(s)].t.data();
    }
    SUNVO_RETURN_IF_ERROR(schur_.begin(size_, q, t));
  }
  int n_landmarks = 0;
  int n_stereo = 0;
  for (auto g = begin; g != end;) {
    auto g_end = g;
    while (g_end != end && g_end->landmark_id == g->landmark_id) ++g_end;
    // Number of distinct frames (entries are sorted by slot within a landmark); a duplicated id
    // within one frame does not count as a second view.
    int count = 0;
    for (auto e = g; e != g_end; ++e) {
      if (e == g || e->slot != (e - 1)->slot) ++count;
    }
    if (count >= 2 && n_landmarks < options_.max_landmarks) {
      // Initialise p_b from the first observation with enough disparity: p_j from Eq. 1 inverted,
      // p_b = T_j_b^-1 p_j.
      bool have = false;
      Eigen::Vector3d p_b = Eigen::Vector3d::Zero();
      for (auto e = g; e != g_end; ++e) {
        const StereoMeasurement& y =
            frames_[static_cast<std::size_t>(e->slot)].obs[static_cast<std::size_t>(e->obs)].y;
        if (y.d >= options_.min_disparity_px) {
          p_b = T_k_b(e->slot).inverse() * camera_.triangulate(y.u, y.v, y.d);
          have = p_b.allFinite();
          break;
        }
      }
      if (have) {
        auto& l = landmarks_[static_cast<std::size_t>(n_landmarks++)];
        l = {p_b.x(), p_b.y(), p_b.z()};
        if (!use_ceres) SUNVO_RETURN_IF_ERROR(schur_.addLandmark(l.data()));
        for (auto e = g; e != g_end; ++e) {
          const auto r = static_cast<std::size_t>(n_stereo++);
          measurements_[r] =
              frames_[static_cast<std::size_t>(e->slot)].obs[static_cast<std::size_t>(e->obs)].y;
          if (!use_ceres) {
            SUNVO_RETURN_IF_ERROR(schur_.addStereo(e->slot, &measurements_[r], loss_.get()));
            continue;
          }
          PoseBlock& p = poses_[static_cast<std::size_t>(e->slot)];
          residual_ids_[static_cast<std::size_t>(num_residuals_++)] = problem_->AddResidualBlock(
              cost_pool_[r].get(), loss_.get(), p.q.data(), p.t.data(), l.data());
        }
      }
    }
    g = g_end;
  }
  out.num_landmarks = n_landmarks;
  out.num_stereo_residuals = n_stereo;
  if (n_landmarks < 3) {
    return failedPrecondition("window: only " + std::to_string(n_landmarks) +
                              " landmarks seen in two or more frames");
  }

  // Motion priors between consecutive slots (the base frame's own prior refers to a frame that
  // has left the window and is skipped).
  for (int s = 1; s < size_; ++s) {
    const auto us = static_cast<std::size_t>(s);
    if (!frames_[us].has_prior) continue;
    ++out.num_prior_residuals;
    if (!use_ceres) {
      using Kind = SchurLmSolver::BlockRef::Kind;
      const SchurLmSolver::BlockRef refs[] = {{Kind::kRotation, s - 1, nullptr},
                                              {Kind::kTranslation, s - 1, nullptr},
                                              {Kind::kRotation, s, nullptr},
                                              {Kind::kTranslation, s, nullptr}};
      SUNVO_RETURN_IF_ERROR(schur_.addGeneric(prior_pool_[us].get(), nullptr, refs));
      ++num_residuals_;
      continue;
    }
    residual_ids_[static_cast<std::size_t>(num_residuals_++)] = problem_->AddResidualBlock(
        prior_pool_[us].get(), nullptr, poses_[us - 1].q.data(), poses_[us - 1].t.data(),
        poses_[us].q.data(), poses_[us].t.data());
  }

  if (options_.rotation_rate_prior) SUNVO_RETURN_IF_ERROR(addRatePriors(out, use_ceres));

  saved_poses_ = poses_;
  saved_yaw_scatter_ = yaw_scatter_;
  saved_yaw_axis_c_ = yaw_axis_c_;
  rate_spread_.commit();
  travel_x_.commit();
  travel_y_.commit();
  if (hook_) {
    in_hook_ = true;
    const Status s = hook_(*this);
    in_hook_ = false;
    if (!s.isOk()) return s;
  }
  out.num_extra_residuals = num_extra_;

  if (!use_ceres) return solveSchur(out);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.num_threads = 1;
  so.max_num_iterations = options_.max_num_iterations;
  so.max_solver_time_in_seconds = time_budget_s_;
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem_.get(), &summary);

  const bool finite = normalizePoses();
  if (!summary.IsSolutionUsable() || !finite) {
    poses_ = saved_poses_;
    return failedPrecondition("window: solver result unusable: " + summary.message);
  }
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.solver_time_s = summary.total_time_in_seconds;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  learnFromNewestStep();
  if (post_hook_) post_hook_(*this);
  return out;
}

Expected<WindowSolveSummary> BundleWindow::solveSchur(WindowSolveSummary out) {
  SchurLmSolver::Options so;
  so.max_iterations = options_.max_num_iterations;
  so.max_time_s = time_budget_s_;
  const Expected<SchurLmSummary> r = schur_.solve(so);
  if (!r.hasValue() || !normalizePoses()) {
    poses_ = saved_poses_;
    return failedPrecondition(std::string("window: solver result unusable") +
                              (r.hasValue() ? "" : ": " + r.status().message()));
  }
  out.iterations = r->iterations;
  out.solver_time_s = r->time_s;
  out.initial_cost = r->initial_cost;
  out.final_cost = r->final_cost;
  out.converged = r->converged;
  learnFromNewestStep();
  if (post_hook_) post_hook_(*this);
  return out;
}

void BundleWindow::learnFromNewestStep() {
  if (size_ < 2) return;
  const auto k = static_cast<std::size_t>(size_ - 1);
  const double dt_s = static_cast<double>(frames_[k].time_ns - frames_[k - 1].time_ns) * 1e-9;
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  const Isometry3 T_k_km1 = T_k_b(size_ - 1) * T_k_b(size_ - 2).inverse();
  const Eigen::Vector3d phi = logSO3(T_k_km1.linear());
  updateYawAxis(dt_s, phi);
  updateTravelDirection(dt_s, T_k_km1.translation(), phi);
}

bool BundleWindow::normalizePoses() {
  for (int s = 1; s < size_; ++s) {
    PoseBlock& p = poses_[static_cast<std::size_t>(s)];
    Eigen::Map<Eigen::Quaterniond> q(p.q.data());
    const double n = q.norm();
    if (!std::isfinite(n) || n < 1e-6 || !std::isfinite(p.t[0]) || !std::isfinite(p.t[1]) ||
        !std::isfinite(p.t[2])) {
      return false;
    }
    q.normalize();
  }
  return true;
}

}  // namespace sunvo::backend
