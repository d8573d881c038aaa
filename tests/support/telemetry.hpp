#pragma once
// Shared pieces of the MAVLink and serial tests: a monotonic clock in ns, an ODOMETRY message
// with every field set (non-zero, distinct values), and decoding a byte stream into frames.

#include <time.h>

#include <cstdint>
#include <vector>

#include "sunvo/core/time.hpp"
#include "sunvo/mavlink/mavlink.hpp"

namespace sunvo::testing {

inline TimeNs monotonicNs() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

// quality != 0, so the full 233-byte payload is sent.
inline mavlink::Odometry sampleOdometry() {
  mavlink::Odometry m;
  m.time_usec = 1'317'380'000'123'456ULL;
  m.frame_id = mavlink::kMavFrameLocalNed;
  m.child_frame_id = mavlink::kMavFrameBodyFrd;
  m.x = 12.5f;
  m.y = -3.25f;
  m.z = 0.1f;
  m.q = {0.9238795f, 0.01f, -0.02f, 0.3826834f};
  m.vx = 1.5f;
  m.vy = -0.5f;
  m.vz = 0.01f;
  m.rollspeed = 0.001f;
  m.pitchspeed = -0.002f;
  m.yawspeed = 0.1f;
  for (std::size_t i = 0; i < 21; ++i) {
    m.pose_covariance[i] = 1e-3f * static_cast<float>(i + 1);
    m.velocity_covariance[i] = -0.25f * static_cast<float>(i + 1);
  }
  m.reset_counter = 3;
  m.estimator_type = mavlink::kMavEstimatorVision;
  m.quality = 87;
  return m;
}

// Every frame the decoder finds in bytes, in order (including those after a resync).
inline std::vector<mavlink::Frame> decodeAll(const std::vector<std::uint8_t>& bytes,
                                             mavlink::Decoder* decoder) {
  std::vector<mavlink::Frame> frames;
  mavlink::Frame f;
  for (std::uint8_t b : bytes) {
    if (decoder->push(b, &f)) {
      frames.push_back(f);
      while (decoder->next(&f)) frames.push_back(f);
    }
  }
  return frames;
}

}  // namespace sunvo::testing
