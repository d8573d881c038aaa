#pragma once
// The emulated rover rig of the firmware tests (rover_devices, supervisor, clock_jump): two
// EmulatedV4l2 cameras under the device names config/rover.yaml gives them (the package's udev
// links) showing a textured plane 12 px of disparity away that slides 2 px per frame (trackable
// stereo images), the strobe line of an EmulatedGpio chip, and the overrides that run
// config/rover.yaml on it inside a test (no real-time priorities, no locked memory, no serial
// port, no sun, no pose log).

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"

namespace sunvo::testing {

constexpr int kRigWidth = 1242;  // the size of the calibration used (kitti_raw_sample)
constexpr int kRigHeight = 375;
constexpr double kRigRateHz = 20.0;
constexpr int kRigStrobeLine = 17;

// Row `frame % 100 * 2 + disparity` onwards of the texture.
inline emulated::FrameContent planeContent(const cv::Mat& texture, int disparity) {
  return [texture, disparity](std::uint64_t frame, cv::Mat& gray) {
    const int shift = static_cast<int>(frame % 100) * 2 + disparity;
    texture(cv::Rect(shift, 0, gray.cols, gray.rows)).copyTo(gray);
  };
}

// Adds /dev/sunvo-left and /dev/sunvo-right showing the plane (blobs rather than pixel noise, so
// that the front end finds corners, stretched to the full range).
inline Status addRigCameras(emulated::EmulatedV4l2& cameras) {
  cv::Mat texture(kRigHeight, kRigWidth + 260, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  SUNVO_RETURN_IF_ERROR(cameras.addCamera(
      {"/dev/sunvo-left", kRigWidth, kRigHeight, true, true, 0, 0, planeContent(texture, 12)}));
  return cameras.addCamera(
      {"/dev/sunvo-right", kRigWidth, kRigHeight, true, true, 0, 0, planeContent(texture, 0)});
}

// The config/rover.yaml overrides of a test run on the rig, writing profiles to out_dir; a test
// appends its own (later keys win).
inline std::vector<std::pair<std::string, std::string>> rigOverrides(const std::string& out_dir) {
  return {{"source.v4l2.calibration",
           std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26/calib_cam_to_cam.txt"},
          {"trigger.rate_hz", std::to_string(kRigRateHz)},
          {"trigger.gpio_line", std::to_string(kRigStrobeLine)},
          {"trigger.frame_delay_ms", "3.0"},
          {"trigger.match_window_ms", "4.0"},
          {"serial.device", "\"\""},
          {"rt.lock_memory", "false"},
          {"rt.heap_reserve_mb", "0"},
          {"rt.threads",
           "{capture: {fifo_priority: 0, cpu: -1}, estimator: {fifo_priority: 0, "
           "cpu: -1}, sun: {fifo_priority: 0, cpu: -1}, telemetry: {fifo_priority: "
           "0, cpu: -1}}"},
          {"realtime.warmup_frames", "0"},
          {"sun.provider", "none"},
          {"telemetry.pose_log", "\"\""},
          {"profiling.output_dir", out_dir}};
}

}  // namespace sunvo::testing
