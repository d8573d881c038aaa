#pragma once
// Reader for a stereo feature-track folder (e.g. kitti_tracks/2011_09_30_drive_0020/):
//   calib.txt     one line "fu fv cu cv baseline_m" (rectified cam0/cam1)
//   times.txt     one frame time per line, seconds since the Unix epoch (read as UTC)
//   tracks.csv    header "frame,landmark,uL,vL,uR,vR", then one observation per row, rows grouped
//                 by frame in increasing frame order
//   gt_poses.txt  optional: KITTI 3x4 poses T_0_k (camera k -> camera 0), 12 numbers per line
//
// Decisions:
// - The image size is not in calib.txt; it is a parameter (TrackReadOptions, KITTI's 1242x375 by
//   default). An observation outside [0, width) x [0, height) is a parse error naming the field.
// - Negative or zero disparity (uL - uR <= 0) is accepted: it is what the tracker measured (the
// 0020
//   tracks hold 175 such rows, mismatches or points near infinity). The estimator decides what to
//   do with it (it rejects disparities below its min_disparity_px option).
// - A frame index with no rows (no observations) gives an empty FrameFeatures; the frame count is
//   the number of lines in times.txt, and a row whose frame is >= that count is an error.
// - Frames must be non-decreasing row to row; a landmark may appear only once per frame.

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
  int image_width = 1242;   // px, > 0: rectified image width (KITTI: 1242)
  int image_height = 375;   // px, > 0: rectified image height (KITTI: 375)
  bool require_gt = false;  // when true a missing gt_poses.txt is an error; else it is optional

  Status validate() const;
};

struct TrackSequence {
  StereoCamera camera;
  std::vector<FrameFeatures> frames;  // frames[k].sequence == k
  std::vector<Isometry3> gt_T_0_k;    // empty when there is no gt_poses.txt
};

// calib.txt: "fu fv cu cv baseline_m" on the first non-blank line.
Expected<StereoCamera> parseTrackCalib(TextFile& file, int image_width, int image_height);
// tracks.csv for num_frames frames; times[k] becomes frames[k].time_ns (times.size() must be
// num_frames).
Expected<std::vector<FrameFeatures>> parseTracks(TextFile& file, const std::vector<TimeNs>& times,
                                                 int image_width, int image_height);

// Reads a whole track folder; times.txt and gt_poses.txt go through trajectory_io.hpp
// (readTimes: exact decimal seconds to ns; readKittiPoses).
Expected<TrackSequence> readTrackFolder(const std::string& folder, const TrackReadOptions& options);

}  // namespace sunvo::files
