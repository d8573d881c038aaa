#include "sunvo/files/tracks_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::files {
namespace {
constexpr int kMinSize = 16, kMaxSize = 16384;  // px, plausible image sizes
// With the size from the extent: the principal point is at least this share of the size.
constexpr double kMinPrincipalShare = 0.35;

std::string formatPx(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", v);
  return buf;
}
}  // namespace

Status TrackReadOptions::validate() const {
  const bool w = image_width != 0, h = image_height != 0;
  if (w != h) return invalidArgument("tracks: image_width and image_height: give both or neither");
  if (w && (image_width < kMinSize || image_width > kMaxSize)) {
    return invalidArgument("tracks: image_width must be 0 (from the data) or in [16, 16384] px");
  }
  if (h && (image_height < kMinSize || image_height > kMaxSize)) {
    return invalidArgument("tracks: image_height must be 0 (from the data) or in [16, 16384] px");
  }
  if (!(border_tolerance_px >= 0.0 && border_tolerance_px <= 50.0)) {
    return invalidArgument("tracks: border_tolerance_px must be in [0, 50] px");
  }
  return Status::ok();
}

Expected<StereoCamera> parseTrackCalibLine(TextFile& file, bool* has_size) {
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 5 && fields.size() != 7) {
      return file.lineError(
          "expected 5 fields 'fu fv cu cv baseline_m' or 7 with 'width height', "
          "got " +
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
    if (!(cam.fu > 0.0)) return file.error("fu", "must be > 0");
    if (!(cam.fv > 0.0)) return file.error("fv", "must be > 0");
    if (!(cam.baseline_m > 0.0)) return file.error("baseline_m", "must be > 0");
    *has_size = fields.size() == 7;
    if (*has_size) {
      static constexpr const char* kSize[2] = {"width", "height"};
      int* out[2] = {&cam.width, &cam.height};
      for (int i = 0; i < 2; ++i) {
        auto x = file.parseInt(fields[static_cast<std::size_t>(5 + i)], kSize[i]);
        if (!x) return x.status();
        if (*x < kMinSize || *x > kMaxSize) return file.error(kSize[i], "outside [16, 16384] px");
        *out[i] = static_cast<int>(*x);
      }
      SUNVO_RETURN_IF_ERROR(cam.validate());
    }
    return cam;
  }
  return parseError(file.path() + ": no calibration line");
}

Expected<StereoCamera> parseTrackCalib(TextFile& file, int image_width, int image_height) {
  bool has_size = false;
  auto cam = parseTrackCalibLine(file, &has_size);
  if (!cam) return cam.status();
  if (!has_size) {
    cam->width = image_width;
    cam->height = image_height;
    SUNVO_RETURN_IF_ERROR(cam->validate());
  }
  return cam;
}

