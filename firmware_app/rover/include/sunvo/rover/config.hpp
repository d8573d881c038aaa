#pragma once
// The configuration of sunvo_rover: one YAML file (config/rover.yaml on the rover,
// config/rover_replay.yaml for a replay), read and validated once at start-up.
//
// One vocabulary: every key is the name of a struct field, listed once in the struct's fields()
// (core/fields.hpp); the `estimator` section is the estimator's own pipeline::SunAidedOptions
// (estimator.window.max_num_iterations, estimator.frontend.max_features, estimator.fusion.*).
// Every option has a default (below or in its struct), with its unit and range. Unknown keys are
// rejected; a bad value names its key and the file ("config/rover.yaml: estimator.window.x must
// be ..."); a value of the wrong type also names the line. Command-line overrides use the same
// keys ("--set source.kitti.drive_dir=/data/drive").

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sunvo/calib/rectifier.hpp"
#include "sunvo/calib/stereo_calibration.hpp"
#include "sunvo/core/fields.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/mavlink/conventions.hpp"
#include "sunvo/pipeline/sun_aided_odometry.hpp"
#include "sunvo/runtime/frame_pool.hpp"
#include "sunvo/runtime/rt_setup.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace sunvo::v4l2 {
inline std::span<const std::string_view> enumNames(V4l2Layout) {
  static constexpr std::string_view kNames[] = {"two_devices", "side_by_side"};
  return kNames;
}
inline std::span<const std::string_view> enumNames(V4l2PixelFormat) {
  static constexpr std::string_view kNames[] = {"grey", "yuyv"};
  return kNames;
}
}  // namespace sunvo::v4l2

namespace sunvo::mavlink {
inline std::span<const std::string_view> enumNames(FrameProfile) {
  static constexpr std::string_view kNames[] = {"px4", "ardupilot"};
  return kNames;
}
}  // namespace sunvo::mavlink

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
// What start-up does when the kernel says the system clock is not synchronised (adjtimex).
enum class ClockUnsyncedAction { kWarn, kRefuse };

std::span<const std::string_view> enumNames(SourceType);
std::span<const std::string_view> enumNames(TriggerType);
std::span<const std::string_view> enumNames(EndAction);
std::span<const std::string_view> enumNames(WorldInit);
std::span<const std::string_view> enumNames(SunProviderType);
std::span<const std::string_view> enumNames(ClockUnsyncedAction);

struct KittiSourceConfig {
  std::string drive_dir;          // KITTI raw drive folder (<date>/<date>_drive_NNNN_sync)
  std::int64_t utc_offset_s = 0;  // s, [-50400, 50400]: offset of the timestamps to UTC
  bool preload = true;            // decode every frame at start-up (no decoding per frame)
  std::int64_t first_frame = 0;   // index, >= 0
  std::int64_t last_frame = -1;   // index, >= first_frame; -1 = the last one
  EndAction end = EndAction::kStop;
  std::int64_t total_frames = 0;  // frames, >= 0: stop after this many (loop / pingpong); 0 = all
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("drive_dir", s.drive_dir);
    v("utc_offset_s", s.utc_offset_s);
    v("preload", s.preload);
    v("first_frame", s.first_frame);
    v("last_frame", s.last_frame);
    v("end", s.end);
    v("total_frames", s.total_frames);
  }
};

struct V4l2SourceConfig {
  std::string left_device = "/dev/video0";   // V4L2 node of the left camera
  std::string right_device = "/dev/video1";  // V4L2 node of the right camera
  // The rig's calibration (docs/deployment.md, "Stereo calibration"): a KITTI
  // calib_cam_to_cam.txt (cameras that deliver rectified images: P_rect_00/01, no remap), or a
  // raw calibration, OpenCV stereo YAML or Kalibr camchain.yaml, from which every frame is
  // rectified (calib::StereoRectifier) before the estimator; its image size must be
  // frames.width x frames.height.
  std::string calibration = "";
  calib::CalibrationFormat calibration_format = calib::CalibrationFormat::kAuto;
  // ^ auto | kitti | opencv | kalibr (auto: by the file's content)
  calib::RectifyOptions rectify;  // raw calibrations: rectify.alpha, [0, 1]
  v4l2::V4l2Layout layout = v4l2::V4l2Layout::kTwoDevices;            // two_devices | side_by_side
  v4l2::V4l2PixelFormat pixel_format = v4l2::V4l2PixelFormat::kGrey;  // grey | yuyv
  // yuyv only: also the left image in colour (BGR) for the image sun providers (the colour
  // Sun-CNN model needs it; converted only when sun.provider looks at images); off: the
  // providers get the grey image.
  bool left_color = false;
  int buffer_count = 4;          // MMAP buffers per device, [2, 32]
  int dequeue_timeout_ms = 200;  // ms, [1, 60000]: the longest wait for one stereo pair
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("left_device", s.left_device);
    v("right_device", s.right_device);
    v("calibration", s.calibration);
    v("calibration_format", s.calibration_format);
    v("rectify", s.rectify);
    v("layout", s.layout);
    v("pixel_format", s.pixel_format);
    v("left_color", s.left_color);
    v("buffer_count", s.buffer_count);
    v("dequeue_timeout_ms", s.dequeue_timeout_ms);
  }
};

