#pragma once
// The configuration of sunvo_rover: one YAML file (config/rover.yaml on the rover,
// config/rover_replay.yaml for a replay), read and validated once at start-up.
//
// Every option has a default (below), with its unit and range. Unknown keys are rejected; a bad
// value names its key and the file ("config/rover.yaml: estimator.window.max_iterations: 0 is
// outside [1, 100]"); a value of the wrong type also names the line. Command-line overrides use
// the same keys ("--set source.kitti.drive_dir=/data/drive").

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/runtime/frame_pool.hpp"
#include "sunvo/runtime/rt_setup.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace sunvo::rover {

enum class SourceType { kKitti, kV4l2 };
enum class TriggerType { kSimulated, kGpio };
// What the replay source does after its last frame.
enum class EndAction {
  kStop,      // no more frames; the program shuts down once the last pose is sent
  kHold,      // no more frames; the program keeps running (heartbeats) until a signal
  kLoop,      // start again at the first frame (a jump: tracking loss and recovery)
  kPingPong,  // play backwards, then forwards again (continuous motion)
};
enum class WorldInit {
  kOxts,    // origin and first camera pose from the replay drive's first OXTS record
  kConfig,  // origin from world.latitude/longitude/altitude, camera attitude from world.*_deg
};
// none: pure VO; csv: a per-frame file; lalonde / lalonde_vo: sunvision::LalondeEstimator with the
// zenith / the VO attitude as prior; sun_cnn: suncnn::SunCnnEstimator (ONNX model at sun.model).
enum class SunProviderType { kNone, kCsv, kLalonde, kLalondeVo, kSunCnn };

struct KittiSourceConfig {
  std::string drive_dir;          // KITTI raw drive folder (<date>/<date>_drive_NNNN_sync)
  std::int64_t utc_offset_s = 0;  // s, [-50400, 50400]: offset of the timestamps to UTC
  bool preload = true;            // decode every frame at start-up (no decoding per frame)
  std::int64_t first_frame = 0;   // index, >= 0
  std::int64_t last_frame = -1;   // index, >= first_frame; -1 = the last one
  EndAction end = EndAction::kStop;
  std::int64_t total_frames =
      0;  // frames, >= 0: stop after this many (loop / pingpong); 0 = no limit
};

struct V4l2SourceConfig {
  std::string left_device = "/dev/video0";   // V4L2 node of the left camera
  std::string right_device = "/dev/video1";  // V4L2 node of the right camera
  std::string calibration = "";              // KITTI-style calib_cam_to_cam.txt of the rig
  v4l2::V4l2Layout layout = v4l2::V4l2Layout::kTwoDevices;            // two_devices | side_by_side
  v4l2::V4l2PixelFormat pixel_format = v4l2::V4l2PixelFormat::kGrey;  // grey | yuyv
  int buffer_count = 4;          // MMAP buffers per device, [2, 32]
  int dequeue_timeout_ms = 200;  // ms, [1, 60000]: the longest wait for one stereo pair
};

struct SourceConfig {
  SourceType type = SourceType::kKitti;
  KittiSourceConfig kitti;
  V4l2SourceConfig v4l2;
};

struct TriggerConfig {
  TriggerType type = TriggerType::kSimulated;
  double rate_hz = 10.0;  // Hz, (0, 200]: frame rate (the simulated trigger's rate when it does not
                          //   follow the recording's times)
  bool follow_recording = true;  // simulated: trigger at the recording's time deltas (first pass)
  double timeout_factor = 3.0;   // periods, [1.5, 100]: no trigger for this long -> counted missed
  std::string gpio_chip = "gpiochip0";  // gpio: chip name
  int gpio_line = 0;                    // gpio: line offset, [0, 1023] (the strobe input)
  double frame_delay_ms = 0.0;    // gpio: ms, [-1000, 1000]: frame buffer timestamp - strobe edge
  double match_window_ms = 10.0;  // gpio: ms, [0, half a period]: largest pairing error
};

struct QueueConfig {
  int frames = 4;        // capture -> estimator, power of two [1, 256], drop-oldest
  int sun_requests = 4;  // capture -> sun, power of two [1, 256], drop-oldest
  int sun_results = 4;   // sun -> estimator, power of two [1, 256], drop-oldest
  int poses = 16;        // estimator -> telemetry, power of two [1, 1024], drop-oldest
};

struct WorldConfig {
  WorldInit init = WorldInit::kOxts;
  double latitude_deg = 0.0;   // deg, [-90, 90]
  double longitude_deg = 0.0;  // deg, [-180, 180]
  double altitude_m = 0.0;     // m, [-500, 9000]
  // kConfig: the first camera's attitude in ENU as yaw (heading of the optical axis from north,
  // clockwise), pitch (optical axis up) and roll (about the optical axis, right side down).
  double camera_heading_deg = 0.0;  // deg, [-360, 360]
  double camera_pitch_deg = 0.0;    // deg, [-90, 90]
  double camera_roll_deg = 0.0;     // deg, [-180, 180]
};

