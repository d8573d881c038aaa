#include "sunvo/bench/kitti_sample.hpp"

#include <array>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "sunvo/files/text_file.hpp"

namespace sunvo::bench {

Expected<StereoCamera> readKittiOdometryCalib(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  std::array<double, 12> p0{};
  std::array<double, 12> p1{};
  bool have_p0 = false;
  bool have_p1 = false;
  std::string_view line;
  while (file->nextLine(line)) {
    const auto fields = files::splitFields(line);
    if (fields.empty()) continue;
    std::array<double, 12>* target = nullptr;
    if (fields[0] == "P0:") {
      target = &p0;
      have_p0 = true;
    } else if (fields[0] == "P1:") {
      target = &p1;
      have_p1 = true;
    } else {
      continue;
    }
    if (fields.size() != 13) return file->error(fields[0], "expected 12 numbers");
    for (std::size_t i = 0; i < 12; ++i) {
      auto v = file->parseDouble(fields[i + 1], fields[0]);
      if (!v) return v.status();
      (*target)[i] = *v;
    }
  }
  if (!have_p0 || !have_p1) return parseError(path + ": missing P0 or P1");
  StereoCamera cam;
  cam.fu = p0[0];
  cam.cu = p0[2];
  cam.fv = p0[5];
  cam.cv = p0[6];
  // P1 = K [I | -b e_x] in rectified coordinates: P1[3] = -fu * b.
  if (!(p1[0] > 0.0)) return parseError(path + ": field 'P1'[0]: must be > 0");
  cam.baseline_m = -p1[3] / p1[0];
  return cam;
}

Expected<KittiOdometrySample> loadKittiOdometrySample(const std::string& dir) {
  auto cam = readKittiOdometryCalib(dir + "/calib.txt");
  if (!cam) return cam.status();
  KittiOdometrySample sample;
  sample.camera = *cam;
  auto times = files::TextFile::open(dir + "/times.txt");
  if (!times) return times.status();
  std::string_view line;
  while (times->nextLine(line)) {
    if (files::isBlank(line)) continue;
    auto t = times->parseDouble(files::splitFields(line)[0], "time");
    if (!t) return t.status();
    sample.times_s.push_back(*t);
  }
  for (std::size_t i = 0; i < sample.times_s.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%06zu.png", i);
    const std::string lp = dir + "/image_0" + name;
    const std::string rp = dir + "/image_1" + name;
    cv::Mat l = cv::imread(lp, cv::IMREAD_GRAYSCALE);
    cv::Mat r = cv::imread(rp, cv::IMREAD_GRAYSCALE);
    if (l.empty()) return notFound(lp + ": cannot read image");
    if (r.empty()) return notFound(rp + ": cannot read image");
    if (l.size() != r.size()) return invalidArgument(rp + ": size differs from the left image");
    sample.left.push_back(l);
    sample.right.push_back(r);
  }
  if (sample.left.empty()) return notFound(dir + ": no frames");
  sample.camera.width = sample.left[0].cols;
  sample.camera.height = sample.left[0].rows;
  return sample;
}

}  // namespace sunvo::bench