// Random faults injected at the capture seams for soak and HIL runs (fault_injection.hpp).
struct FaultInjectionConfig {
  int seed = 1;                      // draws; the same seed gives the same faults, >= 0
  double missed_trigger_rate = 0.0;  // [0, 0.5]: share of trigger edges swallowed
  double bad_frame_rate = 0.0;       // [0, 0.5]: share of frames whose grab fails
  double dark_frame_rate = 0.0;      // [0, 0.5]: share of frames delivered all black
  bool enabled() const {
    return missed_trigger_rate > 0.0 || bad_frame_rate > 0.0 || dark_frame_rate > 0.0;
  }
  // Checks every range; the message names the key under `prefix` (e.g. "source.faults").
  Status validate(const char* prefix) const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("seed", s.seed);
    v("missed_trigger_rate", s.missed_trigger_rate);
    v("bad_frame_rate", s.bad_frame_rate);
    v("dark_frame_rate", s.dark_frame_rate);
  }
};

struct SourceConfig {
  SourceType type = SourceType::kKitti;
  KittiSourceConfig kitti;
  V4l2SourceConfig v4l2;
  // frames, [1, 1000000]: failed grabs in a row (a missing or corrupt replay image, a camera that
  // gives no frame while it is reopened) after which capture stops and sunvo_rover exits 1; each
  // failed grab before that drops its frame and counts in the summary's grab errors.
  int max_consecutive_bad_frames = 100;
  // Random faults injected at the capture seams (soak / HIL runs; fault_injection.hpp). Off.
  FaultInjectionConfig faults;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("type", s.type);
    v("kitti", s.kitti);
    v("v4l2", s.v4l2);
    v("max_consecutive_bad_frames", s.max_consecutive_bad_frames);
    v("faults", s.faults);
  }
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
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("type", s.type);
    v("rate_hz", s.rate_hz);
    v("follow_recording", s.follow_recording);
    v("timeout_factor", s.timeout_factor);
    v("gpio_chip", s.gpio_chip);
    v("gpio_line", s.gpio_line);
    v("frame_delay_ms", s.frame_delay_ms);
    v("match_window_ms", s.match_window_ms);
  }
};

struct QueueConfig {
  int frames = 4;        // capture -> estimator, power of two [1, 256], drop-oldest
  int sun_requests = 4;  // capture -> sun, power of two [1, 256], drop-oldest
  int sun_results = 4;   // sun -> estimator, power of two [1, 256], drop-oldest
  int poses = 16;        // estimator -> telemetry, power of two [1, 1024], drop-oldest
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("frames", s.frames);
    v("sun_requests", s.sun_requests);
    v("sun_results", s.sun_results);
    v("poses", s.poses);
  }
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
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("init", s.init);
    v("latitude_deg", s.latitude_deg);
    v("longitude_deg", s.longitude_deg);
    v("altitude_m", s.altitude_m);
    v("camera_heading_deg", s.camera_heading_deg);
    v("camera_pitch_deg", s.camera_pitch_deg);
    v("camera_roll_deg", s.camera_roll_deg);
  }
};

// The real-time loop around the estimator (the estimator's own options are `estimator`).
struct RealtimeConfig {
  double deadline_ms = 100.0;      // ms, [10, 10000]: trigger -> pose sent; later = a miss
  double publish_margin_ms = 5.0;  // ms, [0, 1000]: kept for telemetry when budgeting the solver
  // ms, [0.1, estimator.window.max_solver_time_in_seconds * 1000]: the solver's budget of a late
  // frame never shrinks below this (an on-time frame gets max_solver_time_in_seconds)
  double min_solver_time_ms = 5.0;
  int warmup_frames = 50;    // frames, [0, 100000]: not counted in the allocation meters
  double sun_wait_ms = 5.0;  // ms, [0, 100]: the estimator waits at most this long for a sun
                             //   frame's measurement (0 = never waits)
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("deadline_ms", s.deadline_ms);
    v("publish_margin_ms", s.publish_margin_ms);
    v("min_solver_time_ms", s.min_solver_time_ms);
    v("warmup_frames", s.warmup_frames);
    v("sun_wait_ms", s.sun_wait_ms);
  }
};

