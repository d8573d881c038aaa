#include "sunvo/vo/stereo_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <string>

namespace sunvo::vo {
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// splitmix64: decorrelates per-frame seeds.
std::uint64_t mixSeed(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

const char* toString(TrackingStatus s) {
  switch (s) {
    case TrackingStatus::kInitializing:
      return "initializing";
    case TrackingStatus::kTracking:
      return "tracking";
    case TrackingStatus::kLost:
      return "lost";
    case TrackingStatus::kRecovered:
      return "recovered";
  }
  return "?";
}

Status VoOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(ransac.validate());
  SUNVO_RETURN_IF_ERROR(window.validate());
  if (max_observations < 3) return invalidArgument("vo.max_observations must be >= 3");
  if (ransac.max_observations < max_observations) {
    return invalidArgument("ransac.max_observations must be >= vo.max_observations");
  }
  if (window.max_observations_per_frame < max_observations) {
    return invalidArgument("window.max_observations_per_frame must be >= vo.max_observations");
  }
  if (!(max_translation_per_frame_m > 0.0)) {
    return invalidArgument("vo.max_translation_per_frame_m must be > 0");
  }
  return Status::ok();
}

Status StereoOdometry::init(const VoOptions& options, const StereoCamera& camera,
                            const Isometry3& T_w_c0) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  if (!allFinite(T_w_c0)) return invalidArgument("vo: non-finite T_w_c0");
  options_ = options;
  camera_ = camera;
  SUNVO_RETURN_IF_ERROR(ransac_.init(options.ransac, camera));
  if (options.use_window) SUNVO_RETURN_IF_ERROR(window_.init(options.window, camera));
  const auto n = static_cast<std::size_t>(options.max_observations);
  prev_obs_.assign(n, StereoObservation{});
  prev_sorted_.assign(n, IdIndex{});
  matches_.assign(n, motion::StereoMatch{});
  match_cur_index_.assign(n, 0);
  window_obs_.assign(n, backend::WindowObservation{});
  prev_count_ = 0;
  T_w_c0_ = T_w_c0;
  T_w_prev_ = T_w_c0;
  last_motion_ = Isometry3::Identity();
  have_prev_ = false;
  lost_ = false;
  initialized_ = true;
  return Status::ok();
}

void StereoOdometry::rememberFrame(const FrameFeatures& frame) {
  prev_count_ = static_cast<int>(frame.observations.size());
  for (int i = 0; i < prev_count_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    prev_obs_[ui] = frame.observations[ui];
    prev_sorted_[ui] = IdIndex{frame.observations[ui].landmark_id, i};
  }
  std::sort(prev_sorted_.begin(), prev_sorted_.begin() + prev_count_,
            [](const IdIndex& a, const IdIndex& b) { return a.id < b.id; });
  have_prev_ = true;
}

// Restarts the window at this frame: every observation with positive disparity goes in.
static int baseObservations(const FrameFeatures& frame,
                            std::vector<backend::WindowObservation>& out) {
  int n = 0;
  for (const auto& o : frame.observations) {
    if (!(o.disparity() > 0.0)) continue;
    out[static_cast<std::size_t>(n++)] = {o.landmark_id, {o.u_left, o.v_left, o.disparity()}};
  }
  return n;
}

VoResult StereoOdometry::lose(const FrameFeatures& frame, VoResult r) {
  const Isometry3 motion =
      options_.constant_velocity_on_loss ? last_motion_ : Isometry3::Identity();
  r.T_k_km1 = motion;
  r.T_w_c = T_w_prev_ * motion.inverse();
  r.status = TrackingStatus::kLost;
  r.window_used = false;
  T_w_prev_ = r.T_w_c;
  if (options_.use_window) {
    window_.reset(r.T_w_c);
    const int n = baseObservations(frame, window_obs_);
    // Cannot fail: sizes were checked by process().
    (void)window_.addFrame(frame.sequence, frame.time_ns,
                           std::span(window_obs_.data(), static_cast<std::size_t>(n)),
                           Isometry3::Identity());
  }
  rememberFrame(frame);
  lost_ = true;
  return r;
}

