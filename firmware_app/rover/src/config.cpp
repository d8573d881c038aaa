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
      // A complex key ("? [a, b]: 1") has no name to check (found by fuzzing: as<std::string>()
      // threw out of the reader).
      if (!kv.first.IsScalar()) {
        return invalidArgument(file_ + ":" + line(kv.first) + ": " +
                               (prefix.empty() ? std::string("top level") : prefix) +
                               ": a key must be a plain name");
      }
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

// Reads every field of an options struct from its YAML map (core/fields.hpp): sections recurse,
// enums by name, scalars by type; the first error stops the walk.
class ReadVisitor {
 public:
  ReadVisitor(Reader& r, YAML::Node map, std::string prefix)
      : r_(r), map_(std::move(map)), prefix_(std::move(prefix)) {}

  template <typename T>
  void operator()(const char* key, T& value) {
    if (!status_.isOk()) return;
    if constexpr (OptionsStruct<T>) {
      YAML::Node node;
      status_ = r_.section(map_, prefix_, key, &node);
      if (!status_.isOk()) return;
      ReadVisitor sub(r_, node, prefix_.empty() ? key : prefix_ + "." + key);
      T::fields(value, sub);
      status_ = sub.status();
    } else if constexpr (NamedEnum<T>) {
      std::vector<std::string> names;
      for (const std::string_view n : enumNames(value)) names.emplace_back(n);
      int v = static_cast<int>(value);
      status_ = r_.getEnum(map_, prefix_, key, names, &v);
      value = static_cast<T>(v);
    } else {
      status_ = r_.get(map_, prefix_, key, &value);
    }
  }
  const Status& status() const { return status_; }

 private:
  Reader& r_;
  YAML::Node map_;
  std::string prefix_;
  Status status_;
};

// "key: value" for every field, one per line (the start-up description).
class DescribeVisitor {
 public:
  explicit DescribeVisitor(std::ostringstream& out, std::string prefix = "")
      : out_(out), prefix_(std::move(prefix)) {}

  template <typename T>
  void operator()(const char* key, const T& value) {
    const std::string name = prefix_.empty() ? key : prefix_ + "." + key;
    if constexpr (OptionsStruct<T>) {
      DescribeVisitor sub(out_, name);
      T::fields(value, sub);
    } else if constexpr (NamedEnum<T>) {
      out_ << "  " << name << ": " << enumName(value) << "\n";
    } else if constexpr (std::is_same_v<T, bool>) {
      out_ << "  " << name << ": " << (value ? "true" : "false") << "\n";
    } else {
      out_ << "  " << name << ": " << value << "\n";
    }
  }

 private:
  std::ostringstream& out_;
  std::string prefix_;
};

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

std::span<const std::string_view> enumNames(SourceType) {
  static constexpr std::string_view kNames[] = {"kitti", "v4l2"};
  return kNames;
}
std::span<const std::string_view> enumNames(TriggerType) {
  static constexpr std::string_view kNames[] = {"simulated", "gpio"};
  return kNames;
}
std::span<const std::string_view> enumNames(EndAction) {
  static constexpr std::string_view kNames[] = {"stop", "hold", "loop", "pingpong"};
  return kNames;
}
std::span<const std::string_view> enumNames(WorldInit) {
  static constexpr std::string_view kNames[] = {"oxts", "config"};
  return kNames;
}
std::span<const std::string_view> enumNames(ClockUnsyncedAction) {
  static constexpr std::string_view kNames[] = {"warn", "refuse"};
  return kNames;
}
std::span<const std::string_view> enumNames(SunProviderType) {
  static constexpr std::string_view kNames[] = {"none", "csv", "lalonde", "lalonde_vo", "sun_cnn"};
  return kNames;
}

pipeline::SunAidedOptions roverEstimatorDefaults() {
  pipeline::SunAidedOptions o;
  o.pipeline.vo.window.max_solver_time_in_seconds = 0.040;
  using Image = sunfusion::ImageEstimatorFusion;  // the rover's sun comes from the images
  o.fusion.max_drift_deg_per_frame = Image::kMaxDriftDegPerFrame;
  o.fusion.sun_bias_sigma_deg = Image::kSunBiasSigmaDeg;
  o.fusion.sun_bias_length_frames = Image::kSunBiasLengthFrames;
  return o;
}

