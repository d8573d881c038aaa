#include <filesystem>
#include <opencv2/core/persistence.hpp>

#include "sunvo/suncnn/sun_cnn_estimator.hpp"

namespace sunvo::suncnn {

std::string modelJsonPath(const std::string& model_path) {
  std::filesystem::path p(model_path);
  p.replace_extension(".json");
  return p.string();
}

Expected<SunCnnOptions> loadSunCnnOptions(const std::string& json_path, const SunCnnOptions& base) {
  cv::FileStorage fs;
  try {
    if (!fs.open(json_path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON))
      return notFound("suncnn: cannot open the model's JSON " + json_path);
  } catch (const cv::Exception& e) {
    return parseError("suncnn: " + json_path + ": not valid JSON: " + e.msg);
  }
  SunCnnOptions o = base;
  // Reads one number; a missing key keeps the default, a non-number is an error naming it.
  Status st;
  auto num = [&](const cv::FileNode& parent, const char* key, const std::string& name, auto& out) {
    if (!st.isOk()) return;
    const cv::FileNode n = parent[key];
    if (n.empty() || n.isNone()) return;
    if (!n.isReal() && !n.isInt()) {
      st = parseError("suncnn: " + json_path + ": key '" + name + "' is not a number");
      return;
    }
    out = static_cast<std::remove_reference_t<decltype(out)>>(static_cast<double>(n));
  };
  const cv::FileNode root = fs.root(), in = root["input"], mc = root["mc"];
  num(in, "width", "input.width", o.input_width);
  num(in, "height", "input.height", o.input_height);
  num(in, "channels", "input.channels", o.input_channels);
  num(mc, "members", "mc.members", o.ensemble_members);
  num(mc, "rows", "mc.rows", o.mask_rows);
  num(mc, "mask1", "mc.mask1", o.mask1_size);
  num(mc, "mask2", "mc.mask2", o.mask2_size);
  num(mc, "dropout_p", "mc.dropout_p", o.dropout_p);
  num(root, "sigma_scale", "sigma_scale", o.sigma_scale);
  num(root, "max_valid_sigma_rad", "max_valid_sigma_rad", o.max_valid_sigma_rad);
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
