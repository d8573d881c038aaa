#include "sunvo/files/tracks_io.hpp"

#include "sunvo/files/trajectory_io.hpp"

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
    auto t = readTimes(folder + "/times.txt");
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

}  // namespace sunvo::files
