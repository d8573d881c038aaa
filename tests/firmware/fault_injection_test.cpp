// The fault decorators of the capture seams: what they inject, that they count it, that a seed
// repeats it, and that the capture stage's monitor sees a swallowed edge as a missed trigger.
#include "sunvo/rover/fault_injection.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace sunvo::rover {
namespace {

constexpr TimeNs kP = 100'000'000;  // 10 Hz

// Fires trigger k at k periods, forever.
class CountingTrigger final : public TriggerSource {
 public:
  Status wait(TimeNs, TriggerEvent* out) override {
    out->sequence = next_;
    out->mono_ns = static_cast<TimeNs>(next_) * kP;
    out->utc_ns = out->mono_ns;
    ++next_;
    return Status::ok();
  }

 private:
  std::uint64_t next_ = 0;
};

// Writes a mid-grey pair.
class GreySource final : public FrameSource {
 public:
  const StereoCamera& camera() const override { return camera_; }
  Status grab(const TriggerEvent&, runtime::FrameSlot& slot) override {
    slot.frame.left.setTo(128);
    slot.frame.right.setTo(128);
    ++grabs;
    return Status::ok();
  }
  int grabs = 0;

 private:
  StereoCamera camera_;
};

runtime::FrameSlot makeSlot() {
  runtime::FrameSlot slot;
  slot.frame.left = cv::Mat(8, 16, CV_8UC1, cv::Scalar(0));
  slot.frame.right = cv::Mat(8, 16, CV_8UC1, cv::Scalar(0));
  return slot;
}

struct Draws {
  std::vector<std::uint64_t> bad, dark;
  std::uint64_t grabbed_nonblack = 0;
};

Draws runSource(const FaultInjectionConfig& config, int frames, InjectedFaults* counts) {
  auto inner = std::make_unique<GreySource>();
  FaultyFrameSource source(std::move(inner), config, *counts);
  runtime::FrameSlot slot = makeSlot();
  Draws d;
  for (int k = 0; k < frames; ++k) {
    TriggerEvent ev;
    ev.sequence = static_cast<std::uint64_t>(k);
    const Status st = source.grab(ev, slot);
    if (!st.isOk()) {
      EXPECT_EQ(st.code(), StatusCode::kIoError);
      d.bad.push_back(ev.sequence);
      continue;
    }
    if (cv::countNonZero(slot.frame.left) == 0 && cv::countNonZero(slot.frame.right) == 0) {
      d.dark.push_back(ev.sequence);
    } else {
      ++d.grabbed_nonblack;
    }
  }
  return d;
}

TEST(FaultyFrameSource, InjectsAtTheConfiguredRatesCountsAndRepeatsWithASeed) {
  FaultInjectionConfig config;
  config.seed = 7;
  config.bad_frame_rate = 0.05;
  config.dark_frame_rate = 0.02;
  InjectedFaults counts;
  const int n = 20000;
  const Draws a = runSource(config, n, &counts);
  EXPECT_EQ(counts.bad_frames.load(), a.bad.size());
  EXPECT_EQ(counts.dark_frames.load(), a.dark.size());
  EXPECT_EQ(a.bad.size() + a.dark.size() + a.grabbed_nonblack, static_cast<std::size_t>(n));
  // Binomial: 1000 +- 31 and 400 +- 20 (one sigma); 5 sigma bounds.
  EXPECT_NEAR(static_cast<double>(a.bad.size()), 0.05 * n, 5 * 31);
  EXPECT_NEAR(static_cast<double>(a.dark.size()), 0.02 * n * 0.95, 5 * 20);
  InjectedFaults again;
  const Draws b = runSource(config, n, &again);
  EXPECT_EQ(a.bad, b.bad);
  EXPECT_EQ(a.dark, b.dark);
  config.seed = 8;
  InjectedFaults other;
  EXPECT_NE(runSource(config, n, &other).bad, a.bad);
}

TEST(FaultyTrigger, ASwallowedEdgeIsAMissedTriggerForTheMonitor) {
  FaultInjectionConfig config;
  config.seed = 3;
  config.missed_trigger_rate = 0.1;
  InjectedFaults counts;
  FaultyTrigger trigger(std::make_unique<CountingTrigger>(), config, counts);
  TriggerMonitor monitor(kP);
  std::uint64_t last = 0;
  for (int i = 0; i < 5000; ++i) {
    TriggerEvent ev;
    ASSERT_TRUE(trigger.wait(kP, &ev).isOk());
    if (i > 0) {
      EXPECT_GT(ev.sequence, last);
    }
    last = ev.sequence;
    monitor.observe(ev.mono_ns);
  }
  EXPECT_EQ(monitor.missed(), counts.missed_triggers.load());
  EXPECT_EQ(last + 1, 5000 + counts.missed_triggers.load());
  EXPECT_NEAR(static_cast<double>(counts.missed_triggers.load()), 5000.0 / 0.9 * 0.1, 5 * 22.0);
}

// A source that rectifies, with a rectification rotation.
class RectifyingSource final : public FrameSource {
 public:
  const StereoCamera& camera() const override { return camera_; }
  Eigen::Matrix3d C_c_l() const override {
    return Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()).toRotationMatrix();
  }
  bool rectifies() const override { return true; }
  Status grab(const TriggerEvent&, runtime::FrameSlot&) override { return Status::ok(); }

 private:
  StereoCamera camera_;
};

// The decorator is transparent for what the rover reads from the source besides frames (the
// camera-to-body mount uses C_c_l, the summary rectifies()).
TEST(FaultyFrameSource, ForwardsTheRectificationOfTheSourceItWraps) {
  FaultInjectionConfig config;
  config.bad_frame_rate = 0.1;
  InjectedFaults counts;
  auto inner = std::make_unique<RectifyingSource>();
  const Eigen::Matrix3d expected = inner->C_c_l();
  const FaultyFrameSource source(std::move(inner), config, counts);
  EXPECT_TRUE(source.rectifies());
  EXPECT_TRUE(source.C_c_l().isApprox(expected, 1e-15));
  EXPECT_FALSE(source.C_c_l().isIdentity(1e-6));
}

TEST(FaultInjectionConfig, OffByDefaultAndRangesNameTheKey) {
  FaultInjectionConfig config;
  EXPECT_FALSE(config.enabled());
  EXPECT_TRUE(config.validate("source.faults").isOk());
  config.dark_frame_rate = 0.7;
  const Status st = config.validate("source.faults");
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(st.message().find("source.faults.dark_frame_rate"), std::string::npos) << st.message();
  config.dark_frame_rate = 0.01;
  config.seed = -1;
  EXPECT_NE(config.validate("source.faults").message().find("source.faults.seed"),
            std::string::npos);
}

}  // namespace
}  // namespace sunvo::rover
