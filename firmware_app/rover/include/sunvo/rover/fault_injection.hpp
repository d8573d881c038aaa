#pragma once
// Faults injected at random through the capture seams (TriggerSource, FrameSource), for soak and
// hardware-in-the-loop runs: a lost strobe edge, a frame whose image is lost or corrupt, a frame
// that comes out black. Off by default (every rate 0); with a seed the same faults come at the
// same triggers, so a run can be repeated. The counts of what was injected sit next to the health
// counters that must account for them (summary: "faults injected"). Options: FaultInjectionConfig
// (config.hpp, keys source.faults.*).

#include <atomic>
#include <cstdint>
#include <memory>
#include <random>

#include "sunvo/core/status.hpp"
#include "sunvo/rover/sources.hpp"

namespace sunvo::rover {

// What was injected (written by the capture thread, read by anyone).
struct InjectedFaults {
  std::atomic<std::uint64_t> missed_triggers{0};
  std::atomic<std::uint64_t> bad_frames{0};
  std::atomic<std::uint64_t> dark_frames{0};
};

// Swallows a trigger edge with probability missed_trigger_rate and waits for the next one, as a
// lost strobe pulse does: the capture stage's TriggerMonitor then sees an interval of two periods.
class FaultyTrigger final : public TriggerSource {
 public:
  FaultyTrigger(std::unique_ptr<TriggerSource> inner, const FaultInjectionConfig& config,
                InjectedFaults& counts);
  Status wait(TimeNs timeout_ns, TriggerEvent* out) override;

 private:
  std::unique_ptr<TriggerSource> inner_;
  double rate_;
  InjectedFaults& counts_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
};

// Fails a grab with probability bad_frame_rate (the frame is dropped and counted as a grab error),
// or blackens both images of a grabbed frame with probability dark_frame_rate. No allocation.
class FaultyFrameSource final : public FrameSource {
 public:
  FaultyFrameSource(std::unique_ptr<FrameSource> inner, const FaultInjectionConfig& config,
                    InjectedFaults& counts);
  const StereoCamera& camera() const override { return inner_->camera(); }
  Eigen::Matrix3d C_c_l() const override { return inner_->C_c_l(); }
  bool rectifies() const override { return inner_->rectifies(); }
  Status grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) override;

 private:
  std::unique_ptr<FrameSource> inner_;
  double bad_rate_;
  double dark_rate_;
  InjectedFaults& counts_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
};

}  // namespace sunvo::rover
