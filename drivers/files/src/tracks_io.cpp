#include "sunvo/files/tracks_io.hpp"

#include <cstdio>
#include <memory>

namespace sunvo::files {

Status TrackReadOptions::validate() const {
  if (image_width <= 0) return invalidArgument("tracks: image_width must be > 0 px");
  if (image_height <= 0) return invalidArgument("tracks: image_height must be > 0 px");
  return Status::ok();
}

Expected<StereoCamera> parseTrackCalib(TextFile& file, int image_width, int image_height) {
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 5) {
      return file.lineError("expected 5 fields 'fu fv cu cv baseline_m', got " +
                            std::to_string(fields.size()));
    }
    static constexpr const char* kNames[5] = {"fu", "fv", "cu", "cv", "baseline_m"};
    double v[5];
    for (int i = 0; i < 5; ++i) {
      auto x = file.parseDouble(fields[static_cast<std::size_t>(i)], kNames[i]);
      if (!x) return x.status();
      v[i] = *x;
    }
    StereoCamera cam;
    cam.fu = v[0];
    cam.fv = v[1];
    cam.cu = v[2];
    cam.cv = v[3];
    cam.baseline_m = v[4];
    cam.width = image_width;
    cam.height = image_height;
    if (!(cam.fu > 0.0)) return file.error("fu", "must be > 0");
    if (!(cam.fv > 0.0)) return file.error("fv", "must be > 0");
    if (!(cam.baseline_m > 0.0)) return file.error("baseline_m", "must be > 0");
    SUNVO_RETURN_IF_ERROR(cam.validate());
    return cam;
  }
  return parseError(file.path() + ": no calibration line");
}

Expected<std::vector<TimeNs>> parseFrameTimes(TextFile& file) {
  std::vector<TimeNs> times;
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 1) return file.lineError("expected one field 'seconds'");
    const std::string_view text = fields[0];
    const std::size_t dot = text.find('.');
    const std::string_view whole = text.substr(0, dot);
    auto s = file.parseInt(whole, "seconds");
    if (!s) return s.status();
    if (*s < 0 || *s > 9'000'000'000LL) return file.error("seconds", "out of range");
    std::int64_t ns = 0;
    if (dot != std::string_view::npos) {
      const std::string_view frac = text.substr(dot + 1);
      if (frac.empty() || frac.size() > 9) {
        return file.error("seconds",
                          "fraction must have 1 to 9 digits: '" + std::string(text) + "'");
      }
      for (char c : frac) {
        if (c < '0' || c > '9')
          return file.error("seconds", "not a number: '" + std::string(text) + "'");
        ns = ns * 10 + (c - '0');
      }
      for (std::size_t i = frac.size(); i < 9; ++i) ns *= 10;
    }
    const TimeNs t = *s * kNsPerSecond + ns;
    if (!times.empty() && t <= times.back()) return file.error("seconds", "times must increase");
    times.push_back(t);
  }
  if (times.empty()) return parseError(file.path() + ": no frame times");
  return times;
}

Expected<std::vector<Isometry3>> parseKittiPoses(TextFile& file) {
  std::vector<Isometry3> poses;
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 12) {
      return file.lineError("expected 12 fields (3x4 pose), got " + std::to_string(fields.size()));
    }
    Eigen::Matrix<double, 3, 4> Rt;
    for (int i = 0; i < 12; ++i) {
      const std::string name = "T[" + std::to_string(i / 4) + "][" + std::to_string(i % 4) + "]";
      auto x = file.parseDouble(fields[static_cast<std::size_t>(i)], name);
      if (!x) return x.status();
      Rt(i / 4, i % 4) = *x;
    }
    const Eigen::Matrix3d R = Rt.leftCols<3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3) {
      return file.error("T[0..2][0..2]", "not a rotation (R^T R differs from I by > 1e-3)");
    }
    poses.push_back(isometryFrom3x4(Rt));
  }
  return poses;
}

