#include "sunvo/kitti/stereo_source.hpp"

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "sunvo/kitti/calibration.hpp"
#include "sunvo/kitti/timestamps.hpp"

namespace sunvo::kitti {
namespace fs = std::filesystem;

namespace {

constexpr std::int64_t kMaxUtcOffsetS = 14 * 3600;

Status endOfSequence() {
  return notFound("end of sequence");
}

std::string frameLabel(std::int64_t index) {
  return "frame " + std::to_string(index);
}

std::string describeType(int type) {
  return "depth " + std::to_string(CV_MAT_DEPTH(type)) + " with " +
         std::to_string(CV_MAT_CN(type)) + " channel(s)";
}

}  // namespace

const char* toString(KittiLayout layout) {
  switch (layout) {
    case KittiLayout::kAuto:
      return "auto";
    case KittiLayout::kRaw:
      return "raw";
    case KittiLayout::kOdometry:
      return "odometry";
  }
  return "?";
}

TimeNs SteadyPacingClock::nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void SteadyPacingClock::sleepUntilNs(TimeNs t_ns) {
  std::this_thread::sleep_until(
      std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t_ns)));
}

Status KittiSourceOptions::validate() const {
  if (root.empty()) return invalidArgument("root: must name the drive or sequence folder");
  if (utc_offset_s && (*utc_offset_s < -kMaxUtcOffsetS || *utc_offset_s > kMaxUtcOffsetS)) {
    return invalidArgument("utc_offset_s: " + std::to_string(*utc_offset_s) +
                           " outside [-50400, 50400] s");
  }
  if (odometry_start_time_ns && *odometry_start_time_ns < 0) {
    return invalidArgument("odometry_start_time_ns: must be >= 0 (UTC ns of times.txt's 0)");
  }
  if (first_frame < 0) return invalidArgument("first_frame: must be >= 0");
  if (last_frame < -1 || (last_frame != -1 && last_frame < first_frame)) {
    return invalidArgument("last_frame: must be -1 (to the end) or >= first_frame");
  }
  return Status::ok();
}

Expected<KittiStereoSource> KittiStereoSource::open(const KittiSourceOptions& options,
                                                    std::shared_ptr<PacingClock> clock) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  KittiStereoSource src;
  src.options_ = options;
  src.clock_ = clock ? std::move(clock) : std::make_shared<SteadyPacingClock>();
  const fs::path root(options.root);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return notFound("root: not a folder: " + options.root);

  src.layout_ = options.layout;
  if (src.layout_ == KittiLayout::kAuto) {
    if (fs::is_directory(root / "image_00", ec)) {
      src.layout_ = KittiLayout::kRaw;
    } else if (fs::is_directory(root / "image_0", ec)) {
      src.layout_ = KittiLayout::kOdometry;
    } else {
      return notFound("root: " + options.root +
                      " holds neither image_00 (raw layout) nor image_0 (odometry layout)");
    }
  }
  SUNVO_RETURN_IF_ERROR(src.layout_ == KittiLayout::kRaw ? src.openRaw() : src.openOdometry());
  return src;
}

Status KittiStereoSource::openRaw() {
  if (!options_.utc_offset_s) {
    return invalidArgument(
        "utc_offset_s: required for the raw layout (KITTI timestamps carry no zone)");
  }
  fs::path root = fs::path(options_.root).lexically_normal();
  if (!root.has_filename()) root = root.parent_path();
  calib_dir_ = options_.calib_dir;
  if (calib_dir_.empty()) {
    calib_dir_ = root.parent_path().string();
    if (calib_dir_.empty()) calib_dir_ = ".";
  }
  auto c2c = readCamToCam(calib_dir_ + "/calib_cam_to_cam.txt");
  if (!c2c) return c2c.status();
  auto cam = rawStereoCamera(*c2c, 0, 1);
  if (!cam) return cam.status();
  camera_ = *cam;
  if (options_.use_color) {
    auto color = rawStereoCamera(*c2c, 2, 3);
    if (!color) return color.status();
    color_camera_ = *color;
  }

  const int cameras = options_.use_color ? 4 : 2;
  std::array<std::string, 4> ts_paths;
  std::array<std::vector<TimeNs>, 4> ts;
  for (int c = 0; c < cameras; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    ts_paths[ci] = options_.root + "/image_0" + std::to_string(c) + "/timestamps.txt";
    auto t = readRawTimestamps(ts_paths[ci], *options_.utc_offset_s);
    if (!t) return t.status();
    ts[ci] = std::move(*t);
    if (ts[ci].size() != ts[0].size()) {
      return parseError(ts_paths[ci] + " has " + std::to_string(ts[ci].size()) +
                        " timestamps but " + ts_paths[0] + " has " + std::to_string(ts[0].size()) +
                        " (frame " + std::to_string(std::min(ts[ci].size(), ts[0].size())) +
                        " is missing in one camera)");
    }
  }
  times_ns_ = std::move(ts[0]);
  for (std::size_t k = 1; k < times_ns_.size(); ++k) {
    if (times_ns_[k] <= times_ns_[k - 1]) {
      return parseError(ts_paths[0] + ":" + std::to_string(k + 1) +
                        ": field 'timestamp': " + frameLabel(static_cast<std::int64_t>(k)) +
                        " is not later than the frame before");
    }
  }
  if (times_ns_.empty()) return parseError(ts_paths[0] + ": no timestamps");
  first_ = options_.first_frame;
  last_ = options_.last_frame < 0 ? frameCount() - 1 : options_.last_frame;
  if (first_ >= frameCount() || last_ >= frameCount()) {
    return invalidArgument("first_frame/last_frame: range [" + std::to_string(first_) + ", " +
                           std::to_string(last_) + "] outside the recording's " +
                           std::to_string(frameCount()) + " frames");
  }
  for (int c = 0; c < cameras; ++c) SUNVO_RETURN_IF_ERROR(checkImages(c));
  next_index_ = first_;
  return Status::ok();
}

