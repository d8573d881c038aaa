#pragma once
// Reader for a stereo feature-track folder (e.g. kitti_tracks/2011_09_30_drive_0020/):
//   calib.txt     one line "fu fv cu cv baseline_m" (rectified cam0/cam1), optionally followed by
//                 "width height" (px) of the rectified images
//   times.txt     one frame time per line, seconds since the Unix epoch (read as UTC)
//   tracks.csv    header "frame,landmark,uL,vL,uR,vR", then one observation per row, rows grouped
//                 by frame in increasing frame order; an optional 7th column vR_measured (0 or 1:
//                 whether the right row was measured, StereoObservation::v_right_measured;
//                 without it every row counts as measured)
//   gt_poses.txt  optional: KITTI 3x4 poses T_0_k (camera k -> camera 0), 12 numbers per line
//
// Decisions:
// - The image size comes from the data, first found of: TrackReadOptions (explicit), the size on
//   the calib.txt line, else the observed extent of tracks.csv (the smallest whole-pixel image
//   that holds every observation). drivers/dataset adds the KITTI sources between the last two
//   (calib_cam_to_cam.txt's S_rect_00, the recording day's rig). KITTI rigs differ: 1242x375
//   (2011_09_26), 1226x370 (2011_09_30), 1241x376 (2011_10_03).
// - An observation at most border_tolerance_px outside [0, width) x [0, height) (sub-pixel
//   trackers report such points at the border) is dropped and counted, not clipped: clipping would
//   move the measurement by up to the tolerance without the estimator knowing. Farther outside is
//   a parse error naming file, line and field. With the size from the extent, the extent must fit
//   the principal point: cu >= 0.35 width and cv >= 0.35 height (KITTI: 0.49); a far-off value
//   that breaks this fails naming the row that holds it.
// - Negative or zero disparity (uL - uR <= 0) is accepted: it is what the tracker measured (the
//   0020 tracks hold 175 such rows, mismatches or points near infinity). The estimator decides
//   what to do with it (it rejects disparities below its min_disparity_px option).
// - A frame index with no rows (no observations) gives an empty FrameFeatures; the frame count is
//   the number of lines in times.txt, and a row whose frame is >= that count is an error.
// - Frames must be non-decreasing row to row; a landmark may appear only once per frame.

#include <cstddef>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/files/text_file.hpp"

namespace sunvo::files {

struct TrackReadOptions {
  // px, 0 or [16, 16384]: rectified image size; 0 x 0 = from the data (see above). Both or neither.
  int image_width = 0;
  int image_height = 0;
  // px, [0, 50]: observations at most this far outside the image are dropped and counted.
  double border_tolerance_px = 2.0;
  bool require_gt = false;  // when true a missing gt_poses.txt is an error; else it is optional

  Status validate() const;
};

// The image an observation must lie in. width/height 0: not known yet (only the lower borders are
// checked).
struct TrackBounds {
  int width = 0;                     // px, >= 0
  int height = 0;                    // px, >= 0
  double border_tolerance_px = 2.0;  // px, >= 0
};

// The largest coordinate of one axis (u: uL/uR, v: vL/vR) and the row that holds it.
struct TrackExtent {
  double max_px = 0.0;
  int line = 0;            // line number in tracks.csv (0: no observation)
  const char* field = "";  // "uL", "uR", "vL" or "vR"
};

struct ParsedTracks {
  std::vector<FrameFeatures> frames;    // frames[k].sequence == k
  std::size_t dropped_past_border = 0;  // observations within the tolerance outside the image
  double max_outside_px = 0.0;          // the farthest of them past the border, px
  TrackExtent u, v;                     // of the kept observations
};

struct TrackSequence {
  StereoCamera camera;
  std::vector<FrameFeatures> frames;    // frames[k].sequence == k
  std::vector<Isometry3> gt_T_0_k;      // empty when there is no gt_poses.txt
  std::string image_size_source;        // e.g. "calib.txt", "the options", "extent of tracks.csv"
  std::size_t dropped_past_border = 0;  // see ParsedTracks
  double max_outside_px = 0.0;
};

// calib.txt: "fu fv cu cv baseline_m [width height]" on the first non-blank line. *has_size tells
// whether the line states the size; the camera's width/height are then the line's, else 0.
Expected<StereoCamera> parseTrackCalibLine(TextFile& file, bool* has_size);
// The same with a size for lines that state none (> 0); a size on the line wins.
Expected<StereoCamera> parseTrackCalib(TextFile& file, int image_width, int image_height);
// tracks.csv for times.size() frames; times[k] becomes frames[k].time_ns.
Expected<ParsedTracks> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                   const TrackBounds& bounds);
// The strict form: every observation inside [0, image_width) x [0, image_height) (> 0), no
// tolerance, no counts.
Expected<std::vector<FrameFeatures>> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                                 int image_width, int image_height);

// Reads a whole track folder; times.txt and gt_poses.txt go through trajectory_io.hpp
// (readTimes: exact decimal seconds to ns; readKittiPoses).
Expected<TrackSequence> readTrackFolder(const std::string& folder, const TrackReadOptions& options);

// Writes a track folder that readTrackFolder reads back: calib.txt with the camera's size,
// times.txt (exact decimal seconds), tracks.csv (observations with a landmark id >= 0, in frame
// order; frame k of the folder is frames[k], whatever its sequence) and, when gt_T_0_k is not
// empty (one pose per frame), gt_poses.txt. The folder must exist. E.g. the front end's output of
// an image drive (sunvo_replay --write-tracks), to run the track-mode tools on it.
Status writeTrackFolder(const std::string& folder, const StereoCamera& camera,
                        const std::vector<FrameFeatures>& frames,
                        const std::vector<Isometry3>& gt_T_0_k);

}  // namespace sunvo::files
