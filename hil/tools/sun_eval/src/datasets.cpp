#include "datasets.hpp"

#include <filesystem>

#include "sunvo/dataset/dataset.hpp"
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

Expected<EvalDataset> loadEvalDataset(const std::string& dir, int max_frames,
                                      std::optional<std::int64_t> utc_offset_s,
                                      const std::string& sun_csv) {
  dataset::DatasetOptions o;
  o.path = dir;
  o.utc_offset_s = utc_offset_s;
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
  if (!ds->sunKnown()) return notFound(dir + ": no true sun: " + ds->sunUnknownReason());
  kitti::KittiSourceOptions so = ds->imageSourceOptions();
  so.use_color = ds->colorCamera().has_value();
  auto source = kitti::KittiStereoSource::open(so);
  if (!source) return source.status();
  EvalDataset out;
  std::filesystem::path p(dir);
  if (p.filename().empty()) p = p.parent_path();
  out.name = p.filename().string();
  out.camera = so.use_color ? *ds->colorCamera() : ds->camera();
  out.level_assumed = ds->world() == dataset::WorldFrame::kFirstCamera;
  const Eigen::Vector3d up_w = ds->worldUp();
  for (std::size_t k = 0; k < ds->size(); ++k) {
    EvalFrame f;
    f.image_path = source->imagePath(so.use_color ? 2 : 0, ds->recordingIndex(k));
    f.true_sun_c = ds->trueSun()[k].sun_c;
    f.true_up_c = ds->groundTruth()[k].linear().transpose() * up_w;
    out.frames.push_back(f);
  }
  return out;
}

}  // namespace sunvo::suneval
