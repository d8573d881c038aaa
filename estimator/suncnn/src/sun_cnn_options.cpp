#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>
#include <vector>

#include "sunvo/suncnn/sun_cnn_estimator.hpp"

namespace sunvo::suncnn {

std::string modelJsonPath(const std::string& model_path) {
  std::filesystem::path p(model_path);
  p.replace_extension(".json");
  return p.string();
}

// The JSON is read with yaml-cpp (JSON is YAML), not cv::FileStorage: fuzzing found OpenCV's
// parsers looping and crashing on damaged calibration files (docs/hardening.md), and
// FileNode::operator[] threw out of this reader on a section that was not an object
// (tests/fuzz: sun_cnn_options).
Expected<SunCnnOptions> loadSunCnnOptions(const std::string& json_path, const SunCnnOptions& base) {
  std::ifstream in(json_path, std::ios::binary);
  if (!in) return notFound("suncnn: cannot open the model's JSON " + json_path);
  std::ostringstream text;
  text << in.rdbuf();
  Status st;
  SunCnnOptions o = base;
  try {
    YAML::Node parsed;
    try {
      parsed = YAML::Load(text.str());
    } catch (const YAML::Exception& e) {
      return parseError("suncnn: " + json_path + ": line " + std::to_string(e.mark.line + 1) +
                        ": not valid JSON: " + e.msg);
    }
    const YAML::Node& root = parsed;  // const: a lookup never inserts a key
    if (!root.IsMap()) return parseError("suncnn: " + json_path + ": not a JSON object");
    // A section that is absent keeps every default; one that is not an object is an error.
    const auto section = [&](const char* key) {
      const YAML::Node n = root[key];
      if (n && !n.IsNull() && !n.IsMap() && st.isOk()) {
        st = parseError("suncnn: " + json_path + ": key '" + key + "' is not an object");
      }
      return n && n.IsMap() ? n : YAML::Node(YAML::NodeType::Map);
    };
    // One number; a missing key keeps the default. A non-number, a non-finite number or, for an
    // integer field, a fraction or an out-of-range value is an error naming the key.
    const auto num = [&](const YAML::Node& parent, const char* key, const std::string& name,
                         auto& out) {
      using T = std::remove_reference_t<decltype(out)>;
      if (!st.isOk()) return;
      const YAML::Node n = parent[key];
      if (!n || n.IsNull()) return;
      double v = 0.0;
      if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
        st = parseError("suncnn: " + json_path + ": key '" + name + "' is not a number");
        return;
      }
      if constexpr (std::is_integral_v<T>) {
        if (v != std::floor(v) || v < static_cast<double>(std::numeric_limits<T>::min()) ||
            v > static_cast<double>(std::numeric_limits<T>::max())) {
          st = parseError("suncnn: " + json_path + ": key '" + name + "' is not an integer");
          return;
        }
      }
      out = static_cast<T>(v);
    };
    // A list of numbers; a missing key leaves `out` empty.
    const auto numbers = [&](const YAML::Node& parent, const char* key, const std::string& name,
                             std::vector<double>& out) {
      out.clear();
      if (!st.isOk()) return;
      const YAML::Node n = parent[key];
      if (!n || n.IsNull()) return;
      if (!n.IsSequence()) {
        st = parseError("suncnn: " + json_path + ": key '" + name + "' is not a list");
        return;
      }
      out.reserve(n.size());
      for (std::size_t i = 0; i < n.size(); ++i) {
        double v = 0.0;
        if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v)) {
          st = parseError("suncnn: " + json_path + ": key '" + name + "[" + std::to_string(i) +
                          "]' is not a number");
          return;
        }
        out.push_back(v);
      }
    };
    // A feature prior (sun_cnn_features.hpp): components, features, and per member its mean,
    // axes and variances, concatenated member after member. Sizes are checked by validate().
    const auto prior = [&](const YAML::Node& parent, const std::string& name,
                           SunCnnFeaturePrior& out) {
      out = SunCnnFeaturePrior{};
      const YAML::Node n = parent["feature_prior"];
      if (!n || n.IsNull() || !st.isOk()) return;
      if (!n.IsMap()) {
        st = parseError("suncnn: " + json_path + ": key '" + name + "' is not an object");
        return;
      }
      num(n, "components", name + ".components", out.components);
      num(n, "features", name + ".features", out.features);
      const YAML::Node members = n["members"];
      if (st.isOk() && (!members || !members.IsSequence())) {
        st = parseError("suncnn: " + json_path + ": key '" + name + ".members' is not a list");
        return;
      }
      std::vector<double> part;
      for (std::size_t m = 0; st.isOk() && m < members.size(); ++m) {
        const std::string at = name + ".members[" + std::to_string(m) + "]";
        if (!members[m].IsMap()) {
          st = parseError("suncnn: " + json_path + ": key '" + at + "' is not an object");
          return;
        }
        for (auto [key, dst] : {std::pair{"mean", &out.mean}, std::pair{"axes", &out.axes},
                                std::pair{"variances", &out.variances}}) {
          numbers(members[m], key, at + "." + key, part);
          dst->insert(dst->end(), part.begin(), part.end());
        }
      }
      if (st.isOk() && out.components == 0)
        st = parseError("suncnn: " + json_path + ": key '" + name + ".components' is 0");
    };
    const YAML::Node in_node = section("input"), mc = section("mc");
    num(in_node, "width", "input.width", o.input_width);
    num(in_node, "height", "input.height", o.input_height);
    num(in_node, "channels", "input.channels", o.input_channels);
    num(mc, "members", "mc.members", o.ensemble_members);
    num(mc, "rows", "mc.rows", o.mask_rows);
    num(mc, "mask1", "mc.mask1", o.mask1_size);
    num(mc, "mask2", "mc.mask2", o.mask2_size);
    num(mc, "dropout_p", "mc.dropout_p", o.dropout_p);
    num(root, "sigma_scale", "sigma_scale", o.sigma_scale);
    num(root, "max_valid_sigma_rad", "max_valid_sigma_rad", o.max_valid_sigma_rad);
    // A JSON without the elevation gain was calibrated without the elevation term: gain 0.
    o.elevation_gain = 0.0;
    num(root, "elevation_gain", "elevation_gain", o.elevation_gain);
    // Likewise a JSON without the feature term: gain 0 and no prior.
    o.feature_gain = 0.0;
    num(root, "feature_gain", "feature_gain", o.feature_gain);
    prior(root, "feature_prior", o.feature_prior);
    // Grey images on a colour model: their own calibration where the JSON has one, else the
    // colour calibration (a model calibrated before grey inputs had their own numbers).
    const YAML::Node gray = section("gray_input");
    if (gray.size() == 0) {
      o.gray_sigma_scale = o.sigma_scale;
      o.gray_max_valid_sigma_rad = o.max_valid_sigma_rad;
      o.gray_elevation_gain = o.elevation_gain;
      o.gray_feature_gain = o.feature_gain;
      o.gray_feature_prior = o.feature_prior;
    } else {
      o.gray_elevation_gain = 0.0;
      o.gray_feature_gain = 0.0;
      prior(gray, "gray_input.feature_prior", o.gray_feature_prior);
    }
    num(gray, "sigma_scale", "gray_input.sigma_scale", o.gray_sigma_scale);
    num(gray, "max_valid_sigma_rad", "gray_input.max_valid_sigma_rad", o.gray_max_valid_sigma_rad);
    num(gray, "elevation_gain", "gray_input.elevation_gain", o.gray_elevation_gain);
    num(gray, "feature_gain", "gray_input.feature_gain", o.gray_feature_gain);
  } catch (const YAML::Exception& e) {
    return parseError("suncnn: " + json_path + ": " + e.what());
  }
  SUNVO_RETURN_IF_ERROR(st);
  if (auto v = o.validate(); !v.isOk()) return invalidArgument(json_path + ": " + v.message());
  return o;
}

Expected<SunCnnOptions> optionsForModel(const std::string& model_path) {
  const std::string json = modelJsonPath(model_path);
  if (!std::filesystem::exists(json)) return SunCnnOptions{};
  return loadSunCnnOptions(json);
}

}  // namespace sunvo::suncnn
