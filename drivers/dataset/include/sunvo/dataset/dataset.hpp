#pragma once
// One seam for every recorded (or rendered) drive a program replays, evaluates or learns from.
// A Dataset is what the estimator needs besides the frames themselves: the rectified camera, the
// frame times in UTC, the world frame and the first camera pose in it, the ground truth and, where
// it is known, the true sun in each camera frame. The frames come from the images (through
// kitti::KittiStereoSource, opened with imageSourceOptions()) or, for a track folder, as feature
// tracks (features()).
//
// Kinds, detected from the folder (DatasetOptions::path):
//  - kSunvoRender: a drive written by sunvo_render (KITTI raw layout plus gt/): ground truth
//    gt/poses_cam0_enu.txt (ENU at gt/origin.txt, moved into the dataset's world), true sun
//    gt/sun_cam0.csv. Its timestamps are UTC by construction (utc_offset_s defaults to 0).
//  - kKittiRaw: a KITTI raw drive <date>/<date>_drive_NNNN_sync (image_00..03, oxts/, calibration
//    in <date>/). Ground truth from the OXTS records through the calibration chain (the KITTI
//    devkit's convention: camera 0 = T_w_imu T_imu_cam0rect); the true sun from the NREL SPA at
//    each frame's fix and UTC time, rotated into the camera by the ground truth. Needs
//    utc_offset_s for the sun (KITTI's files name no zone); without it the frames and the ground
//    truth load, sunKnown() is false and sunUnknownReason() says why.
//  - kKittiOdometry: a KITTI odometry sequence folder (image_0, image_1, calib.txt, times.txt).
//    Ground truth from `ground_truth`, DIR/poses.txt, DIR/gt_poses.txt or
//    DIR/../<NN>_gt_poses.txt (NN = the folder name up to its first '_'); true sun from
//    `sun_csv`, DIR/sun_cam.csv or DIR/../<NN>_sun_cam.csv. times.txt starts at 0: the UTC time of
//    its 0 is `odometry_start_utc_ns` (0 when unknown: the times are then only relative).
//  - kTrackFolder: stereo feature tracks (calib.txt, times.txt, tracks.csv, gt_poses.txt), as
//    kitti_tracks/<drive>; true sun from `sun_csv` or DIR/sun_cam.csv. The image size from the
//    options or the data (dataset/track_folder.hpp); observations slightly past the border are
//    dropped and counted (droppedPastBorder()).
//  - kTrajectory: a route without frames, for the experiment's simulated tracks: ground truth,
//    times, true sun and calibration. Either a folder (gt_poses.txt or poses.txt, times.txt,
//    sun_cam.csv, calib.txt in the track folder's "fu fv cu cv b" form or KITTI odometry P0..P3)
//    or a KITTI odometry prefix DIR/NN (NN_gt_poses.txt, NN_times.txt, NN_sun_cam.csv; calibration
//    from NN_calib.txt, NN_first_frames/calib.txt or else the KITTI rig that recorded sequence NN).
//
// World frames: ENU at the first GPS fix of the range (render, raw) or the first camera frame of
// the ground truth (odometry, tracks, trajectories; KITTI odometry poses carry no GPS). Every
// check is made in open(): a missing or unreadable file, a count that does not match the frames,
// a malformed record fail there, naming the file and line, before any frame is processed.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/geodesy/local_enu.hpp"
#include "sunvo/kitti/stereo_source.hpp"

namespace sunvo::dataset {

enum class DatasetKind { kSunvoRender, kKittiRaw, kKittiOdometry, kTrackFolder, kTrajectory };
const char* toString(DatasetKind kind);

enum class WorldFrame {
  kEnu,          // local East-North-Up at the first GPS fix of the range (up = +z)
  kFirstCamera,  // camera 0 of the first ground-truth frame (up = about -y: KITTI's rig is level)
};

struct DatasetOptions {
  std::string path;  // the drive, sequence, track folder or trajectory prefix (see above)
  // s, [-50400, 50400]: offset of the recording's civil timestamps to UTC (+3600 = written in
  // UTC+1). Render: 0 when unset; KITTI raw: unset = unknown (no sun). Not used by other kinds.
  std::optional<std::int64_t> utc_offset_s;
  // UTC ns of times.txt's 0 (KITTI odometry, track folders, trajectories), >= 0; 0 = unknown.
  TimeNs odometry_start_utc_ns = 0;
  std::string ground_truth;  // a KITTI or TUM pose file that replaces the detected one; "" = auto
  std::string sun_csv;       // a frame,sx,sy,sz file of the true sun in camera 0; "" = auto
  std::int64_t first_frame = 0;  // index, >= 0: first frame of the range
  std::int64_t last_frame = -1;  // index, >= first_frame; -1 = the last frame
  bool color = false;            // the image source also delivers the colour pair (2/3)
  // Track folders: px, 0 or [16, 16384], the rectified image size (0 x 0 = from the data).
  int image_width = 0;
  int image_height = 0;
  double border_tolerance_px = 2.0;  // track folders: px, [0, 50]; see files/tracks_io.hpp
  // Images: a missing image file is not an error at open, and imageSourceOptions() drops bad
  // frames (kitti::KittiSourceOptions::drop_bad_frames); false = every image must be there.
  bool drop_bad_frames = false;

