#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>

#include "sunvo/core/time.hpp"
#include "sunvo/render/drive.hpp"

// The scenario YAML: reading, key checking and validation (the rendering is in drive.cpp).

namespace sunvo::render {
namespace {
Status range(const std::string& key, const char* r) {
  return invalidArgument(key + " out of range " + r);
}

// --- YAML helpers: every key is checked against the allowed set and its value parsed with
// the key named in the error. yaml-cpp throws; the exceptions stop here.
struct Reader {
  std::string label;
  Status st;
  void keys(const YAML::Node& n, const std::string& sec, const std::set<std::string>& allowed) {
    if (!st.isOk() || !n) return;
    if (!n.IsMap()) {
      st = invalidArgument(label + ": " + (sec.empty() ? "top level" : sec) + " must be a map");
      return;
    }
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      if (allowed.count(k) == 0) {
        st = invalidArgument(label + ": unknown key '" + (sec.empty() ? k : sec + "." + k) + "'");
        return;
      }
    }
  }
  template <typename T>
  void get(const YAML::Node& n, const std::string& sec, const char* key, T& out) {
    if (!st.isOk() || !n || !n[key]) return;
    try {
      out = n[key].as<T>();
    } catch (const YAML::Exception&) {
      st = invalidArgument(label + ": key '" + sec + (sec.empty() ? "" : ".") + key +
                           "': not a valid value");
    }
  }
};
}  // namespace

Status CalibErrorOptions::validate() const {
  if (!(focal_scale >= 0.9 && focal_scale <= 1.1))
    return range("calib_error.focal_scale", "[0.9, 1.1]");
  if (!(cu_offset_px >= -20 && cu_offset_px <= 20))
    return range("calib_error.cu_offset_px", "[-20, 20]");
  if (!(cv_offset_px >= -20 && cv_offset_px <= 20))
    return range("calib_error.cv_offset_px", "[-20, 20]");
  if (!(baseline_scale >= 0.9 && baseline_scale <= 1.1))
    return range("calib_error.baseline_scale", "[0.9, 1.1]");
  return Status::ok();
}

Status RigErrorOptions::validate() const {
  const std::pair<const char*, double> angles[] = {{"right_roll_start_deg", right_roll_start_deg},
                                                   {"right_roll_end_deg", right_roll_end_deg},
                                                   {"right_pitch_start_deg", right_pitch_start_deg},
                                                   {"right_pitch_end_deg", right_pitch_end_deg},
                                                   {"right_yaw_start_deg", right_yaw_start_deg},
                                                   {"right_yaw_end_deg", right_yaw_end_deg}};
  for (const auto& [key, value] : angles) {
    if (!(value >= -1.0 && value <= 1.0)) return range(std::string("rig_error.") + key, "[-1, 1]");
  }
  return Status::ok();
}

bool RigErrorOptions::any() const {
  return right_roll_start_deg != 0.0 || right_roll_end_deg != 0.0 || right_pitch_start_deg != 0.0 ||
         right_pitch_end_deg != 0.0 || right_yaw_start_deg != 0.0 || right_yaw_end_deg != 0.0;
}

Status Scenario::validate() const {
  if (name.empty() || name.find('/') != std::string::npos)
    return invalidArgument("name: empty or contains '/'");
  if (!(drive_number >= 0 && drive_number <= 9999)) return range("drive_number", "[0, 9999]");
  if (!(latitude_deg >= -90 && latitude_deg <= 90)) return range("place.latitude_deg", "[-90, 90]");
  if (!(longitude_deg >= -180 && longitude_deg <= 180))
    return range("place.longitude_deg", "[-180, 180]");
  if (!(altitude_m >= -500 && altitude_m <= 9000)) return range("place.altitude_m", "[-500, 9000]");
  if (!(grid_heading_deg >= -180 && grid_heading_deg <= 180))
    return range("place.grid_heading_deg", "[-180, 180]");
  if (!(frames >= 1 && frames <= 100000)) return range("frames", "[1, 100000]");
  if (!(sky_image_width >= 32 && sky_image_width <= 4096))
    return range("sky.image_width", "[32, 4096]");
  SUNVO_RETURN_IF_ERROR(sky.validate());
  SUNVO_RETURN_IF_ERROR(city.validate());
  SUNVO_RETURN_IF_ERROR(route.validate());
  SUNVO_RETURN_IF_ERROR(traffic.validate());
  if (auto st = camera.validate(); !st.isOk()) return invalidArgument("camera: " + st.message());
  SUNVO_RETURN_IF_ERROR(quality.validate());
  SUNVO_RETURN_IF_ERROR(sensor.validate());
  SUNVO_RETURN_IF_ERROR(style.validate());
  SUNVO_RETURN_IF_ERROR(calib_error.validate());
  SUNVO_RETURN_IF_ERROR(rig_error.validate());
  return Status::ok();
}

