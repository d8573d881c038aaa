#pragma once
// The 11 real KITTI odometry frames of sequence 00 (data/kitti_odometry/00_first_frames), read
// through drivers/kitti's KittiStereoSource into memory, for the front-end and pipeline tests.

#include <string>
#include <utility>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/kitti/stereo_source.hpp"

namespace sunvo::testing {

using KittiFrames = kitti::LoadedFrames;

// Frame times only order the frames in these tests; times.txt's 0 is placed at 1 s after the
// epoch (the odometry layout names no absolute time).
inline constexpr TimeNs kKittiFirstFramesStartNs = 1'000'000'000;

inline std::string kittiFirstFramesDir() {
  return std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";
}

inline Expected<KittiFrames> loadKittiFirstFrames() {
  kitti::KittiSourceOptions o;
  o.root = kittiFirstFramesDir();
  o.layout = kitti::KittiLayout::kOdometry;
  o.odometry_start_time_ns = kKittiFirstFramesStartNs;
  return kitti::loadAllFrames(o);
}

}  // namespace sunvo::testing
