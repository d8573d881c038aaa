#include "datasets.hpp"

#include <filesystem>

#include "sunvo/dataset/dataset.hpp"
#include "sunvo/files/sun_csv.hpp"
#include "sunvo/kitti/stereo_source.hpp"

namespace sunvo::suneval {

SetSpec parseSetSpec(const std::string& text) {
  std::error_code ec;
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon + 1 == text.size() || std::filesystem::exists(text, ec)) {
    return SetSpec{text, ""};
  }
  return SetSpec{text.substr(0, colon), text.substr(colon + 1)};
}

Expected<EvalDataset> loadEvalDataset(const std::string& dir, const EvalSetOptions& options) {
  const int max_frames = options.max_frames;
  const std::string& sun_csv = options.sun_csv;
  dataset::DatasetOptions o;
  o.path = dir;
  o.utc_offset_s = options.utc_offset_s;
  o.sun_csv = sun_csv;
  if (max_frames > 0) o.last_frame = max_frames - 1;
  auto ds = dataset::Dataset::open(o);
  if (!ds && max_frames > 0 &&
      ds.status().message().find("dataset.last_frame") != std::string::npos) {
    o.last_frame = -1;  // fewer frames than asked for: all of them
    ds = dataset::Dataset::open(o);
  }
  if (!ds) return ds.status();
  if (!ds->hasImages()) return invalidArgument(dir + ": no images (" + ds->describe() + ")");
  // A sun file but no poses (a KITTI odometry test sequence): the sun in camera 0 is all the
  // evaluation needs; "up" is then the camera's -y, the rig taken as level.
  std::vector<Eigen::Vector3d> csv_sun_c;
  if (!ds->sunKnown() && !sun_csv.empty() && !ds->hasGroundTruth() && ds->size() > 0) {
    auto sun = files::readSunCsv(sun_csv);
    if (!sun) return sun.status();
    const auto need = static_cast<std::size_t>(ds->recordingIndex(ds->size() - 1)) + 1;
    if (sun->sun_c.size() < need) {
      return invalidArgument(sun_csv + ": " + std::to_string(sun->sun_c.size()) +
                             " rows, fewer than the " + std::to_string(need) + " frames");
    }
    csv_sun_c = std::move(sun->sun_c);
  } else if (!ds->sunKnown()) {
    return notFound(dir + ": no true sun: " + ds->sunUnknownReason());
  }
  kitti::KittiSourceOptions so = ds->imageSourceOptions();
  if (options.camera == CameraChoice::kColor && !ds->colorCamera()) {
    return invalidArgument(dir + ": no colour camera (image_2 or image_02) for --camera color");
  }
  so.use_color = ds->colorCamera().has_value() && options.camera != CameraChoice::kGray;
  auto source = kitti::KittiStereoSource::open(so);
  if (!source) return source.status();
  EvalDataset out;
  std::filesystem::path p(dir);
  if (p.filename().empty()) p = p.parent_path();
  out.name = p.filename().string();
  out.camera = so.use_color ? *ds->colorCamera() : ds->camera();
  out.color = so.use_color;
  out.level_assumed = ds->world() == dataset::WorldFrame::kFirstCamera || !csv_sun_c.empty();
  const Eigen::Vector3d up_w = ds->worldUp();
  for (std::size_t k = 0; k < ds->size(); ++k) {
    EvalFrame f;
    f.image_path = source->imagePath(so.use_color ? 2 : 0, ds->recordingIndex(k));
    if (csv_sun_c.empty()) {
      f.true_sun_c = ds->trueSun()[k].sun_c;
      f.true_up_c = ds->groundTruth()[k].linear().transpose() * up_w;
    } else {
      f.true_sun_c = csv_sun_c[static_cast<std::size_t>(ds->recordingIndex(k))].normalized();
      f.true_up_c = -Eigen::Vector3d::UnitY();
    }
    out.frames.push_back(f);
  }
  return out;
}

}  // namespace sunvo::suneval