  Status validate() const;
};

// The true sun of a frame.
struct TrueSun {
  Eigen::Vector3d sun_c = Eigen::Vector3d::UnitZ();  // unit vector toward the sun, camera 0
  Eigen::Vector3d sun_w = Eigen::Vector3d::UnitZ();  // the same in the dataset's world frame
};

class Dataset {
 public:
  static Expected<Dataset> open(const DatasetOptions& options);

  DatasetKind kind() const { return kind_; }
  const std::string& name() const { return name_; }       // e.g. "2011_09_30_drive_0020_sync"
  const std::string& folder() const { return folder_; }   // the folder the files were read from
  const StereoCamera& camera() const { return camera_; }  // rectified gray pair 0/1
  // Rectified colour pair 2/3, when the recording has one.
  const std::optional<StereoCamera>& colorCamera() const { return color_camera_; }

  // Frames of the range, in order; times in UTC ns (see utcKnown()).
  std::size_t size() const { return times_ns_.size(); }
  const std::vector<TimeNs>& timesNs() const { return times_ns_; }
  bool utcKnown() const { return utc_known_; }
  // Index of frame k of the range in the recording (first_frame + k).
  std::int64_t recordingIndex(std::size_t k) const { return first_ + static_cast<std::int64_t>(k); }

  WorldFrame world() const { return world_; }
  Eigen::Vector3d worldUp() const;  // unit "up" in the world frame
  // ENU worlds: the geodetic origin (the first fix of the range).
  const std::optional<geodesy::GeodeticPoint>& origin() const { return origin_; }
  // Camera 0 of the first frame in the world: OXTS + calibration (raw), the ground truth's first
  // pose (others). What a rover knows at start-up from its INS or its level and compass.
  const Isometry3& T_w_c0() const { return T_w_c0_; }
  // Per-frame GPS fixes (raw and render: the OXTS records of the range); empty otherwise.
  const std::vector<geodesy::GeodeticPoint>& fixes() const { return fixes_; }

  bool hasGroundTruth() const { return !T_w_c_gt_.empty(); }
  const std::vector<Isometry3>& groundTruth() const { return T_w_c_gt_; }  // camera 0 in world
  bool sunKnown() const { return !sun_.empty(); }
  const std::vector<TrueSun>& trueSun() const { return sun_; }
  const std::string& sunUnknownReason() const { return sun_reason_; }
  // The sun in the world from the NREL SPA at each frame's fix and UTC time: what a rover computes
  // (raw drives and renders with a known UTC; empty otherwise). For a raw drive it is the true
  // sun's sun_w; for a render it agrees with gt/sun_cam0.csv to the renderer's precision.
  const std::vector<Eigen::Vector3d>& ephemerisSunWorld() const { return ephemeris_sun_w_; }

  bool hasImages() const { return has_images_; }
  // Options that open this dataset's range in a kitti::KittiStereoSource (hasImages() only).
  kitti::KittiSourceOptions imageSourceOptions() const;
  bool hasFeatures() const { return !features_.empty(); }
  const std::vector<FrameFeatures>& features() const { return features_; }  // track folders
  // Track folders: where the image size came from, and the observations dropped (of the whole
  // folder) for lying within the tolerance past the border.
  const std::string& imageSizeSource() const { return image_size_source_; }
  std::size_t droppedPastBorder() const { return dropped_past_border_; }

  // A one-line description: kind, frames, camera, world, what is known.
  std::string describe() const;

 private:
  friend class DatasetLoader;
  DatasetKind kind_ = DatasetKind::kTrajectory;
  std::string name_;
  std::string folder_;
  DatasetOptions options_;
  StereoCamera camera_;
  std::optional<StereoCamera> color_camera_;
  std::vector<TimeNs> times_ns_;
  bool utc_known_ = false;
  std::int64_t first_ = 0;
  WorldFrame world_ = WorldFrame::kFirstCamera;
  std::optional<geodesy::GeodeticPoint> origin_;
  Isometry3 T_w_c0_ = Isometry3::Identity();
  std::vector<geodesy::GeodeticPoint> fixes_;
  std::vector<Isometry3> T_w_c_gt_;
  std::vector<TrueSun> sun_;
  std::vector<Eigen::Vector3d> ephemeris_sun_w_;
  std::string sun_reason_;
  bool has_images_ = false;
  std::vector<FrameFeatures> features_;
  std::string image_size_source_;
  std::size_t dropped_past_border_ = 0;
};

// The true sun in camera frames from the world sun and camera poses: sun_c = C_c_w sun_w.
std::vector<TrueSun> sunFromWorld(const std::vector<Eigen::Vector3d>& sun_w,
                                  const std::vector<Isometry3>& T_w_c);

}  // namespace sunvo::dataset
