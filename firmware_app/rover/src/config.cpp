#include "sunvo/rover/config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <sstream>

#include "sunvo/rover/sun_provider.hpp"
#include "sunvo/runtime/spsc_queue.hpp"

namespace sunvo::rover {
namespace {

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// "<key>: <value> is outside <range>".
Status outside(const std::string& key, double value, const std::string& range) {
  return invalidArgument(key + ": " + num(value) + " is outside " + range);
}

std::string interval(char open, double lo, double hi) {
  std::ostringstream s;
  s << open << lo << ", " << hi << ']';
  return s.str();
}

Status checkRange(const std::string& key, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi)) return outside(key, v, interval('[', lo, hi));
  return Status::ok();
}

// (lo, hi]
Status checkOpenLow(const std::string& key, double v, double lo, double hi) {
  if (!(v > lo && v <= hi)) return outside(key, v, interval('(', lo, hi));
  return Status::ok();
}

Status checkQueue(const std::string& key, int v, int hi) {
  SUNVO_RETURN_IF_ERROR(checkRange(key, v, 1, hi));
  if (!runtime::isPowerOfTwo(static_cast<std::size_t>(v))) {
    return invalidArgument(key + ": " + std::to_string(v) + " is not a power of two");
  }
  return Status::ok();
}

// Walks the YAML tree with the option structs: every map's keys are checked against the keys
// read from it, every scalar is converted with its key (and line) in the error.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  // A nested map (absent = defaults). Records the keys this section may hold.
  Status section(const YAML::Node& parent, const std::string& prefix, const char* key,
                 YAML::Node* out) {
    // reset() rebinds the handle; assigning a Node would overwrite the node it refers to.
    out->reset();
    sections_.insert(join(prefix, key));
    if (!parent[key]) return Status::ok();
    const YAML::Node node = parent[key];
    if (!node.IsMap() && !node.IsNull()) return typeError(node, join(prefix, key), "a map");
    out->reset(node);
    return Status::ok();
  }

  template <typename T>
  Status get(const YAML::Node& map, const std::string& prefix, const char* key, T* out) {
    seen_.insert(join(prefix, key));
    if (!map || !map.IsMap() || !map[key]) return Status::ok();
    const YAML::Node node = map[key];
    if (!node.IsScalar()) return typeError(node, join(prefix, key), "a scalar");
    try {
      *out = node.as<T>();
    } catch (const YAML::Exception&) {
      return typeError(node, join(prefix, key), typeName(out));
    }
    return Status::ok();
  }

  Status getEnum(const YAML::Node& map, const std::string& prefix, const char* key,
                 const std::vector<std::string>& names, int* out) {
    std::string value = names[static_cast<std::size_t>(*out)];
    SUNVO_RETURN_IF_ERROR(get(map, prefix, key, &value));
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == value) {
        *out = static_cast<int>(i);
        return Status::ok();
      }
    }
    std::string list;
    for (const auto& n : names) {
      if (!list.empty()) list += ", ";
      list += n;
    }
    return invalidArgument(file_ + ":" + line(map[key]) + ": " + join(prefix, key) + ": '" + value +
                           "' is not one of " + list);
  }

  // Every key of the file must have been read by a get() (sections are walked recursively).
  Status checkUnknown(const YAML::Node& node, const std::string& prefix) const {
    if (!node.IsMap()) return Status::ok();
    for (const auto& kv : node) {
      const std::string key = join(prefix, kv.first.as<std::string>());
      if (sections_.count(key) != 0) {
        SUNVO_RETURN_IF_ERROR(checkUnknown(kv.second, key));  // a null section is empty
      } else if (seen_.count(key) == 0) {
        return unknown(kv.first, key);
      }
    }
    return Status::ok();
  }

  const std::string& file() const { return file_; }

 private:
  static std::string join(const std::string& prefix, const std::string& key) {
    return prefix.empty() ? key : prefix + "." + key;
  }
  static std::string line(const YAML::Node& n) { return std::to_string(n.Mark().line + 1); }
  template <typename T>
  static const char* typeName(T*) {
    if constexpr (std::is_same_v<T, bool>) return "true or false";
    if constexpr (std::is_integral_v<T>) return "an integer";
    if constexpr (std::is_floating_point_v<T>) return "a number";
    return "a string";
  }
  Status typeError(const YAML::Node& n, const std::string& key, const char* what) const {
    return invalidArgument(file_ + ":" + line(n) + ": " + key + ": expected " + what);
  }
  Status unknown(const YAML::Node& n, const std::string& key) const {
    return invalidArgument(file_ + ":" + line(n) + ": " + key + ": unknown key");
  }

  std::string file_;
  std::set<std::string> seen_;      // scalar keys read
  std::set<std::string> sections_;  // map keys walked
};

