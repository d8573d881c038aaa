#pragma once
// A PoseLink that records every pose the rover's telemetry thread hands over, for the tests that
// run RoverApp in-process (the serial port is not under test there).

#include <mutex>
#include <string>
#include <vector>

#include "sunvo/rover/pose_link.hpp"

namespace sunvo::testing {

class RecordingLink final : public rover::PoseLink {
 public:
  Status sendPose(const rover::PoseRecord& pose, TimeNs now) override {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(pose);
    last_ns_ = now;
    return Status::ok();
  }
  Status sendHeartbeat(TimeNs) override { return Status::ok(); }
  Status service(TimeNs) override { return Status::ok(); }
  bool drained() const override { return true; }
  TimeNs lastByteWrittenNs() const override { return last_ns_; }
  std::string countersText() const override { return "recording link"; }
  std::vector<rover::PoseRecord> poses() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<rover::PoseRecord> poses_;
  TimeNs last_ns_ = 0;
};

}  // namespace sunvo::testing
