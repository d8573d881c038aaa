#pragma once
// A file-backed stereo source: replays a KITTI recording as core StereoFrames, like a camera.
//
// Raw layout (root = <date>/<date>_drive_NNNN_sync, calibration in the parent folder <date>/):
//   image_00/data/NNNNNNNNNN.png (left gray), image_01 (right gray), image_02/03 (colour pair),
//   image_0x/timestamps.txt; StereoCamera from calib_cam_to_cam.txt (P_rect_00/01, S_rect_00).
// Odometry layout (root = sequence folder):
//   image_0/NNNNNN.png, image_1 (gray), image_2/3 (colour), times.txt, calib.txt;
//   width and height from the first image of the range.
// The frame time is the left camera's timestamp (raw) or times.txt (odometry), in UTC ns.
//
// Memory: each image is read into a byte buffer kept by the source and decoded with
// cv::imdecode straight into the caller's StereoFrame Mats, so once the frame's Mats have the
// right size and type no image memory is allocated per frame. A Mat whose buffer is shared with
// another Mat header (refcount > 1) is released first, so a view the caller kept is never
// overwritten. By default errors never skip a frame: a missing or malformed image, disagreeing
// timestamp counts, wrong size or channel count each give an error naming the file and frame
// number. With drop_bad_frames a bad image drops its frame instead (see the option).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::kitti {

enum class KittiLayout { kAuto, kRaw, kOdometry };
enum class Pacing {
  kAsFastAsPossible,  // next() returns as soon as the images are decoded
  kRecordedRate,      // next() returns no earlier than the recorded time deltas after the first
};

const char* toString(KittiLayout layout);

// The clock that pacing uses; injectable so tests run without sleeping.
class PacingClock {
 public:
  virtual ~PacingClock() = default;
  virtual TimeNs nowNs() = 0;                  // monotonic ns
  virtual void sleepUntilNs(TimeNs t_ns) = 0;  // returns at once when t_ns has passed
};

// std::chrono::steady_clock and std::this_thread::sleep_until.
class SteadyPacingClock final : public PacingClock {
 public:
  TimeNs nowNs() override;
  void sleepUntilNs(TimeNs t_ns) override;
};

struct KittiSourceOptions {
  // Raw: the drive folder (<date>/<date>_drive_NNNN_sync); odometry: the sequence folder.
  std::string root;
  // Raw only: folder with calib_cam_to_cam.txt; empty = the parent folder of root.
  std::string calib_dir;
  // kAuto picks kRaw when root/image_00 exists, kOdometry when root/image_0 exists.
  KittiLayout layout = KittiLayout::kAuto;
  // s, required for the raw layout, range [-50400, 50400]: offset of the files' zone to UTC
  // (+3600 = timestamps written in UTC+1). No default: the files name no zone.
  std::optional<std::int64_t> utc_offset_s;
  // UTC ns of times.txt's 0, required for the odometry layout, >= 0. No default: 0 states that
  // the UTC time is unknown (the frame times are then only relative).
  std::optional<TimeNs> odometry_start_time_ns;
  // Also deliver left_color/right_color (CV_8UC3) from image_02/03 (raw) or image_2/3
  // (odometry); open() fails when requested and absent.
  bool use_color = false;
  Pacing pacing = Pacing::kAsFastAsPossible;
  // First frame index to deliver, >= 0 and < the number of frames.
  std::int64_t first_frame = 0;
  // Last frame index to deliver (inclusive), >= first_frame, < the number of frames; -1 = last.
  std::int64_t last_frame = -1;
  // false: open() checks that every image file exists and a bad image fails next() on the same
  // frame again and again (a recording is checked whole). true (a replay that must go on):
  // open() accepts missing image files (not the odometry layout's first frame of the range,
  // which gives the image size), and next() on a frame with a missing, truncated or corrupt
  // image, or one of the wrong size or channel count, returns that error, moves past the frame
  // and counts it in droppedFrames(); the next call delivers the next frame.
  bool drop_bad_frames = false;

  // Checks the fields that do not need the files; the error names the bad key.
  Status validate() const;
};

class KittiStereoSource {
 public:
  // Reads calibration and timestamps and checks that every image of the range exists and that
  // the timestamp counts agree with each other and with the number of images.
  // clock: used only with Pacing::kRecordedRate; null = SteadyPacingClock.
  static Expected<KittiStereoSource> open(const KittiSourceOptions& options,
                                          std::shared_ptr<PacingClock> clock = nullptr);

  // Fills `out` with the next frame (sequence = frame index in the recording). At the end of the
  // range returns kNotFound "end of sequence" and finished() becomes true; any other failure
  // leaves finished() false and does not advance (the same frame fails again).
  // With drop_bad_frames a bad frame's error comes with the source moved past it.
  Status next(StereoFrame& out);
  bool finished() const { return finished_; }
  // Frames dropped by next() for a bad image (drop_bad_frames only).
  std::int64_t droppedFrames() const { return dropped_frames_; }

  KittiLayout layout() const { return layout_; }
  const StereoCamera& camera() const { return camera_; }  // rectified gray pair 0/1
  // The rectified colour pair 2/3; set when use_color.
  const std::optional<StereoCamera>& colorCamera() const { return color_camera_; }
  // Number of frames in the recording (not only the range).
  std::int64_t frameCount() const { return static_cast<std::int64_t>(times_ns_.size()); }
  // UTC ns of every frame of the recording.
  const std::vector<TimeNs>& frameTimes() const { return times_ns_; }
  // Image path of camera 0..3 for frame `index`.
  std::string imagePath(int camera, std::int64_t index) const;
  // Raw layout: the folder the calibration files were read from (calib_dir, or the drive's
  // parent folder); empty for the odometry layout.
  const std::string& calibrationDir() const { return calib_dir_; }

 private:
  KittiStereoSource() = default;
  Status openRaw();
  Status openOdometry();
  Status checkImages(int camera) const;
  Status readImage(int camera, std::int64_t index, int type, cv::Mat& dst);
  Status readFrame(std::int64_t index, StereoFrame& out);

  KittiSourceOptions options_;
  std::shared_ptr<PacingClock> clock_;
  KittiLayout layout_ = KittiLayout::kAuto;
  StereoCamera camera_;
  std::optional<StereoCamera> color_camera_;
  std::vector<TimeNs> times_ns_;
  std::string calib_dir_;
  std::int64_t first_ = 0;
  std::int64_t last_ = 0;
  std::int64_t next_index_ = 0;
  std::int64_t dropped_frames_ = 0;
  bool finished_ = false;
  bool pacing_started_ = false;
  TimeNs pacing_wall0_ns_ = 0;
  TimeNs pacing_rec0_ns_ = 0;
  std::vector<unsigned char> file_buffer_;  // reused for every image file read
};

// Every frame of a recording decoded into memory, for tests and benchmarks (a few hundred frames
// at most: 1241x376 gray pairs take about 0.9 MB each).
// With options.drop_bad_frames a dropped frame stays in `frames` with empty images (so index k of
// `frames` is still frame first_frame + k) and is counted in `dropped`.
struct LoadedFrames {
  StereoCamera camera;              // rectified gray pair 0/1 with the image size
  std::vector<StereoFrame> frames;  // in order; sequence = frame index
  std::int64_t dropped = 0;         // frames with empty images (drop_bad_frames)
};
Expected<LoadedFrames> loadAllFrames(const KittiSourceOptions& options);

}  // namespace sunvo::kitti