Expected<ParsedTracks> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                   const TrackBounds& bounds) {
  std::string_view line;
  // Header.
  bool have_header = false;
  std::size_t columns = 6;  // 7 with the optional vR_measured
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line, ',');
    static constexpr const char* kHeader[7] = {"frame", "landmark", "uL",         "vL",
                                               "uR",    "vR",       "vR_measured"};
    if (fields.size() != 6 && fields.size() != 7) {
      return file.lineError("expected header 'frame,landmark,uL,vL,uR,vR[,vR_measured]'");
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (fields[i] != kHeader[i]) {
        return file.error(kHeader[i], "unexpected header name '" + std::string(fields[i]) + "'");
      }
    }
    columns = fields.size();
    have_header = true;
    break;
  }
  if (!have_header) return parseError(file.path() + ": empty file, no header");

  ParsedTracks out;
  std::vector<FrameFeatures>& frames = out.frames;
  frames.resize(times.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k].sequence = k;
    frames[k].time_ns = times[k];
  }
  const double tol = bounds.border_tolerance_px;
  std::int64_t last_frame = -1;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto f = splitFields(line, ',');
    if (f.size() != columns) {
      return file.lineError(columns == 6 ? "expected 6 fields 'frame,landmark,uL,vL,uR,vR', got " +
                                               std::to_string(f.size())
                                         : "expected 7 fields 'frame,landmark,uL,vL,uR,vR,"
                                           "vR_measured', got " +
                                               std::to_string(f.size()));
    }
    bool v_right_measured = true;
    if (columns == 7) {
      auto m = file.parseInt(f[6], "vR_measured");
      if (!m) return m.status();
      if (*m != 0 && *m != 1) return file.error("vR_measured", "must be 0 or 1");
      v_right_measured = *m == 1;
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
    bool outside = false;  // one of the four coordinates is outside the image, within tolerance
    for (int i = 0; i < 4; ++i) {
      const auto text = f[static_cast<std::size_t>(i) + 2];
      auto x = file.parseDouble(text, kNames[i]);
      if (!x) return x.status();
      px[i] = *x;
      // Inside: [0, limit); limit 0 = not known yet, no upper border.
      const int limit = (i % 2 == 0) ? bounds.width : bounds.height;
      const bool below = *x < 0.0;
      const bool above = limit > 0 && *x >= limit;
      if (!below && !above) continue;
      const double past = below ? -*x : *x - limit;  // px past the border
      if (past > tol) {
        const std::string range = limit > 0 ? "[0, " + std::to_string(limit) + ")" : "[0, inf)";
        return file.error(kNames[i], "outside the image " + range + " by more than the " +
                                         formatPx(tol) + " px tolerance: " + std::string(text));
      }
      outside = true;
      out.max_outside_px = std::max(out.max_outside_px, past);
    }
    if (*frame != last_frame) last_frame = *frame;
    if (outside) {
      ++out.dropped_past_border;
      continue;
    }
    FrameFeatures& ff = frames[static_cast<std::size_t>(*frame)];
    for (const auto& o : ff.observations) {
      if (o.landmark_id == *landmark) return file.error("landmark", "duplicate in this frame");
    }
    for (int i = 0; i < 4; ++i) {
      TrackExtent& e = (i % 2 == 0) ? out.u : out.v;
      if (e.line == 0 || px[i] > e.max_px) e = {px[i], file.lineNumber(), kNames[i]};
    }
    StereoObservation o;
    o.landmark_id = *landmark;
    o.u_left = px[0];
    o.v_left = px[1];
    o.u_right = px[2];
    o.v_right = px[3];
    o.v_right_measured = v_right_measured;
    ff.observations.push_back(o);
  }
  return out;
}

Expected<std::vector<FrameFeatures>> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                                 int image_width, int image_height) {
  if (image_width <= 0 || image_height <= 0) {
    return invalidArgument("parseTracks: image_width and image_height must be > 0 px");
  }
  auto parsed = parseTracks(file, times, TrackBounds{image_width, image_height, 0.0});
  if (!parsed) return parsed.status();
  return std::move(parsed->frames);
}

namespace {
// The smallest whole-pixel size that holds the extent; it must fit the principal point c.
Expected<int> sizeFromExtent(const std::string& path, const TrackExtent& e, double c,
                             const char* axis) {
  if (e.line == 0) {
    return parseError(path + ": no observation to take the image " + axis +
                      " from; state the size in calib.txt or the options");
  }
  const double size = std::floor(e.max_px) + 1.0;
  if (c < kMinPrincipalShare * size || size > kMaxSize) {
    return parseError(path + ":" + std::to_string(e.line) + ": field '" + e.field +
                      "': " + formatPx(e.max_px) + " is far outside any image whose principal " +
                      "point is " + formatPx(c) + " px (the size is not stated; state it in " +
                      "calib.txt or the options)");
  }
  return static_cast<int>(size);
}
}  // namespace