struct EstimatorConfig {
  int window_size = 2;               // poses, [2, 8]
  int max_iterations = 10;           // Ceres iterations per solve, [1, 100]
  double max_solver_time_ms = 40.0;  // ms, [1, 1000]: the solver budget of an on-time frame
  double min_solver_time_ms = 5.0;  // ms, [0.1, max_solver_time_ms]: the budget never shrinks below
  double deadline_ms = 100.0;       // ms, [10, 10000]: trigger -> pose sent; later = a miss
  double publish_margin_ms = 5.0;   // ms, [0, 1000]: kept for telemetry when budgeting the solver
  int max_features = 2000;          // per frame, [16, 2000]
  int warmup_frames = 50;           // frames, [0, 100000]: not counted in the allocation meters
};

struct SunConfig {
  SunProviderType provider = SunProviderType::kNone;
  int every_n_frames = 5;  // a measurement every n-th frame, [1, 1000]
  std::string csv;         // csv provider: "frame,sx,sy,sz" per recording frame
  std::string model;       // sun_cnn provider: the ONNX model file (e.g. /etc/sunvo/sun_cnn.onnx)
  double sigma = 0.05;     // csv provider: measurement sigma (R_s = sigma^2 I), (0, 2]
  double wait_ms = 5.0;    // ms, [0, 100]: the estimator waits at most this long for a
                           //   sun frame's measurement (0 = never waits)
  bool estimate_base_attitude = true;  // see sunfusion::SunFusionOptions
  double max_cosine_distance = 0.3;    // gate, [0, 2]
  // deg, (0, 45]: attitude std of the start pose (from the INS / level and heading at start-up)
  double initial_attitude_sigma_deg = 1.0;
  // deg/frame, [0.002, 5]: cap of the adapted attitude random walk (docs/experiment.md). 0.01
  // for the image estimators, whose errors are correlated along a street (docs/sun_estimators.md,
  // benchmark drives); raise it (0.05) for a source whose errors are independent from frame to
  // frame (a sun sensor, the csv provider with the true sun)
  double max_drift_deg_per_frame = 0.01;
};

struct SerialConfig {
  std::string device;           // serial port (e.g. /dev/ttyS1, a pty); empty = no pose stream
  int baud = 921600;            // bit/s, a termios speed
  int tx_buffer_bytes = 16384;  // bytes, [1024, 1048576]: frames waiting for the port
};

struct TelemetryConfig {
  double heartbeat_hz = 1.0;        // Hz, (0, 50]
  int system_id = 1;                // [1, 255]
  int component_id = 197;           // [1, 255] (197 = MAV_COMP_ID_VISUAL_INERTIAL_ODOMETRY)
  double position_sigma_m = 0.1;    // m, (0, 1000]: reported position std when tracking
  double attitude_sigma_deg = 1.0;  // deg, (0, 180]: reported attitude std when tracking
  int full_quality_inliers = 150;   // RANSAC inliers that count as quality 100, [1, 100000]
};

struct RtConfig {
  bool lock_memory = true;  // mlockall(MCL_CURRENT | MCL_FUTURE)
  // MiB, [0, 4096]: heap made resident at start-up for the estimator's per-frame allocations
  // (one malloc arena, no mmap blocks, no trimming; see runtime::configureRealTimeHeap); 0 = off
  int heap_reserve_mb = 64;
  runtime::ThreadPolicy capture{80, -1};
  runtime::ThreadPolicy estimator{70, -1};
  runtime::ThreadPolicy sun{20, -1};
  runtime::ThreadPolicy telemetry{75, -1};
};

struct ProfilingConfig {
  int ring_frames = 8192;                // frames, power of two [2, 1048576]: stage stamps kept
  std::string output_dir = "out/rover";  // CSV, trace and summary go here (created)
};

struct RoverConfig {
  std::string path;  // the file it was read from
  SourceConfig source;
  TriggerConfig trigger;
  runtime::FramePoolOptions frames;
  QueueConfig queues;
  WorldConfig world;
  EstimatorConfig estimator;
  SunConfig sun;
  SerialConfig serial;
  TelemetryConfig telemetry;
  RtConfig rt;
  ProfilingConfig profiling;

  // Checks every range; the message names the key (without the file).
  Status validate() const;
  // The options as "key: value" lines, printed once at start-up.
  std::string describe() const;
};

// Reads the file, applies overrides ("key.path", "value") on top, rejects unknown keys, checks
// ranges. Relative paths in the file stay relative to the working directory.
Expected<RoverConfig> loadRoverConfig(
    const std::string& path,
    const std::vector<std::pair<std::string, std::string>>& overrides = {});

}  // namespace sunvo::rover