Expected<std::vector<FrameFeatures>> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                                 int image_width, int image_height) {
  std::string_view line;
  // Header.
  bool have_header = false;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line, ',');
    static constexpr const char* kHeader[6] = {"frame", "landmark", "uL", "vL", "uR", "vR"};
    if (fields.size() != 6) return file.lineError("expected header 'frame,landmark,uL,vL,uR,vR'");
    for (std::size_t i = 0; i < 6; ++i) {
      if (fields[i] != kHeader[i]) {
        return file.error(kHeader[i], "unexpected header name '" + std::string(fields[i]) + "'");
      }
    }
    have_header = true;
    break;
  }
  if (!have_header) return parseError(file.path() + ": empty file, no header");

  std::vector<FrameFeatures> frames(times.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k].sequence = k;
    frames[k].time_ns = times[k];
  }
  std::int64_t last_frame = -1;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto f = splitFields(line, ',');
    if (f.size() != 6) {
      return file.lineError("expected 6 fields 'frame,landmark,uL,vL,uR,vR', got " +
                            std::to_string(f.size()));
    }
    auto frame = file.parseInt(f[0], "frame");
    if (!frame) return frame.status();
    auto landmark = file.parseInt(f[1], "landmark");
    if (!landmark) return landmark.status();
    if (*frame < 0 || *frame >= static_cast<std::int64_t>(frames.size())) {
      return file.error("frame", "out of range [0, " + std::to_string(frames.size()) +
                                     ") given by times.txt: " + std::to_string(*frame));
    }
    if (*frame < last_frame) {
      return file.error("frame", "frames out of order: " + std::to_string(*frame) + " after " +
                                     std::to_string(last_frame));
    }
    if (*landmark < 0) return file.error("landmark", "must be >= 0");
    static constexpr const char* kNames[4] = {"uL", "vL", "uR", "vR"};
    double px[4];
    for (int i = 0; i < 4; ++i) {
      auto x = file.parseDouble(f[static_cast<std::size_t>(i) + 2], kNames[i]);
      if (!x) return x.status();
      const double limit = (i % 2 == 0) ? image_width : image_height;
      if (*x < 0.0 || *x >= limit) {
        return file.error(kNames[i], "outside the image [0, " +
                                         std::to_string(static_cast<int>(limit)) +
                                         "): " + std::string(f[static_cast<std::size_t>(i) + 2]));
      }
      px[i] = *x;
    }
    FrameFeatures& ff = frames[static_cast<std::size_t>(*frame)];
    if (*frame != last_frame) last_frame = *frame;
    for (const auto& o : ff.observations) {
      if (o.landmark_id == *landmark) return file.error("landmark", "duplicate in this frame");
    }
    StereoObservation o;
    o.landmark_id = *landmark;
    o.u_left = px[0];
    o.v_left = px[1];
    o.u_right = px[2];
    o.v_right = px[3];
    ff.observations.push_back(o);
  }
  return frames;
}

Expected<TrackSequence> readTrackFolder(const std::string& folder,
                                        const TrackReadOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  TrackSequence seq;
  {
    auto f = TextFile::open(folder + "/calib.txt");
    if (!f) return f.status();
    auto cam = parseTrackCalib(*f, options.image_width, options.image_height);
    if (!cam) return cam.status();
    seq.camera = *cam;
  }
  std::vector<TimeNs> times;
  {
    auto f = TextFile::open(folder + "/times.txt");
    if (!f) return f.status();
    auto t = parseFrameTimes(*f);
    if (!t) return t.status();
    times = std::move(*t);
  }
  {
    auto f = TextFile::open(folder + "/tracks.csv");
    if (!f) return f.status();
    auto fr = parseTracks(*f, times, options.image_width, options.image_height);
    if (!fr) return fr.status();
    seq.frames = std::move(*fr);
  }
  {
    auto f = TextFile::open(folder + "/gt_poses.txt");
    if (!f) {
      if (options.require_gt || f.status().code() != StatusCode::kNotFound) return f.status();
    } else {
      auto p = parseKittiPoses(*f);
      if (!p) return p.status();
      if (p->size() != seq.frames.size()) {
        return parseError(folder + "/gt_poses.txt: " + std::to_string(p->size()) + " poses for " +
                          std::to_string(seq.frames.size()) + " frames");
      }
      seq.gt_T_0_k = std::move(*p);
    }
  }
  return seq;
}

Status writeKittiPoses(const std::string& path, const std::vector<Isometry3>& T_0_k) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(path.c_str(), "w"), &std::fclose);
  if (!out) return ioError(path + ": cannot open for writing");
  for (const auto& T : T_0_k) {
    const Eigen::Matrix4d M = T.matrix();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        std::fprintf(out.get(), (r == 2 && c == 3) ? "%.9e\n" : "%.9e ", M(r, c));
      }
    }
  }
  if (std::ferror(out.get()) != 0) return ioError(path + ": write failed");
  return Status::ok();
}

}  // namespace sunvo::files
