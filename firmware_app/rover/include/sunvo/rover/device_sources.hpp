#pragma once
// The rover's own trigger and camera behind the capture thread's two interfaces:
//   StrobeTrigger  (TriggerSource): the cameras' strobe (exposure) edges read with
//                  gpio::StrobeInput; each rising edge is one trigger, its kernel timestamp
//                  (CLOCK_MONOTONIC) the trigger time, mapped to UTC with the clock offset taken
//                  when the trigger opens.
//   V4l2FrameSource (FrameSource): v4l2::V4l2StereoSource, each frame paired with its strobe
//                  by gpio::TriggerPairer on the driver's buffer timestamp (same clock).
// Both reach the kernel only through the seams they are given (sysio::SysIo, gpio::GpioApi), so
// tests run this code on hil/sim/emulated_devices.

#include <memory>

#include "sunvo/calib/rectifier.hpp"
#include "sunvo/gpio/gpio_api.hpp"
#include "sunvo/gpio/trigger.hpp"
#include "sunvo/gpio/trigger_pairer.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/sources.hpp"
#include "sunvo/sysio/sysio.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace sunvo::rover {

class StrobeTrigger final : public TriggerSource {
 public:
  // trigger.gpio_chip / gpio_line: the strobe input line. utc_minus_mono_ns: UTC - monotonic.
  static Expected<std::unique_ptr<StrobeTrigger>> open(const TriggerConfig& config,
                                                       TimeNs wait_timeout_ns, gpio::GpioApi& api,
                                                       TimeNs utc_minus_mono_ns);
  // The next rising strobe edge (waits at most the timeout given to open(), a hardware limit
  // of StrobeInput; timeout_ns is not shortened per call).
  Status wait(TimeNs timeout_ns, TriggerEvent* out) override;
  const gpio::StrobeInputCounters& counters() const { return input_->counters(); }

 private:
  StrobeTrigger() = default;
  std::unique_ptr<gpio::StrobeInput> input_;
  TimeNs utc_minus_mono_ns_ = 0;
};

class V4l2FrameSource final : public FrameSource {
 public:
  // The options come from source.v4l2 and frames.width/height; the camera model from
  // source.v4l2.calibration: a KITTI calib_cam_to_cam.txt (rectified cameras 00/01, frames used
  // as they come), or a raw OpenCV / Kalibr calibration, from which a calib::StereoRectifier is
  // built once and every paired frame is rectified into the slot (no allocation once warm).
  static Expected<std::unique_ptr<V4l2FrameSource>> open(const RoverConfig& config,
                                                         sysio::SysIo& io,
                                                         TimeNs utc_minus_mono_ns);
  const StereoCamera& camera() const override { return camera_; }
  Eigen::Matrix3d C_c_l() const override {
    return rectifier_ ? rectifier_->C_c_l() : Eigen::Matrix3d::Identity();
  }
  bool rectifies() const override { return rectifier_ != nullptr; }
  // Hands the trigger to the pairer, then reads frames until one pairs with a trigger: a frame
  // whose strobe was lost (older than every held trigger) is skipped, at most buffer_count + 1
  // frames per call. frame.trigger_time_ns = the paired strobe's time in UTC;
  // meta.source_index = the left buffer's sequence. kNotFound: no frame for this trigger.
  Status grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) override;

  const v4l2::V4l2Counters& cameraCounters() const { return camera_source_->counters(); }
  const gpio::TriggerPairerCounters& pairerCounters() const { return pairer_->counters(); }

 private:
  V4l2FrameSource() = default;
  StereoCamera camera_;
  std::unique_ptr<v4l2::V4l2StereoSource> camera_source_;
  std::unique_ptr<gpio::TriggerPairer> pairer_;
  std::unique_ptr<calib::StereoRectifier> rectifier_;  // null: the frames come rectified
  StereoFrame raw_;  // the camera's frame before rectification (allocated at open())
  TimeNs utc_minus_mono_ns_ = 0;
  int max_reads_ = 5;
};

}  // namespace sunvo::rover