template <typename E>
Status readEnum(Reader& r, const YAML::Node& map, const std::string& prefix, const char* key,
                const std::vector<std::string>& names, E* out) {
  int v = static_cast<int>(*out);
  SUNVO_RETURN_IF_ERROR(r.getEnum(map, prefix, key, names, &v));
  *out = static_cast<E>(v);
  return Status::ok();
}

const std::vector<std::string> kSourceNames = {"kitti", "v4l2"};
const std::vector<std::string> kTriggerNames = {"simulated", "gpio"};
const std::vector<std::string> kLayoutNames = {"two_devices", "side_by_side"};
const std::vector<std::string> kPixelFormatNames = {"grey", "yuyv"};
const std::vector<std::string> kEndNames = {"stop", "hold", "loop", "pingpong"};
const std::vector<std::string> kWorldNames = {"oxts", "config"};
const std::vector<std::string> kSunNames = {"none", "csv", "lalonde", "lalonde_vo", "sun_cnn"};

Status readThread(Reader& r, const YAML::Node& threads, const char* name,
                  runtime::ThreadPolicy* p) {
  YAML::Node n;
  SUNVO_RETURN_IF_ERROR(r.section(threads, "rt.threads", name, &n));
  const std::string prefix = std::string("rt.threads.") + name;
  SUNVO_RETURN_IF_ERROR(r.get(n, prefix, "fifo_priority", &p->fifo_priority));
  return r.get(n, prefix, "cpu", &p->cpu);
}