Status KittiStereoSource::openOdometry() {
  if (!options_.odometry_start_time_ns) {
    return invalidArgument(
        "odometry_start_time_ns: required for the odometry layout (times.txt is relative)");
  }
  auto calib = readOdometryCalibration(options_.root + "/calib.txt");
  if (!calib) return calib.status();
  const std::string times_path = options_.root + "/times.txt";
  auto times = readOdometryTimes(times_path, *options_.odometry_start_time_ns);
  if (!times) return times.status();
  times_ns_ = std::move(*times);
  if (times_ns_.empty()) return parseError(times_path + ": no times");
  for (std::size_t k = 1; k < times_ns_.size(); ++k) {
    if (times_ns_[k] <= times_ns_[k - 1]) {
      return parseError(times_path + ":" + std::to_string(k + 1) +
                        ": field 'time_s': " + frameLabel(static_cast<std::int64_t>(k)) +
                        " is not later than the frame before");
    }
  }
  first_ = options_.first_frame;
  last_ = options_.last_frame < 0 ? frameCount() - 1 : options_.last_frame;
  if (first_ >= frameCount() || last_ >= frameCount()) {
    return invalidArgument("first_frame/last_frame: range [" + std::to_string(first_) + ", " +
                           std::to_string(last_) + "] outside the recording's " +
                           std::to_string(frameCount()) + " frames");
  }
  const int cameras = options_.use_color ? 4 : 2;
  for (int c = 0; c < cameras; ++c) SUNVO_RETURN_IF_ERROR(checkImages(c));

  // The odometry calib.txt has no image size: take it from the first image of the range.
  const std::string first_path = imagePath(0, first_);
  cv::Mat first;
  try {
    first = cv::imread(first_path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return parseError(frameLabel(first_) + ": cannot decode " + first_path + ": " + e.what());
  }
  if (first.empty()) return parseError(frameLabel(first_) + ": cannot decode " + first_path);
  if (first.type() != CV_8UC1) {
    return parseError(frameLabel(first_) + ": " + first_path + ": expected 8-bit gray, got " +
                      describeType(first.type()));
  }
  auto cam = odometryStereoCamera(*calib, 0, 1, first.cols, first.rows);
  if (!cam) return cam.status();
  camera_ = *cam;
  if (options_.use_color) {
    auto color = odometryStereoCamera(*calib, 2, 3, first.cols, first.rows);
    if (!color) return color.status();
    color_camera_ = *color;
  }
  next_index_ = first_;
  return Status::ok();
}

std::string KittiStereoSource::imagePath(int camera, std::int64_t index) const {
  std::array<char, 64> buf{};
  if (layout_ == KittiLayout::kRaw) {
    std::snprintf(buf.data(), buf.size(), "/image_%02d/data/%010lld.png", camera,
                  static_cast<long long>(index));
  } else {
    std::snprintf(buf.data(), buf.size(), "/image_%d/%06lld.png", camera,
                  static_cast<long long>(index));
  }
  return options_.root + buf.data();
}

Status KittiStereoSource::checkImages(int camera) const {
  const fs::path dir = fs::path(imagePath(camera, 0)).parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return notFound("image folder missing: " + dir.string());
  // Every frame of the recording must have its image (not only the range): a gap would shift
  // images against timestamps. With drop_bad_frames a missing file is a frame to drop, but there
  // may still be no more images than timestamps.
  if (!options_.drop_bad_frames) {
    for (std::int64_t k = 0; k < frameCount(); ++k) {
      const std::string path = imagePath(camera, k);
      if (!fs::is_regular_file(path, ec)) {
        return notFound(frameLabel(k) + ": image file missing: " + path);
      }
    }
  }
  std::int64_t pngs = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".png") ++pngs;
  }
  if (ec) return ioError("cannot list " + dir.string() + ": " + ec.message());
  if (options_.drop_bad_frames ? pngs > frameCount() : pngs != frameCount()) {
    return parseError(dir.string() + " holds " + std::to_string(pngs) +
                      " PNG images but the "
                      "timestamps list " +
                      std::to_string(frameCount()) + " frames");
  }
  return Status::ok();
}