Expected<VoResult> StereoOdometry::process(const FrameFeatures& frame) {
  if (!initialized_) return failedPrecondition("StereoOdometry::process before init");
  if (frame.observations.size() > static_cast<std::size_t>(options_.max_observations)) {
    return invalidArgument(
        "vo: frame " + std::to_string(frame.sequence) + " has " +
        std::to_string(frame.observations.size()) +
        " observations > vo.max_observations = " + std::to_string(options_.max_observations));
  }
  VoResult r;
  r.sequence = frame.sequence;
  r.time_ns = frame.time_ns;

  if (!have_prev_) {
    r.T_w_c = T_w_c0_;
    r.status = TrackingStatus::kInitializing;
    T_w_prev_ = T_w_c0_;
    if (options_.use_window) {
      window_.reset(T_w_c0_);
      const int n = baseObservations(frame, window_obs_);
      SUNVO_RETURN_IF_ERROR(window_.addFrame(
          frame.sequence, frame.time_ns, std::span(window_obs_.data(), static_cast<std::size_t>(n)),
          Isometry3::Identity()));
    }
    rememberFrame(frame);
    return r;
  }

  // Association with frame k-1 by landmark id (binary search in the sorted previous ids).
  const auto t_ransac = std::chrono::steady_clock::now();
  int n_matches = 0;
  const auto sorted_end = prev_sorted_.begin() + prev_count_;
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    const StereoObservation& o = frame.observations[i];
    const auto it = std::lower_bound(prev_sorted_.begin(), sorted_end, o.landmark_id,
                                     [](const IdIndex& a, std::int64_t id) { return a.id < id; });
    if (it == sorted_end || it->id != o.landmark_id) continue;
    const StereoObservation& p = prev_obs_[static_cast<std::size_t>(it->index)];
    const auto m = static_cast<std::size_t>(n_matches++);
    matches_[m] = {p.u_left, p.v_left, p.u_right, o.u_left, o.v_left, o.u_right};
    match_cur_index_[m] = static_cast<int>(i);
  }
  r.num_matches = n_matches;
  auto est = ransac_.estimate(std::span(matches_.data(), static_cast<std::size_t>(n_matches)),
                              mixSeed(options_.seed ^ frame.sequence));
  r.ransac_ms = msSince(t_ransac);
  if (!est || est->T_k_km1.translation().norm() > options_.max_translation_per_frame_m) {
    return lose(frame, r);
  }
  r.ransac_inliers = est->num_inliers;
  r.T_k_km1 = est->T_k_km1;
  Isometry3 T_w_k = T_w_prev_ * est->T_k_km1.inverse();

  if (options_.use_window) {
    const auto t_window = std::chrono::steady_clock::now();
    // Window observations of frame k: RANSAC inliers among the matched, plus every unmatched
    // observation with positive disparity (new landmarks for the next windows).
    std::fill(window_obs_.begin(),
              window_obs_.begin() + static_cast<std::ptrdiff_t>(frame.observations.size()),
              backend::WindowObservation{});
    int n = 0;
    int m = 0;
    for (std::size_t i = 0; i < frame.observations.size(); ++i) {
      const StereoObservation& o = frame.observations[i];
      bool matched = false;
      bool inlier = false;
      if (m < n_matches && match_cur_index_[static_cast<std::size_t>(m)] == static_cast<int>(i)) {
        matched = true;
        inlier = est->inlier_mask[static_cast<std::size_t>(m)] != 0;
        ++m;
      }
      if (matched ? !inlier : !(o.disparity() > 0.0)) continue;
      window_obs_[static_cast<std::size_t>(n++)] = {o.landmark_id,
                                                    {o.u_left, o.v_left, o.disparity()}};
    }
    SUNVO_RETURN_IF_ERROR(
        window_.addFrame(frame.sequence, frame.time_ns,
                         std::span(window_obs_.data(), static_cast<std::size_t>(n)), est->T_k_km1));
    auto sol = window_.solve();
    if (sol) {
      const Isometry3 T_w_new = window_.T_w_newest();
      const Isometry3 motion = T_w_new.inverse() * T_w_prev_;
      if (allFinite(T_w_new) &&
          motion.translation().norm() <= options_.max_translation_per_frame_m) {
        T_w_k = T_w_new;
        r.window_used = true;
      } else {
        window_.restoreInitialGuess();
      }
      r.window_landmarks = sol->num_landmarks;
      r.window_residuals = sol->num_stereo_residuals;
      r.solver_iterations = sol->iterations;
      r.solver_time_s = sol->solver_time_s;
    }
    if (!r.window_used) T_w_k = window_.T_w_newest();  // the RANSAC guess chained in the window
    r.window_ms = msSince(t_window);
  }
  if (!allFinite(T_w_k)) return lose(frame, r);

  r.T_k_km1 = T_w_k.inverse() * T_w_prev_;
  r.T_w_c = T_w_k;
  r.status = lost_ ? TrackingStatus::kRecovered : TrackingStatus::kTracking;
  lost_ = false;
  last_motion_ = r.T_k_km1;
  T_w_prev_ = T_w_k;
  rememberFrame(frame);
  return r;
}

}  // namespace sunvo::vo