// Where sun measurements come from; how they are fused is estimator.every_n_frames and
// estimator.fusion.*.
struct SunConfig {
  SunProviderType provider = SunProviderType::kNone;
  std::string csv;          // csv provider: "frame,sx,sy,sz" per recording frame
  double csv_sigma = 0.05;  // csv provider: measurement sigma (R_s = sigma^2 I), (0, 2]
  std::string model;        // sun_cnn provider: the ONNX model file (e.g. /etc/sunvo/sun_cnn.onnx)
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("provider", s.provider);
    v("csv", s.csv);
    v("csv_sigma", s.csv_sigma);
    v("model", s.model);
  }
};

struct SerialConfig {
  std::string device;           // serial port (e.g. /dev/ttyS1, a pty); empty = no pose stream
  int baud = 921600;            // bit/s, a termios speed
  int tx_buffer_bytes = 16384;  // bytes, [1024, 1048576]: frames waiting for the port
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("device", s.device);
    v("baud", s.baud);
    v("tx_buffer_bytes", s.tx_buffer_bytes);
  }
};

struct TelemetryConfig {
  // Which autopilot reads ODOMETRY: px4 (frame_id MAV_FRAME_LOCAL_NED) or ardupilot
  // (MAV_FRAME_LOCAL_FRD); child_frame_id is MAV_FRAME_BODY_FRD for both (docs/telemetry.md).
  mavlink::FrameProfile frame = mavlink::FrameProfile::kPx4;
  double heartbeat_hz = 1.0;  // Hz, (0, 50]
  int system_id = 1;          // [1, 255]
  int component_id = 197;     // [1, 255] (197 = MAV_COMP_ID_VISUAL_INERTIAL_ODOMETRY)
  // Reported position std: position_sigma_m + position_sigma_per_m * (path length since start).
  double position_sigma_m = 0.1;       // m, (0, 1000]: at the start
  double position_sigma_per_m = 0.02;  // m per m travelled, [0, 1] (0.02 = 2 % of distance)
  // deg, (0, 180]: reported attitude std when the estimator has no attitude covariance (sun
  // fusion off); with the sun on, the sun filter's covariance is sent instead.
  double attitude_sigma_deg = 1.0;
  int full_quality_inliers = 150;  // RANSAC inliers that count as quality 100, [1, 100000]
  double origin_period_s = 10.0;   // s, [0, 3600]: SET_GPS_GLOBAL_ORIGIN again after this (0 =
                                   //   only at start)
  double statustext_min_interval_s = 1.0;  // s, [0, 60]: at most one STATUSTEXT per interval
  double pose_timeout_s = 1.0;             // s, (0, 60]: no pose for this long = a fault (CRITICAL)
  // TUM pose log of every published pose (pose_log.hpp), appended to; empty: none.
  std::string pose_log;
  int pose_log_buffer_kb = 64;  // KiB, [1, 65536]: the log's line buffer, written when full
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("frame", s.frame);
    v("heartbeat_hz", s.heartbeat_hz);
    v("system_id", s.system_id);
    v("component_id", s.component_id);
    v("position_sigma_m", s.position_sigma_m);
    v("position_sigma_per_m", s.position_sigma_per_m);
    v("attitude_sigma_deg", s.attitude_sigma_deg);
    v("full_quality_inliers", s.full_quality_inliers);
    v("origin_period_s", s.origin_period_s);
    v("statustext_min_interval_s", s.statustext_min_interval_s);
    v("pose_timeout_s", s.pose_timeout_s);
    v("pose_log", s.pose_log);
    v("pose_log_buffer_kb", s.pose_log_buffer_kb);
  }
};

// Where the camera sits on the vehicle: T_b_c, the raw left camera c in the body frame b that
// the telemetry reports (MAV_FRAME_BODY_FRD: x forward, y right, z down; its origin is the point
// the autopilot tracks). The attitude is relative to a camera looking forward with its image
// upright (c.z = b.x, c.x = b.y, c.y = b.z), turned by yaw, then pitch, then roll about the body
// axes: C_b_c = Rz(yaw) Ry(pitch) Rx(roll) C_b_c(forward). With a raw calibration the estimator's
// camera is the rectified left camera, turned by the rectification (its centre is the same).
struct BodyConfig {
  double camera_yaw_deg = 0.0;    // deg, [-180, 180]: + turns the optical axis to the right
  double camera_pitch_deg = 0.0;  // deg, [-90, 90]: + tilts the optical axis up
  double camera_roll_deg = 0.0;   // deg, [-180, 180]: + lowers the image's right side
  // Lever arm: the left camera's optical centre in b (t_b_c), m, each in [-100, 100].
  double camera_x_m = 0.0;  // m, forward of the body origin
  double camera_y_m = 0.0;  // m, right of it
  double camera_z_m = 0.0;  // m, below it
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("camera_yaw_deg", s.camera_yaw_deg);
    v("camera_pitch_deg", s.camera_pitch_deg);
    v("camera_roll_deg", s.camera_roll_deg);
    v("camera_x_m", s.camera_x_m);
    v("camera_y_m", s.camera_y_m);
    v("camera_z_m", s.camera_z_m);
  }
};