Status readAll(Reader& r, const YAML::Node& root, RoverConfig* c) {
  YAML::Node n, m;
  // source
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "source", &n));
  SUNVO_RETURN_IF_ERROR(readEnum(r, n, "source", "type", kSourceNames, &c->source.type));
  SUNVO_RETURN_IF_ERROR(r.section(n, "source", "kitti", &m));
  KittiSourceConfig& k = c->source.kitti;
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "drive_dir", &k.drive_dir));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "utc_offset_s", &k.utc_offset_s));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "preload", &k.preload));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "first_frame", &k.first_frame));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "last_frame", &k.last_frame));
  SUNVO_RETURN_IF_ERROR(readEnum(r, m, "source.kitti", "end", kEndNames, &k.end));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.kitti", "total_frames", &k.total_frames));
  SUNVO_RETURN_IF_ERROR(r.section(n, "source", "v4l2", &m));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.v4l2", "left_device", &c->source.v4l2.left_device));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.v4l2", "right_device", &c->source.v4l2.right_device));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.v4l2", "calibration", &c->source.v4l2.calibration));
  SUNVO_RETURN_IF_ERROR(
      readEnum(r, m, "source.v4l2", "layout", kLayoutNames, &c->source.v4l2.layout));
  SUNVO_RETURN_IF_ERROR(readEnum(r, m, "source.v4l2", "pixel_format", kPixelFormatNames,
                                 &c->source.v4l2.pixel_format));
  SUNVO_RETURN_IF_ERROR(r.get(m, "source.v4l2", "buffer_count", &c->source.v4l2.buffer_count));
  SUNVO_RETURN_IF_ERROR(
      r.get(m, "source.v4l2", "dequeue_timeout_ms", &c->source.v4l2.dequeue_timeout_ms));
  // trigger
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "trigger", &n));
  TriggerConfig& t = c->trigger;
  SUNVO_RETURN_IF_ERROR(readEnum(r, n, "trigger", "type", kTriggerNames, &t.type));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "rate_hz", &t.rate_hz));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "follow_recording", &t.follow_recording));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "timeout_factor", &t.timeout_factor));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "gpio_chip", &t.gpio_chip));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "gpio_line", &t.gpio_line));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "frame_delay_ms", &t.frame_delay_ms));
  SUNVO_RETURN_IF_ERROR(r.get(n, "trigger", "match_window_ms", &t.match_window_ms));
  // frames
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "frames", &n));
  SUNVO_RETURN_IF_ERROR(r.get(n, "frames", "width", &c->frames.width));
  SUNVO_RETURN_IF_ERROR(r.get(n, "frames", "height", &c->frames.height));
  SUNVO_RETURN_IF_ERROR(r.get(n, "frames", "pool_depth", &c->frames.depth));
  // queues
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "queues", &n));
  SUNVO_RETURN_IF_ERROR(r.get(n, "queues", "frames", &c->queues.frames));
  SUNVO_RETURN_IF_ERROR(r.get(n, "queues", "sun_requests", &c->queues.sun_requests));
  SUNVO_RETURN_IF_ERROR(r.get(n, "queues", "sun_results", &c->queues.sun_results));
  SUNVO_RETURN_IF_ERROR(r.get(n, "queues", "poses", &c->queues.poses));
  // world
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "world", &n));
  WorldConfig& w = c->world;
  SUNVO_RETURN_IF_ERROR(readEnum(r, n, "world", "init", kWorldNames, &w.init));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "latitude_deg", &w.latitude_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "longitude_deg", &w.longitude_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "altitude_m", &w.altitude_m));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "camera_heading_deg", &w.camera_heading_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "camera_pitch_deg", &w.camera_pitch_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "world", "camera_roll_deg", &w.camera_roll_deg));
  // estimator
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "estimator", &n));
  EstimatorConfig& e = c->estimator;
  SUNVO_RETURN_IF_ERROR(r.section(n, "estimator", "window", &m));
  SUNVO_RETURN_IF_ERROR(r.get(m, "estimator.window", "size", &e.window_size));
  SUNVO_RETURN_IF_ERROR(r.get(m, "estimator.window", "max_iterations", &e.max_iterations));
  SUNVO_RETURN_IF_ERROR(r.get(m, "estimator.window", "max_solver_time_ms", &e.max_solver_time_ms));
  SUNVO_RETURN_IF_ERROR(r.get(m, "estimator.window", "min_solver_time_ms", &e.min_solver_time_ms));
  SUNVO_RETURN_IF_ERROR(r.get(n, "estimator", "deadline_ms", &e.deadline_ms));
  SUNVO_RETURN_IF_ERROR(r.get(n, "estimator", "publish_margin_ms", &e.publish_margin_ms));
  SUNVO_RETURN_IF_ERROR(r.get(n, "estimator", "max_features", &e.max_features));
  SUNVO_RETURN_IF_ERROR(r.get(n, "estimator", "warmup_frames", &e.warmup_frames));
  // sun
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "sun", &n));
  SunConfig& s = c->sun;
  SUNVO_RETURN_IF_ERROR(readEnum(r, n, "sun", "provider", kSunNames, &s.provider));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "every_n_frames", &s.every_n_frames));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "csv", &s.csv));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "model", &s.model));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "sigma", &s.sigma));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "wait_ms", &s.wait_ms));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "estimate_base_attitude", &s.estimate_base_attitude));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "max_cosine_distance", &s.max_cosine_distance));
  SUNVO_RETURN_IF_ERROR(
      r.get(n, "sun", "initial_attitude_sigma_deg", &s.initial_attitude_sigma_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "sun", "max_drift_deg_per_frame", &s.max_drift_deg_per_frame));
  // serial
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "serial", &n));
  SUNVO_RETURN_IF_ERROR(r.get(n, "serial", "device", &c->serial.device));
  SUNVO_RETURN_IF_ERROR(r.get(n, "serial", "baud", &c->serial.baud));
  SUNVO_RETURN_IF_ERROR(r.get(n, "serial", "tx_buffer_bytes", &c->serial.tx_buffer_bytes));
  // telemetry
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "telemetry", &n));
  TelemetryConfig& tm = c->telemetry;
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "heartbeat_hz", &tm.heartbeat_hz));
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "system_id", &tm.system_id));
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "component_id", &tm.component_id));
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "position_sigma_m", &tm.position_sigma_m));
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "attitude_sigma_deg", &tm.attitude_sigma_deg));
  SUNVO_RETURN_IF_ERROR(r.get(n, "telemetry", "full_quality_inliers", &tm.full_quality_inliers));
  // rt
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "rt", &n));
  SUNVO_RETURN_IF_ERROR(r.get(n, "rt", "lock_memory", &c->rt.lock_memory));
  SUNVO_RETURN_IF_ERROR(r.get(n, "rt", "heap_reserve_mb", &c->rt.heap_reserve_mb));
  SUNVO_RETURN_IF_ERROR(r.section(n, "rt", "threads", &m));
  SUNVO_RETURN_IF_ERROR(readThread(r, m, "capture", &c->rt.capture));
  SUNVO_RETURN_IF_ERROR(readThread(r, m, "estimator", &c->rt.estimator));
  SUNVO_RETURN_IF_ERROR(readThread(r, m, "sun", &c->rt.sun));
  SUNVO_RETURN_IF_ERROR(readThread(r, m, "telemetry", &c->rt.telemetry));
  // profiling
  SUNVO_RETURN_IF_ERROR(r.section(root, "", "profiling", &n));
  SUNVO_RETURN_IF_ERROR(r.get(n, "profiling", "ring_frames", &c->profiling.ring_frames));
  SUNVO_RETURN_IF_ERROR(r.get(n, "profiling", "output_dir", &c->profiling.output_dir));
  return r.checkUnknown(root, "");
}