Expected<TrackSequence> readTrackFolder(const std::string& folder,
                                        const TrackReadOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  TrackSequence seq;
  {
    auto f = TextFile::open(folder + "/calib.txt");
    if (!f) return f.status();
    bool has_size = false;
    auto cam = parseTrackCalibLine(*f, &has_size);
    if (!cam) return cam.status();
    seq.camera = *cam;
    if (options.image_width > 0) {
      seq.camera.width = options.image_width;
      seq.camera.height = options.image_height;
      seq.image_size_source = "the options";
    } else if (has_size) {
      seq.image_size_source = "calib.txt";
    } else {
      seq.image_size_source = "extent of tracks.csv";
    }
  }
  std::vector<TimeNs> times;
  {
    auto t = readTimes(folder + "/times.txt");
    if (!t) return t.status();
    times = std::move(*t);
  }
  {
    auto f = TextFile::open(folder + "/tracks.csv");
    if (!f) return f.status();
    TrackBounds bounds;
    bounds.width = seq.camera.width;
    bounds.height = seq.camera.height;
    bounds.border_tolerance_px = options.border_tolerance_px;
    auto parsed = parseTracks(*f, times, bounds);
    if (!parsed) return parsed.status();
    if (seq.camera.width == 0) {
      auto w = sizeFromExtent(f->path(), parsed->u, seq.camera.cu, "width");
      if (!w) return w.status();
      auto h = sizeFromExtent(f->path(), parsed->v, seq.camera.cv, "height");
      if (!h) return h.status();
      seq.camera.width = *w;
      seq.camera.height = *h;
    }
    SUNVO_RETURN_IF_ERROR(seq.camera.validate());
    seq.frames = std::move(parsed->frames);
    seq.dropped_past_border = parsed->dropped_past_border;
    seq.max_outside_px = parsed->max_outside_px;
  }
  {
    auto p = readKittiPoses(folder + "/gt_poses.txt");
    if (!p) {
      if (options.require_gt || p.status().code() != StatusCode::kNotFound) return p.status();
    } else {
      if (p->size() != seq.frames.size()) {
        return parseError(folder + "/gt_poses.txt: " + std::to_string(p->size()) + " poses for " +
                          std::to_string(seq.frames.size()) + " frames");
      }
      seq.gt_T_0_k = std::move(p->T_w_c);
    }
  }
  return seq;
}

Status writeTrackFolder(const std::string& folder, const StereoCamera& camera,
                        const std::vector<FrameFeatures>& frames,
                        const std::vector<Isometry3>& gt_T_0_k) {
  if (!gt_T_0_k.empty() && gt_T_0_k.size() != frames.size()) {
    return invalidArgument("writeTrackFolder: " + std::to_string(gt_T_0_k.size()) +
                           " ground-truth poses for " + std::to_string(frames.size()) + " frames");
  }
  char line[256];
  std::snprintf(line, sizeof(line), "%.10g %.10g %.10g %.10g %.10g %d %d\n", camera.fu, camera.fv,
                camera.cu, camera.cv, camera.baseline_m, camera.width, camera.height);
  SUNVO_RETURN_IF_ERROR(writeWholeFile(folder + "/calib.txt", line));
  std::string times, tracks = "frame,landmark,uL,vL,uR,vR,vR_measured\n";
  for (std::size_t k = 0; k < frames.size(); ++k) {
    appendSecondsFromNs(times, frames[k].time_ns);
    times.push_back('\n');
    for (const StereoObservation& o : frames[k].observations) {
      if (o.landmark_id < 0) continue;
      std::snprintf(line, sizeof(line), "%zu,%lld,%.4f,%.4f,%.4f,%.4f,%d\n", k,
                    static_cast<long long>(o.landmark_id), o.u_left, o.v_left, o.u_right, o.v_right,
                    o.v_right_measured ? 1 : 0);
      tracks += line;
    }
  }
  SUNVO_RETURN_IF_ERROR(writeWholeFile(folder + "/times.txt", times));
  SUNVO_RETURN_IF_ERROR(writeWholeFile(folder + "/tracks.csv", tracks));
  if (gt_T_0_k.empty()) return Status::ok();
  Trajectory gt;
  gt.T_w_c = gt_T_0_k;
  return writeKittiPoses(folder + "/gt_poses.txt", gt);
}

}  // namespace sunvo::files
