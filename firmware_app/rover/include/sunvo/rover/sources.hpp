#pragma once
// Where the frames and the triggers come from. The capture thread sees two small interfaces:
//   TriggerSource::wait() -> the next trigger event (sequence, monotonic and UTC time);
//   FrameSource::grab(trigger, slot) -> that trigger's stereo pair, written into a pool slot.
// On the rover they are the GPIO trigger and the V4L2 stereo pair (drivers/gpio, drivers/v4l2;
// each is one class implementing the interface plus one line in makeTrigger()/makeSource()).
// For a replay, a SimulatedTrigger fires at the recording's frame times and a KittiReplaySource
// gives the recording's frame for each trigger; both follow one ReplaySchedule, which also loops
// or ping-pongs the recording for long runs.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/dataset/dataset.hpp"
#include "sunvo/kitti/stereo_source.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/runtime/frame_pool.hpp"

namespace sunvo::rover {

struct TriggerEvent {
  std::uint64_t sequence = 0;  // 0, 1, 2, ... in trigger order
  TimeNs mono_ns = 0;          // monotonic ns of the trigger edge
  TimeNs utc_ns = 0;           // UTC ns of the exposure
};

class TriggerSource {
 public:
  virtual ~TriggerSource() = default;
  // Waits at most timeout_ns (> 0) for the next trigger. kTimeout: none came; kNotFound: the
  // trigger has ended (a replay's last frame) and will not fire again.
  virtual Status wait(TimeNs timeout_ns, TriggerEvent* out) = 0;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual const StereoCamera& camera() const = 0;
  // C_c_l: the images' camera frame c from the physical left camera l (p_c = C_c_l p_l); the
  // rectification's rotation for a source that rectifies, else the identity.
  virtual Eigen::Matrix3d C_c_l() const { return Eigen::Matrix3d::Identity(); }
  // True when the source rectifies the frames itself (a raw calibration), for the summary.
  virtual bool rectifies() const { return false; }
  // Writes the frame exposed at `trigger` into slot.frame (its Mats have the configured size)
  // and sets slot.meta.source_index. No allocation once warm.
  virtual Status grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) = 0;
};

// Counts irregular trigger intervals against the nominal period: an interval below half a period
// is a duplicate trigger, an interval of n periods (n >= 2, rounded) means n - 1 missed triggers.
class TriggerMonitor {
 public:
  explicit TriggerMonitor(TimeNs period_ns) : period_ns_(period_ns) {}
  void observe(TimeNs trigger_mono_ns);
  std::uint64_t duplicates() const { return duplicates_; }
  std::uint64_t missed() const { return missed_; }

 private:
  TimeNs period_ns_;
  TimeNs last_ns_ = 0;
  bool have_last_ = false;
  std::uint64_t duplicates_ = 0;
  std::uint64_t missed_ = 0;
};

// Which recording frame and what time belong to trigger k of a replay.
class ReplaySchedule {
 public:
  // times_ns: UTC of the recording's frames first..last; period_ns: the trigger period used
  // beyond the first pass (and throughout when !follow_recording).
  ReplaySchedule(std::vector<TimeNs> times_ns, std::int64_t first_index, EndAction end,
                 std::int64_t total_frames, TimeNs period_ns, bool follow_recording);
  // False when trigger k does not exist (end of a stop/hold replay, or total_frames reached).
  bool has(std::uint64_t k) const;
  std::int64_t recordingIndex(std::uint64_t k) const;  // index in the recording
  TimeNs offsetNs(std::uint64_t k) const;              // trigger time after trigger 0
  TimeNs utcNs(std::uint64_t k) const { return times_ns_.front() + offsetNs(k); }
  std::size_t passLength() const { return times_ns_.size(); }

 private:
  std::vector<TimeNs> times_ns_;
  std::int64_t first_;
  EndAction end_;
  std::int64_t total_;
  TimeNs period_ns_;
  bool follow_;
};

// Fires at start + schedule.offsetNs(k) on the monotonic clock (like a hardware trigger, the event
// carries the scheduled edge time, not the wake-up time).
class SimulatedTrigger final : public TriggerSource {
 public:
  explicit SimulatedTrigger(std::shared_ptr<const ReplaySchedule> schedule)
      : schedule_(std::move(schedule)) {}
  Status wait(TimeNs timeout_ns, TriggerEvent* out) override;

 private:
  std::shared_ptr<const ReplaySchedule> schedule_;
  std::uint64_t next_ = 0;
  TimeNs start_mono_ns_ = 0;
};

// A KITTI raw drive (or a sunvo render) as the camera, opened through the dataset seam
// (drivers/dataset), which also gives the world: the origin and the first camera pose from the
// first OXTS record of the range. With preload every frame of the range is decoded at start-up
// and grab() copies it into the slot (no decoding, no allocation per frame); without preload
// grab() decodes the next files (stop/hold only; libpng allocates per frame). A frame with a
// missing or bad image (truncated, corrupt, wrong size or channel count) fails grab() for that
// frame only; the capture stage drops and counts it (source.max_consecutive_bad_frames).
class KittiReplaySource final : public FrameSource {
 public:
  // color: also deliver the left/right colour images (image_02/03) into slots that have them.
  static Expected<std::unique_ptr<KittiReplaySource>> open(const KittiSourceConfig& config,
                                                           bool color = false);
  const StereoCamera& camera() const override { return camera_; }
  Status grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) override;

  const std::vector<TimeNs>& rangeTimes() const { return dataset_->timesNs(); }
  const dataset::Dataset& dataset() const { return *dataset_; }
  void setSchedule(std::shared_ptr<const ReplaySchedule> schedule) {
    schedule_ = std::move(schedule);
  }

 private:
  KittiReplaySource() = default;
  KittiSourceConfig config_;
  StereoCamera camera_;
  std::optional<dataset::Dataset> dataset_;
  std::vector<StereoFrame> preloaded_;            // preload: the whole range
  std::optional<kitti::KittiStereoSource> live_;  // no preload: decoded per grab
  std::shared_ptr<const ReplaySchedule> schedule_;
};

}  // namespace sunvo::rover