// Field health (health_watch.hpp): when to give up so that systemd's Restart=on-failure fires.
struct HealthConfig {
  // s, [0, 3600]: a fault (the camera delivers no frame, the estimator is lost on every frame,
  // no pose is published) that lasts this long ends the program with exit code 3; 0 = never.
  double fault_exit_s = 10.0;
  // s, (0, 60]: the watchdog (WATCHDOG=1) is fed only while the last pose is younger than this.
  double watchdog_pose_age_s = 2.0;
  // warn | refuse: the system clock is not synchronised at start-up (the sun's UTC is unchecked).
  ClockUnsyncedAction clock_unsynced = ClockUnsyncedAction::kWarn;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("fault_exit_s", s.fault_exit_s);
    v("watchdog_pose_age_s", s.watchdog_pose_age_s);
    v("clock_unsynced", s.clock_unsynced);
  }
};

struct ThreadsConfig {
  runtime::ThreadPolicy capture{80, -1};
  runtime::ThreadPolicy estimator{70, -1};
  runtime::ThreadPolicy sun{20, -1};
  runtime::ThreadPolicy telemetry{75, -1};
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("capture", s.capture);
    v("estimator", s.estimator);
    v("sun", s.sun);
    v("telemetry", s.telemetry);
  }
};

struct RtConfig {
  bool lock_memory = true;  // mlockall(MCL_CURRENT | MCL_FUTURE)
  // MiB, [0, 4096]: heap made resident at start-up for the estimator's per-frame allocations
  // (one malloc arena, no mmap blocks, no trimming; see runtime::configureRealTimeHeap); 0 = off
  int heap_reserve_mb = 64;
  ThreadsConfig threads;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("lock_memory", s.lock_memory);
    v("heap_reserve_mb", s.heap_reserve_mb);
    v("threads", s.threads);
  }
};

struct ProfilingConfig {
  int ring_frames = 8192;                // frames, power of two [2, 1048576]: stage stamps kept
  std::string output_dir = "out/rover";  // CSV, trace and summary go here (created)
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("ring_frames", s.ring_frames);
    v("output_dir", s.output_dir);
  }
};

// The estimator's defaults on a rover: a 40 ms solver budget for an on-time frame, and the image
// estimators' attitude random-walk cap of 0.01 deg/frame (their errors are correlated along a
// street: docs/sun_estimators.md, benchmark drives; raise it, e.g. 0.05, for a source whose errors
// are independent from frame to frame, such as a sun sensor or the csv provider's true sun).
pipeline::SunAidedOptions roverEstimatorDefaults();

struct RoverConfig {
  std::string path;  // the file it was read from
  SourceConfig source;
  TriggerConfig trigger;
  runtime::FramePoolOptions frames;
  QueueConfig queues;
  WorldConfig world;
  pipeline::SunAidedOptions estimator = roverEstimatorDefaults();
  RealtimeConfig realtime;
  SunConfig sun;
  SerialConfig serial;
  TelemetryConfig telemetry;
  BodyConfig body;
  HealthConfig health;
  RtConfig rt;
  ProfilingConfig profiling;

  // Checks every range; the message names the key (without the file).
  Status validate() const;
  // The options as "key: value" lines, printed once at start-up.
  std::string describe() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("source", s.source);
    v("trigger", s.trigger);
    v("frames", s.frames);
    v("queues", s.queues);
    v("world", s.world);
    v("estimator", s.estimator);
    v("realtime", s.realtime);
    v("sun", s.sun);
    v("serial", s.serial);
    v("telemetry", s.telemetry);
    v("body", s.body);
    v("health", s.health);
    v("rt", s.rt);
    v("profiling", s.profiling);
  }
};

// Reads the file, applies overrides ("key.path", "value") on top, rejects unknown keys, checks
// ranges. Relative paths in the file stay relative to the working directory.
Expected<RoverConfig> loadRoverConfig(
    const std::string& path,
    const std::vector<std::pair<std::string, std::string>>& overrides = {});

}  // namespace sunvo::rover