Status RoverConfig::validate() const {
  SUNVO_RETURN_IF_ERROR(checkRange("source.max_consecutive_bad_frames",
                                   source.max_consecutive_bad_frames, 1, 1000000));
  SUNVO_RETURN_IF_ERROR(source.faults.validate("source.faults"));
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
    if (const Status r = source.v4l2.rectify.validate(); !r.isOk()) {
      return Status(r.code(), "source.v4l2.rectify." + r.message());
    }
    if (source.v4l2.left_color && source.v4l2.pixel_format != v4l2::V4l2PixelFormat::kYuyv) {
      return invalidArgument("source.v4l2.left_color: needs source.v4l2.pixel_format yuyv");
    }
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
  if (frames.pool_depth < queues.frames + 2) {
    return invalidArgument(
        "frames.pool_depth: " + std::to_string(frames.pool_depth) +
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
  // The estimator's own ranges, named by its keys.
  if (const Status e = estimator.validate(); !e.isOk()) {
    return Status(e.code(), "estimator." + e.message());
  }
  if (estimator.pipeline.frontend.max_features > 2000) {
    return outside("estimator.frontend.max_features", estimator.pipeline.frontend.max_features,
                   "[16, 2000] (the rover's frame budget)");
  }
  const double max_solver_ms = estimator.pipeline.vo.window.max_solver_time_in_seconds * 1e3;
  SUNVO_RETURN_IF_ERROR(checkRange("estimator.window.max_solver_time_in_seconds",
                                   estimator.pipeline.vo.window.max_solver_time_in_seconds, 0.001,
                                   1.0));
  const RealtimeConfig& rtc = realtime;
  SUNVO_RETURN_IF_ERROR(
      checkRange("realtime.min_solver_time_ms", rtc.min_solver_time_ms, 0.1, max_solver_ms));
  SUNVO_RETURN_IF_ERROR(checkRange("realtime.deadline_ms", rtc.deadline_ms, 10, 10000));
  SUNVO_RETURN_IF_ERROR(checkRange("realtime.publish_margin_ms", rtc.publish_margin_ms, 0, 1000));
  SUNVO_RETURN_IF_ERROR(checkRange("realtime.warmup_frames", rtc.warmup_frames, 0, 100000));
  SUNVO_RETURN_IF_ERROR(checkRange("realtime.sun_wait_ms", rtc.sun_wait_ms, 0, 100));
  SUNVO_RETURN_IF_ERROR(checkOpenLow("sun.csv_sigma", sun.csv_sigma, 0.0, 2.0));
  if (sun.provider == SunProviderType::kCsv && sun.csv.empty()) {
    return invalidArgument("sun.csv: empty, but sun.provider is csv");
  }
  if (sun.provider == SunProviderType::kSunCnn && sun.model.empty()) {
    return invalidArgument("sun.model: empty, but sun.provider is sun_cnn");
  }
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_yaw_deg", body.camera_yaw_deg, -180, 180));
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_pitch_deg", body.camera_pitch_deg, -90, 90));
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_roll_deg", body.camera_roll_deg, -180, 180));
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_x_m", body.camera_x_m, -100, 100));
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_y_m", body.camera_y_m, -100, 100));
  SUNVO_RETURN_IF_ERROR(checkRange("body.camera_z_m", body.camera_z_m, -100, 100));
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
  SUNVO_RETURN_IF_ERROR(
      checkRange("telemetry.position_sigma_per_m", telemetry.position_sigma_per_m, 0.0, 1.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("telemetry.origin_period_s", telemetry.origin_period_s, 0.0, 3600.0));
  SUNVO_RETURN_IF_ERROR(checkRange("telemetry.statustext_min_interval_s",
                                   telemetry.statustext_min_interval_s, 0.0, 60.0));
  SUNVO_RETURN_IF_ERROR(
      checkOpenLow("telemetry.pose_timeout_s", telemetry.pose_timeout_s, 0.0, 60.0));
  SUNVO_RETURN_IF_ERROR(
      checkRange("telemetry.pose_log_buffer_kb", telemetry.pose_log_buffer_kb, 1, 65536));
  SUNVO_RETURN_IF_ERROR(checkRange("health.fault_exit_s", health.fault_exit_s, 0.0, 3600.0));
  SUNVO_RETURN_IF_ERROR(
      checkOpenLow("health.watchdog_pose_age_s", health.watchdog_pose_age_s, 0.0, 60.0));
  SUNVO_RETURN_IF_ERROR(checkRange("rt.heap_reserve_mb", rt.heap_reserve_mb, 0, 4096));
  SUNVO_RETURN_IF_ERROR(rt.threads.capture.validate("rt.threads.capture"));
  SUNVO_RETURN_IF_ERROR(rt.threads.estimator.validate("rt.threads.estimator"));
  SUNVO_RETURN_IF_ERROR(rt.threads.sun.validate("rt.threads.sun"));
  SUNVO_RETURN_IF_ERROR(rt.threads.telemetry.validate("rt.threads.telemetry"));
  SUNVO_RETURN_IF_ERROR(checkRange("profiling.ring_frames", profiling.ring_frames, 2, 1048576));
  if (!runtime::isPowerOfTwo(static_cast<std::size_t>(profiling.ring_frames))) {
    return invalidArgument("profiling.ring_frames: " + std::to_string(profiling.ring_frames) +
                           " is not a power of two");
  }
  return Status::ok();
}

std::string RoverConfig::describe() const {
  std::ostringstream o;
  o << "config " << path << ":\n";
  DescribeVisitor v(o);
  fields(*this, v);
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
  // The reader checks node types before converting; a yaml-cpp exception that still escapes it
  // is a bad file, never the end of the program.
  try {
    ReadVisitor visitor(reader, root, "");
    RoverConfig::fields(config, visitor);
    SUNVO_RETURN_IF_ERROR(visitor.status());
    SUNVO_RETURN_IF_ERROR(reader.checkUnknown(root, ""));
  } catch (const YAML::Exception& e) {
    return parseError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const Status s = config.validate();
  if (!s.isOk()) return Status(s.code(), path + ": " + s.message());
  return config;
}

}  // namespace sunvo::rover