// Deep-merges src into dst (maps merged key by key, anything else replaced).
void merge(YAML::Node dst, const YAML::Node& src) {
  for (const auto& kv : src) {
    const std::string key = kv.first.as<std::string>();
    if (kv.second.IsMap() && dst[key] && dst[key].IsMap()) {
      merge(dst[key], kv.second);
    } else {
      dst[key] = kv.second;
    }
  }
}

}  // namespace

Status RoverConfig::validate() const {
  const KittiSourceConfig& k = source.kitti;
  if (source.type == SourceType::kKitti) {
    if (k.drive_dir.empty()) return invalidArgument("source.kitti.drive_dir: empty");
    SUNVO_RETURN_IF_ERROR(checkRange("source.kitti.utc_offset_s",
                                     static_cast<double>(k.utc_offset_s), -50400, 50400));
    if (k.first_frame < 0) return outside("source.kitti.first_frame", k.first_frame, "[0, inf)");
    if (k.last_frame != -1 && k.last_frame < k.first_frame) {
      return invalidArgument("source.kitti.last_frame: " + std::to_string(k.last_frame) +
                             " is before source.kitti.first_frame");
    }
    if (k.total_frames < 0) return outside("source.kitti.total_frames", k.total_frames, "[0, inf)");
  }
  if (source.type == SourceType::kV4l2) {
    if (source.v4l2.calibration.empty()) return invalidArgument("source.v4l2.calibration: empty");
    SUNVO_RETURN_IF_ERROR(checkRange("source.v4l2.buffer_count", source.v4l2.buffer_count, 2, 32));
    SUNVO_RETURN_IF_ERROR(
        checkRange("source.v4l2.dequeue_timeout_ms", source.v4l2.dequeue_timeout_ms, 1, 60000));
    if (trigger.type != TriggerType::kGpio) {
      return invalidArgument("trigger.type: source.type v4l2 needs trigger.type gpio");
    }
  }
  if (trigger.type == TriggerType::kGpio && source.type != SourceType::kV4l2) {
    return invalidArgument("trigger.type: gpio needs source.type v4l2");
  }
  SUNVO_RETURN_IF_ERROR(checkOpenLow("trigger.rate_hz", trigger.rate_hz, 0.0, 200.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("trigger.frame_delay_ms", trigger.frame_delay_ms, -1000.0, 1000.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("trigger.match_window_ms", trigger.match_window_ms, 0.0, 500.0 / trigger.rate_hz));
  SUNVO_RETURN_IF_ERROR(checkRange("trigger.timeout_factor", trigger.timeout_factor, 1.5, 100.0));
  SUNVO_RETURN_IF_ERROR(checkRange("trigger.gpio_line", trigger.gpio_line, 0, 1023));
  SUNVO_RETURN_IF_ERROR(frames.validate());
  SUNVO_RETURN_IF_ERROR(checkQueue("queues.frames", queues.frames, 256));
  SUNVO_RETURN_IF_ERROR(checkQueue("queues.sun_requests", queues.sun_requests, 256));
  SUNVO_RETURN_IF_ERROR(checkQueue("queues.sun_results", queues.sun_results, 256));
  SUNVO_RETURN_IF_ERROR(checkQueue("queues.poses", queues.poses, 1024));
  if (frames.depth < queues.frames + 2) {
    return invalidArgument(
        "frames.pool_depth: " + std::to_string(frames.depth) +
        " must be >= queues.frames + 2 (one slot filling, one in the estimator)");
  }
  SUNVO_RETURN_IF_ERROR(checkRange("world.latitude_deg", world.latitude_deg, -90, 90));
  SUNVO_RETURN_IF_ERROR(checkRange("world.longitude_deg", world.longitude_deg, -180, 180));
  SUNVO_RETURN_IF_ERROR(checkRange("world.altitude_m", world.altitude_m, -500, 9000));
  SUNVO_RETURN_IF_ERROR(
      checkRange("world.camera_heading_deg", world.camera_heading_deg, -360, 360));
  SUNVO_RETURN_IF_ERROR(checkRange("world.camera_pitch_deg", world.camera_pitch_deg, -90, 90));
  SUNVO_RETURN_IF_ERROR(checkRange("world.camera_roll_deg", world.camera_roll_deg, -180, 180));
  if (world.init == WorldInit::kOxts && source.type != SourceType::kKitti) {
    return invalidArgument("world.init: oxts needs source.type: kitti");
  }
  const EstimatorConfig& e = estimator;
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.window.size", e.window_size, 2, 8));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.window.max_iterations", e.max_iterations, 1, 100));
  SUNVO_RETURN_IF_ERROR(
      checkRange("estimator.window.max_solver_time_ms", e.max_solver_time_ms, 1, 1000));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.window.min_solver_time_ms", e.min_solver_time_ms, 0.1,
                                   e.max_solver_time_ms));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.deadline_ms", e.deadline_ms, 10, 10000));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.publish_margin_ms", e.publish_margin_ms, 0, 1000));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.max_features", e.max_features, 16, 2000));
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.warmup_frames", e.warmup_frames, 0, 100000));
  SUNVO_RETURN_IF_ERROR(checkRange("sun.every_n_frames", sun.every_n_frames, 1, 1000));
  SUNVO_RETURN_IF_ERROR(checkOpenLow("sun.sigma", sun.sigma, 0.0, 2.0));
  SUNVO_RETURN_IF_ERROR(checkRange("sun.wait_ms", sun.wait_ms, 0, 100));
  SUNVO_RETURN_IF_ERROR(checkRange("sun.max_cosine_distance", sun.max_cosine_distance, 0, 2));
  SUNVO_RETURN_IF_ERROR(
      checkOpenLow("sun.initial_attitude_sigma_deg", sun.initial_attitude_sigma_deg, 0.0, 45.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("sun.max_drift_deg_per_frame", sun.max_drift_deg_per_frame, 0.002, 5.0));
  if (sun.provider == SunProviderType::kCsv && sun.csv.empty()) {
    return invalidArgument("sun.csv: empty, but sun.provider is csv");
  }
  if (sunProviderNeedsColour(sun.provider) && source.type == SourceType::kV4l2) {
    return invalidArgument("sun.provider: " + kSunNames[static_cast<std::size_t>(sun.provider)] +
                           " needs the left colour image; source.type: v4l2 delivers gray");
  }
  if (sun.provider == SunProviderType::kSunCnn && sun.model.empty()) {
    return invalidArgument("sun.model: empty, but sun.provider is sun_cnn");
  }
  SUNVO_RETURN_IF_ERROR(
      checkRange("serial.tx_buffer_bytes", serial.tx_buffer_bytes, 1024, 1048576));
  SUNVO_RETURN_IF_ERROR(checkOpenLow("telemetry.heartbeat_hz", telemetry.heartbeat_hz, 0.0, 50.0));
  SUNVO_RETURN_IF_ERROR(checkRange("telemetry.system_id", telemetry.system_id, 1, 255));
  SUNVO_RETURN_IF_ERROR(checkRange("telemetry.component_id", telemetry.component_id, 1, 255));
  SUNVO_RETURN_IF_ERROR(
      checkOpenLow("telemetry.position_sigma_m", telemetry.position_sigma_m, 0.0, 1000.0));
  SUNVO_RETURN_IF_ERROR(
      checkOpenLow("telemetry.attitude_sigma_deg", telemetry.attitude_sigma_deg, 0.0, 180.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("telemetry.full_quality_inliers", telemetry.full_quality_inliers, 1, 100000));
  SUNVO_RETURN_IF_ERROR(checkRange("rt.heap_reserve_mb", rt.heap_reserve_mb, 0, 4096));
  SUNVO_RETURN_IF_ERROR(rt.capture.validate("rt.threads.capture"));
  SUNVO_RETURN_IF_ERROR(rt.estimator.validate("rt.threads.estimator"));
  SUNVO_RETURN_IF_ERROR(rt.sun.validate("rt.threads.sun"));
  SUNVO_RETURN_IF_ERROR(rt.telemetry.validate("rt.threads.telemetry"));
  SUNVO_RETURN_IF_ERROR(checkRange("profiling.ring_frames", profiling.ring_frames, 2, 1048576));
  if (!runtime::isPowerOfTwo(static_cast<std::size_t>(profiling.ring_frames))) {
    return invalidArgument("profiling.ring_frames: " + std::to_string(profiling.ring_frames) +
                           " is not a power of two");
  }
  return Status::ok();
}

std::string RoverConfig::describe() const {
  std::ostringstream o;
  o << "config " << path << ":\n"
    << "  source: " << kSourceNames[static_cast<std::size_t>(source.type)];
  if (source.type == SourceType::kV4l2) {
    const V4l2SourceConfig& v = source.v4l2;
    o << " " << kLayoutNames[static_cast<std::size_t>(v.layout)] << " " << v.left_device << " "
      << v.right_device << " " << kPixelFormatNames[static_cast<std::size_t>(v.pixel_format)]
      << " buffers=" << v.buffer_count << " calibration=" << v.calibration << "\n";
  } else {
    o << " drive_dir=" << source.kitti.drive_dir << " preload=" << source.kitti.preload
      << " frames=[" << source.kitti.first_frame << ", " << source.kitti.last_frame << "]"
      << " end=" << kEndNames[static_cast<std::size_t>(source.kitti.end)]
      << " total_frames=" << source.kitti.total_frames << "\n";
  }
  o << "  trigger: " << kTriggerNames[static_cast<std::size_t>(trigger.type)]
    << " rate_hz=" << trigger.rate_hz << " follow_recording=" << trigger.follow_recording
    << (trigger.type == TriggerType::kGpio
            ? " strobe=" + trigger.gpio_chip + ":" + std::to_string(trigger.gpio_line)
            : std::string())
    << "\n"
    << "  frames: " << frames.width << "x" << frames.height << " pool_depth=" << frames.depth
    << "; queues: frames=" << queues.frames << " sun_requests=" << queues.sun_requests
    << " sun_results=" << queues.sun_results << " poses=" << queues.poses << "\n"
    << "  world: " << kWorldNames[static_cast<std::size_t>(world.init)];
  if (world.init == WorldInit::kConfig) {
    o << " lat=" << world.latitude_deg << " lon=" << world.longitude_deg
      << " alt=" << world.altitude_m << " heading=" << world.camera_heading_deg;
  } else {
    o << " (origin and first camera pose from the drive's first OXTS record)";
  }
  o << "\n"
    << "  estimator: window=" << estimator.window_size
    << " max_iterations=" << estimator.max_iterations << " solver_ms=["
    << estimator.min_solver_time_ms << ", " << estimator.max_solver_time_ms
    << "] deadline_ms=" << estimator.deadline_ms << " max_features=" << estimator.max_features
    << "\n"
    << "  sun: " << kSunNames[static_cast<std::size_t>(sun.provider)]
    << " every_n_frames=" << sun.every_n_frames << " wait_ms=" << sun.wait_ms << "\n"
    << "  serial: " << (serial.device.empty() ? "(none)" : serial.device) << " baud=" << serial.baud
    << "; heartbeat_hz=" << telemetry.heartbeat_hz << "\n"
    << "  rt: lock_memory=" << rt.lock_memory
    << " fifo capture/estimator/sun/telemetry=" << rt.capture.fifo_priority << "/"
    << rt.estimator.fifo_priority << "/" << rt.sun.fifo_priority << "/"
    << rt.telemetry.fifo_priority << "\n"
    << "  profiling: ring_frames=" << profiling.ring_frames
    << " output_dir=" << profiling.output_dir << "\n";
  return o.str();
}

Expected<RoverConfig> loadRoverConfig(
    const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return notFound(path + ": cannot read the config file");
  } catch (const YAML::Exception& e) {
    return parseError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) return parseError(path + ": the config must be a YAML map");
  for (const auto& [key, value] : overrides) {
    YAML::Node leaf;
    try {
      leaf = YAML::Load(value);
    } catch (const YAML::Exception& e) {
      return invalidArgument("--set " + key + "=" + value + ": " + e.msg);
    }
    std::vector<std::string> parts;
    std::stringstream ss(key);
    for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    if (parts.empty()) return invalidArgument("--set: empty key");
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
      YAML::Node m(YAML::NodeType::Map);
      m[*it] = leaf;
      leaf = m;
    }
    merge(root, leaf);
  }
  RoverConfig config;
  config.path = path;
  Reader reader(path);
  SUNVO_RETURN_IF_ERROR(readAll(reader, root, &config));
  const Status s = config.validate();
  if (!s.isOk()) return Status(s.code(), path + ": " + s.message());
  return config;
}

}  // namespace sunvo::rover
