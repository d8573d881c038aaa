#pragma once
// What the four thread stages of sunvo_rover share: the messages that travel between them, the
// rings and their wake-up counts, the stop flags, the health counters, and the attitude mailbox
// from the estimator to the sun thread. Everything is sized in RoverApp::create(); nothing grows.

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cstdint>

#include "sunvo/core/time.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/pose_link.hpp"
#include "sunvo/runtime/event_count.hpp"
#include "sunvo/runtime/spsc_queue.hpp"

namespace sunvo::rover {

inline constexpr std::uint32_t kNoImage = 0xFFFFFFFFu;

// capture -> estimator: a filled frame-pool slot.
struct FrameTicket {
  std::uint32_t slot = 0;
  std::uint64_t sequence = 0;
};

// capture -> sun: a sun frame (or a frame of the vertical cue), with its copy in the sun pool
// when the provider or the cue needs images.
struct SunRequest {
  std::uint64_t sequence = 0;
  std::int64_t source_index = 0;
  TimeNs utc_ns = 0;
  std::uint32_t image_slot = kNoImage;  // slot of the sun image pool, or kNoImage
};

// sun -> estimator (plain arrays: it travels through an SPSC ring).
struct SunResult {
  std::uint64_t sequence = 0;
  TimeNs utc_ns = 0;
  bool has_measurement = false;
  bool azimuth_only = false;
  double sun_c[3] = {0, 0, 1};
  double sigma = 0.1;
  double sun_w[3] = {0, 0, 1};
  // The vertical cue (estimator.vertical.enabled): "up" in the camera and its sigma, rad (the
  // worse tangent direction's; up_sigma_strong along up_strong_axis_c, the better one's).
  bool has_up = false;
  double up_c[3] = {0, -1, 0};
  double up_sigma = 0.01;
  double up_sigma_strong = 0.0;
  double up_strong_axis_c[3] = {0, 0, 0};
};

// Counters of everything that can go wrong or be late, written by the stages, read by summary().
struct Health {
  std::atomic<std::uint64_t> triggers{0};
  std::atomic<std::uint64_t> trigger_timeouts{0};
  std::atomic<std::uint64_t> triggers_missed{0};
  std::atomic<std::uint64_t> triggers_duplicate{0};
  std::atomic<std::uint64_t> frames_grabbed{0};
  std::atomic<std::uint64_t> grab_errors{0};  // frames dropped: the source gave none or a bad one
  std::atomic<std::uint64_t> grab_errors_in_a_row_max{0};
  // Capture stopped: more than source.max_consecutive_bad_frames failed grabs in a row.
  std::atomic<bool> source_fault_stop{false};
  std::atomic<std::uint64_t> pool_exhausted{0};
  std::atomic<std::uint64_t> frames_processed{0};
  std::atomic<std::uint64_t> frames_dropped_at_stop{0};
  std::atomic<std::uint64_t> estimator_errors{0};
  std::atomic<std::uint64_t> late_frames{0};  // dequeued more than one period after the trigger
  std::atomic<std::uint64_t> shrunk_budgets{0};
  std::atomic<std::uint64_t> tracking_losses{0};
  std::atomic<std::uint64_t> recoveries{0};
  std::atomic<std::uint64_t> lost_frames{0};
  // estimator.self_calibration: the right camera's estimated pitch and roll (microradians, the
  // last frame's) and the resets of a diverged estimate.
  std::atomic<std::int64_t> self_cal_pitch_urad{0};
  std::atomic<std::int64_t> self_cal_roll_urad{0};
  std::atomic<std::uint64_t> self_cal_resets{0};
  std::atomic<std::uint64_t> sun_requests{0};
  std::atomic<std::uint64_t> sun_measurements{0};
  std::atomic<std::uint64_t> sun_errors{0};
  std::atomic<std::uint64_t> sun_late{0};  // the estimator did not get it in time
  std::atomic<std::uint64_t> sun_accepted{0};
  std::atomic<std::uint64_t> sun_rejected{0};
  // The vertical cue, measured in the sun thread: calls, valid answers, refused images, and what
  // the fusion's gates did with the answers.
  std::atomic<std::uint64_t> vertical_calls{0};
  std::atomic<std::uint64_t> vertical_valid{0};
  std::atomic<std::uint64_t> vertical_errors{0};
  std::atomic<std::uint64_t> vertical_accepted{0};
  std::atomic<std::uint64_t> vertical_rejected{0};
  // fusion.world_up_alignment_use start_tilt: the start's tilt error that the cue's first answers
  // measured, millidegrees, from how many answers (0: not yet), and whether the estimator removed
  // it (false: within the answers' noise, left to the filter). Written before the answers.
  std::atomic<std::int64_t> start_tilt_mdeg{0};
  std::atomic<bool> start_tilt_removed{false};
  std::atomic<std::uint64_t> start_tilt_answers{0};
  std::atomic<std::uint64_t> poses_published{0};
  std::atomic<std::uint64_t> deadline_misses{0};
  std::atomic<std::uint64_t> heartbeats{0};
  std::atomic<std::uint64_t> link_errors{0};
  std::atomic<std::uint64_t> pose_log_errors{0};  // telemetry.pose_log: failed writes, lost lines
};

// The rings between the stages (drop-oldest: a stale frame or pose is of no use), their event
// counts, and the stop flags each stage raises when its loop ends.
struct Channels {
  explicit Channels(const QueueConfig& q)
      : frames(static_cast<std::size_t>(q.frames), runtime::QueuePolicy::kDropOldest),
        sun_requests(static_cast<std::size_t>(q.sun_requests), runtime::QueuePolicy::kDropOldest),
        sun_results(static_cast<std::size_t>(q.sun_results), runtime::QueuePolicy::kDropOldest),
        poses(static_cast<std::size_t>(q.poses), runtime::QueuePolicy::kDropOldest) {}

  // Asks every stage to finish and wakes the ones that wait.
  void requestStop() {
    stop.store(true, std::memory_order_release);
    frames_ev.notify();
    sun_requests_ev.notify();
    sun_results_ev.notify();
    poses_ev.notify();
  }

  runtime::SpscQueue<FrameTicket> frames;
  runtime::SpscQueue<SunRequest> sun_requests;
  runtime::SpscQueue<SunResult> sun_results;
  runtime::SpscQueue<PoseRecord> poses;
  runtime::EventCount frames_ev, sun_requests_ev, sun_results_ev, poses_ev;
  std::atomic<bool> stop{false};
  std::atomic<bool> capture_done{false};
  std::atomic<bool> estimator_done{false};
  std::atomic<bool> sun_done{false};
  std::atomic<bool> telemetry_done{false};
};

// The latest camera attitude q_w_c, written by the estimator thread, read by the sun thread for
// the image estimators' prior: a seqlock (odd = being written), no allocation, no lock.
class AttitudeMailbox {
 public:
  void publish(const Eigen::Quaterniond& q_w_c);
  // False before the first pose or while the writer keeps it busy.
  bool latest(Eigen::Quaterniond* q_w_c) const;

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<double>, 4> q_{};  // w, x, y, z
};

}  // namespace sunvo::rover