Status KittiStereoSource::readImage(int camera, std::int64_t index, int type, cv::Mat& dst) {
  const std::string path = imagePath(camera, index);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return notFound(frameLabel(index) + ": image file missing or unreadable: " + path);
  const std::streamoff size = in.tellg();
  if (size <= 0) return parseError(frameLabel(index) + ": empty image file: " + path);
  in.seekg(0);
  file_buffer_.resize(static_cast<std::size_t>(size));  // capacity kept between frames
  in.read(reinterpret_cast<char*>(file_buffer_.data()), size);
  if (!in) return ioError(frameLabel(index) + ": read failed: " + path);

  // Never overwrite pixels that another Mat header still shares.
  if (dst.u != nullptr && dst.u->refcount > 1) dst.release();
  const cv::Mat encoded(1, static_cast<int>(size), CV_8UC1, file_buffer_.data());
  try {
    // IMREAD_UNCHANGED keeps the file's channel count (no silent conversion) and decodes into
    // dst's existing buffer when its size and type already match.
    cv::imdecode(encoded, cv::IMREAD_UNCHANGED, &dst);
  } catch (const cv::Exception& e) {
    dst.release();
    return parseError(frameLabel(index) + ": cannot decode " + path + ": " + e.what());
  }
  if (dst.empty()) return parseError(frameLabel(index) + ": cannot decode " + path);
  if (dst.type() != type) {
    return parseError(frameLabel(index) + ": " + path + ": expected " + describeType(type) +
                      ", got " + describeType(dst.type()));
  }
  const StereoCamera& cam = camera >= 2 ? *color_camera_ : camera_;
  if (dst.cols != cam.width || dst.rows != cam.height) {
    return parseError(frameLabel(index) + ": " + path + ": image is " + std::to_string(dst.cols) +
                      "x" + std::to_string(dst.rows) + ", calibration says " +
                      std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  return Status::ok();
}

Status KittiStereoSource::readFrame(std::int64_t k, StereoFrame& out) {
  SUNVO_RETURN_IF_ERROR(readImage(0, k, CV_8UC1, out.left));
  SUNVO_RETURN_IF_ERROR(readImage(1, k, CV_8UC1, out.right));
  if (options_.use_color) {
    SUNVO_RETURN_IF_ERROR(readImage(2, k, CV_8UC3, out.left_color));
    SUNVO_RETURN_IF_ERROR(readImage(3, k, CV_8UC3, out.right_color));
  } else {
    out.left_color.release();
    out.right_color.release();
  }
  return Status::ok();
}

Status KittiStereoSource::next(StereoFrame& out) {
  if (finished_) return endOfSequence();
  if (next_index_ > last_) {
    finished_ = true;
    return endOfSequence();
  }
  const std::int64_t k = next_index_;
  if (const Status s = readFrame(k, out); !s.isOk()) {
    if (options_.drop_bad_frames) {
      ++next_index_;
      ++dropped_frames_;
    }
    return s;
  }
  const TimeNs t = times_ns_[static_cast<std::size_t>(k)];
  out.trigger_time_ns = t;
  out.sequence = static_cast<std::uint64_t>(k);
  if (options_.pacing == Pacing::kRecordedRate) {
    // Release frame k no earlier than wall0 + (t_k - t_first): decoding happens before the wait,
    // so it does not add to the recorded interval.
    if (!pacing_started_) {
      pacing_started_ = true;
      pacing_wall0_ns_ = clock_->nowNs();
      pacing_rec0_ns_ = t;
    } else {
      clock_->sleepUntilNs(pacing_wall0_ns_ + (t - pacing_rec0_ns_));
    }
  }
  ++next_index_;
  return Status::ok();
}

Expected<LoadedFrames> loadAllFrames(const KittiSourceOptions& options) {
  auto source = KittiStereoSource::open(options);
  if (!source) return source.status();
  LoadedFrames out;
  out.camera = source->camera();
  for (std::int64_t k = options.first_frame; true; ++k) {
    StereoFrame frame;
    const Status s = source->next(frame);
    if (source->finished()) break;
    if (!s.isOk()) {
      if (!options.drop_bad_frames) return s;
      frame = StereoFrame{};  // dropped: empty images, the index kept
      frame.sequence = static_cast<std::uint64_t>(k);
      frame.trigger_time_ns = source->frameTimes()[static_cast<std::size_t>(k)];
      ++out.dropped;
    }
    out.frames.push_back(std::move(frame));
  }
  return out;
}

}  // namespace sunvo::kitti