Expected<Scenario> parseScenario(const std::string& text, const std::string& label) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return parseError(label + ": YAML: " + e.what());
  }
  Scenario s;
  Reader r{label, {}};
  try {
    r.keys(root, "",
           {"name", "drive_number", "place", "start_utc", "frames", "seed", "sky", "city", "route",
            "traffic", "camera", "render", "sensor", "calib_error", "style", "rig_error"});
    r.get(root, "", "name", s.name);
    r.get(root, "", "drive_number", s.drive_number);
    r.get(root, "", "frames", s.frames);
    r.get(root, "", "seed", s.seed);
    std::string start = "2011-09-26 13:00:00";
    r.get(root, "", "start_utc", start);
    if (r.st.isOk()) {
      auto t = parseCivilTime(start, 0);
      if (!t) return invalidArgument(label + ": key 'start_utc': " + t.status().message());
      s.start_utc = *t;
    }
    const YAML::Node place = root["place"];
    r.keys(place, "place", {"latitude_deg", "longitude_deg", "altitude_m", "grid_heading_deg"});
    r.get(place, "place", "latitude_deg", s.latitude_deg);
    r.get(place, "place", "longitude_deg", s.longitude_deg);
    r.get(place, "place", "altitude_m", s.altitude_m);
    r.get(place, "place", "grid_heading_deg", s.grid_heading_deg);
    const YAML::Node sky = root["sky"];
    r.keys(sky, "sky", {"turbidity", "image_width"});
    r.get(sky, "sky", "turbidity", s.sky.turbidity);
    r.get(sky, "sky", "image_width", s.sky_image_width);
    const YAML::Node c = root["city"];
    r.keys(c, "city",
           {"blocks_x", "blocks_y", "block_size_m", "street_width_m", "sidewalk_width_m",
            "min_height_m", "max_height_m", "min_lot_m", "max_lot_m", "pole_spacing_m",
            "tree_probability", "parked_car_probability", "plain_block_probability"});
    r.get(c, "city", "blocks_x", s.city.blocks_x);
    r.get(c, "city", "blocks_y", s.city.blocks_y);
    r.get(c, "city", "block_size_m", s.city.block_size_m);
    r.get(c, "city", "street_width_m", s.city.street_width_m);
    r.get(c, "city", "sidewalk_width_m", s.city.sidewalk_width_m);
    r.get(c, "city", "min_height_m", s.city.min_height_m);
    r.get(c, "city", "max_height_m", s.city.max_height_m);
    r.get(c, "city", "min_lot_m", s.city.min_lot_m);
    r.get(c, "city", "max_lot_m", s.city.max_lot_m);
    r.get(c, "city", "pole_spacing_m", s.city.pole_spacing_m);
    r.get(c, "city", "tree_probability", s.city.tree_probability);
    r.get(c, "city", "parked_car_probability", s.city.parked_car_probability);
    r.get(c, "city", "plain_block_probability", s.city.plain_block_probability);
    const YAML::Node ro = root["route"];
    r.keys(ro, "route",
           {"speed_min_mps", "speed_max_mps", "max_lateral_accel_mps2", "max_long_accel_mps2",
            "turn_probability", "turn_radius_m", "lane_offset_m", "rate_hz", "pitch_amplitude_deg",
            "roll_amplitude_deg", "roll_per_lateral_accel_deg", "pitch_per_long_accel_deg"});
    r.get(ro, "route", "speed_min_mps", s.route.speed_min_mps);
    r.get(ro, "route", "speed_max_mps", s.route.speed_max_mps);
    r.get(ro, "route", "max_lateral_accel_mps2", s.route.max_lateral_accel_mps2);
    r.get(ro, "route", "max_long_accel_mps2", s.route.max_long_accel_mps2);
    r.get(ro, "route", "turn_probability", s.route.turn_probability);
    r.get(ro, "route", "turn_radius_m", s.route.turn_radius_m);
    r.get(ro, "route", "lane_offset_m", s.route.lane_offset_m);
    r.get(ro, "route", "rate_hz", s.route.rate_hz);
    r.get(ro, "route", "pitch_amplitude_deg", s.route.pitch_amplitude_deg);
    r.get(ro, "route", "roll_amplitude_deg", s.route.roll_amplitude_deg);
    r.get(ro, "route", "roll_per_lateral_accel_deg", s.route.roll_per_lateral_accel_deg);
    r.get(ro, "route", "pitch_per_long_accel_deg", s.route.pitch_per_long_accel_deg);
    const YAML::Node tr = root["traffic"];
    r.keys(tr, "traffic",
           {"cars", "speed_min_mps", "speed_max_mps", "lane_offset_m", "clearance_m"});
    r.get(tr, "traffic", "cars", s.traffic.cars);
    r.get(tr, "traffic", "speed_min_mps", s.traffic.speed_min_mps);
    r.get(tr, "traffic", "speed_max_mps", s.traffic.speed_max_mps);
    r.get(tr, "traffic", "lane_offset_m", s.traffic.lane_offset_m);
    r.get(tr, "traffic", "clearance_m", s.traffic.clearance_m);
    const YAML::Node cam = root["camera"];
    r.keys(cam, "camera", {"fu", "fv", "cu", "cv", "baseline_m", "width", "height"});
    r.get(cam, "camera", "fu", s.camera.fu);
    r.get(cam, "camera", "fv", s.camera.fv);
    r.get(cam, "camera", "cu", s.camera.cu);
    r.get(cam, "camera", "cv", s.camera.cv);
    r.get(cam, "camera", "baseline_m", s.camera.baseline_m);
    r.get(cam, "camera", "width", s.camera.width);
    r.get(cam, "camera", "height", s.camera.height);
    const YAML::Node q = root["render"];
    r.keys(q, "render", {"antialias_threshold", "antialias_depth", "quality"});
    r.get(q, "render", "antialias_threshold", s.quality.antialias_threshold);
    r.get(q, "render", "antialias_depth", s.quality.antialias_depth);
    r.get(q, "render", "quality", s.quality.quality);
    const YAML::Node se = root["sensor"];
    r.keys(se, "sensor",
           {"full_well_e", "read_noise_e", "vignetting", "exposure_sigma", "exposure_target",
            "motion_blur_px", "defocus_sigma_px", "white_balance_r", "white_balance_b", "response",
            "gamma", "contrast"});
    r.get(se, "sensor", "full_well_e", s.sensor.full_well_e);
    r.get(se, "sensor", "read_noise_e", s.sensor.read_noise_e);
    r.get(se, "sensor", "vignetting", s.sensor.vignetting);
    r.get(se, "sensor", "exposure_sigma", s.sensor.exposure_sigma);
    r.get(se, "sensor", "exposure_target", s.sensor.exposure_target);
    r.get(se, "sensor", "motion_blur_px", s.sensor.motion_blur_px);
    r.get(se, "sensor", "defocus_sigma_px", s.sensor.defocus_sigma_px);
    r.get(se, "sensor", "white_balance_r", s.sensor.white_balance_r);
    r.get(se, "sensor", "white_balance_b", s.sensor.white_balance_b);
    r.get(se, "sensor", "response", s.sensor.response);
    r.get(se, "sensor", "gamma", s.sensor.gamma);
    r.get(se, "sensor", "contrast", s.sensor.contrast);
    const YAML::Node sty = root["style"];
    r.keys(sty, "style", {"seed", "set", "frames_per_look"});
    r.get(sty, "style", "seed", s.style.seed);
    r.get(sty, "style", "set", s.style.set);
    r.get(sty, "style", "frames_per_look", s.style.frames_per_look);
    const YAML::Node ce = root["calib_error"];
    r.keys(ce, "calib_error", {"focal_scale", "cu_offset_px", "cv_offset_px", "baseline_scale"});
    r.get(ce, "calib_error", "focal_scale", s.calib_error.focal_scale);
    r.get(ce, "calib_error", "cu_offset_px", s.calib_error.cu_offset_px);
    r.get(ce, "calib_error", "cv_offset_px", s.calib_error.cv_offset_px);
    r.get(ce, "calib_error", "baseline_scale", s.calib_error.baseline_scale);
    const YAML::Node re = root["rig_error"];
    r.keys(re, "rig_error",
           {"right_roll_start_deg", "right_roll_end_deg", "right_pitch_start_deg",
            "right_pitch_end_deg", "right_yaw_start_deg", "right_yaw_end_deg"});
    r.get(re, "rig_error", "right_roll_start_deg", s.rig_error.right_roll_start_deg);
    r.get(re, "rig_error", "right_roll_end_deg", s.rig_error.right_roll_end_deg);
    r.get(re, "rig_error", "right_pitch_start_deg", s.rig_error.right_pitch_start_deg);
    r.get(re, "rig_error", "right_pitch_end_deg", s.rig_error.right_pitch_end_deg);
    r.get(re, "rig_error", "right_yaw_start_deg", s.rig_error.right_yaw_start_deg);
    r.get(re, "rig_error", "right_yaw_end_deg", s.rig_error.right_yaw_end_deg);
  } catch (const YAML::Exception& e) {
    return parseError(label + ": YAML: " + e.what());
  }
  SUNVO_RETURN_IF_ERROR(r.st);
  if (auto st = s.validate(); !st.isOk()) return invalidArgument(label + ": " + st.message());
  s.source_text = text;
  return s;
}

Expected<Scenario> loadScenario(const std::string& path) {
  std::ifstream f(path);
  if (!f) return notFound("cannot open scenario " + path);
  std::stringstream ss;
  ss << f.rdbuf();
  return parseScenario(ss.str(), path);
}

}  // namespace sunvo::render
