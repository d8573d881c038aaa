#pragma once
// A rendered drive: scenario configuration (YAML), the per-frame sun/sky/lighting, the sensor
// model applied to POV-Ray's output, and the KITTI raw layout written to disk:
//   <out>/<date>/calib_cam_to_cam.txt, calib_imu_to_velo.txt, calib_velo_to_cam.txt
//   <out>/<date>/<date>_drive_<nnnn>_sync/image_0{0,1,2,3}/{timestamps.txt,data/%010d.png}
//   ..._sync/gt/poses_cam0.txt       KITTI 3x4 T_c0(0)_c0(k) per line (odometry convention)
//   ..._sync/gt/poses_cam0_enu.txt   3x4 T_enu_c0(k) per line (local ENU at the origin)
//   ..._sync/gt/sun_cam0.csv         frame,sx,sy,sz (unit sun vector in camera 0, as
//                                    kitti_odometry/*_sun_cam.csv)
//   ..._sync/gt/sun_enu.csv          frame,zenith_deg,azimuth_deg,e,n,u (SPA, unrefracted)
//   ..._sync/gt/origin.txt           latitude_deg longitude_deg altitude_m of the ENU origin
//   ..._sync/gt/body_enu.csv         frame,utc_ns,e,n,u,roll_rad,pitch_rad,yaw_rad,ve,vn,vu
//                                    (IMU/body pose for an OXTS writer; see VehicleState)
//   ..._sync/pov/                    city.inc, frame_%06d.pov, sky_%06d.hdr, povray logs

#include <cstdint>
#include <functional>
#include <opencv2/core/mat.hpp>
#include <random>
#include <string>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/render/perez_sky.hpp"
#include "sunvo/render/pov.hpp"
#include "sunvo/render/scene.hpp"
#include "sunvo/render/sensor.hpp"
#include "sunvo/render/style.hpp"
#include "sunvo/render/traffic.hpp"

namespace sunvo::render {

// Written calibration = true calibration perturbed by these (the images use the true one).
struct CalibErrorOptions {
  double focal_scale = 1.0;     // [0.9, 1.1]
  double cu_offset_px = 0.0;    // [-20, 20]
  double cv_offset_px = 0.0;    // [-20, 20]
  double baseline_scale = 1.0;  // [0.9, 1.1]
  Status validate() const;
};

// The rig as built differs from the rig as calibrated, slowly over the drive (temperature, a
// knock to the mount): the right camera is turned by a rotation that goes linearly from *_start
// (first frame) to *_end (last frame), in degrees about the right camera's own axes (roll about
// z, the optical axis; pitch about x; yaw about y; applied as Rz(roll) Rx(pitch) Ry(yaw)). The
// images carry it, the written calibration and camera 0's ground truth do not; the injected
// angles per frame are written to gt/rig_error.csv. A right pitch of 0.3 px / fv rad is a 0.3 px
// vertical offset. Each angle in [-1, 1] deg.
struct RigErrorOptions {
  double right_roll_start_deg = 0.0;
  double right_roll_end_deg = 0.0;
  double right_pitch_start_deg = 0.0;
  double right_pitch_end_deg = 0.0;
  double right_yaw_start_deg = 0.0;
  double right_yaw_end_deg = 0.0;
  Status validate() const;
  bool any() const;
};

// The injected (roll, pitch, yaw) in degrees at `progress` (0 = first frame, 1 = last frame).
Eigen::Vector3d rightCameraErrorDeg(const RigErrorOptions& o, double progress);
// R_c1nominal_c1 of a right camera turned by (roll, pitch, yaw) degrees: Rz(roll) Rx(pitch)
// Ry(yaw).
Eigen::Matrix3d rightCameraTurn(const Eigen::Vector3d& roll_pitch_yaw_deg);
// T_c1nominal_c1: the right camera's pose in the calibrated right-camera frame at `progress`.
Isometry3 rightCameraError(const RigErrorOptions& o, double progress);

struct Scenario {
  std::string name = "drive";
  int drive_number = 1;        // [0, 9999]
  double latitude_deg = 49.0;  // ENU origin, WGS84, [-90, 90]
  double longitude_deg = 8.4;  // [-180, 180]
  double altitude_m = 115.0;   // [-500, 9000]
  // The street grid's x axis on the ground, deg counter-clockwise from east, [-180, 180]:
  // 0 puts the streets along east and north.
  double grid_heading_deg = 0.0;
  TimeNs start_utc = 0;  // first frame, UTC
  int frames = 100;      // [1, 100000]
  std::uint64_t seed = 1;
  int sky_image_width = 256;  // equirectangular sky, px (height = width / 2), [32, 4096]
  SkyOptions sky;
  CityOptions city;
  RouteOptions route;
  TrafficOptions traffic;  // moving cars (traffic.hpp); none by default
  StereoCamera camera{721.5377, 721.5377, 609.5593, 172.854, 0.537, 1242, 375};
  RenderQuality quality;
  SensorOptions sensor;
  StyleOptions style;  // domain randomisation of the look (style.hpp); seed 0 = classic
  CalibErrorOptions calib_error;
  RigErrorOptions rig_error;
  // The YAML text it was parsed from (parseScenario): part of a render's manifest, so that a
  // render is resumed only with the scenario it was started with.
  std::string source_text;
  Status validate() const;
};

// Reads a scenario YAML (see config/scenarios/). Unknown keys and bad values fail with a
// message naming the key ("route.speed_max_mps ..."); missing keys keep their defaults.
Expected<Scenario> loadScenario(const std::string& path);
Expected<Scenario> parseScenario(const std::string& yaml_text, const std::string& label);

// Fixed KITTI-like extrinsics of the rig (body = IMU frame, x forward, y left, z up, origin on
// the ground below the IMU): IMU 0.93 m above ground, Velodyne at (0.81, -0.32, 1.73) m,
// camera 0 at (1.08, -0.32, 1.65) m looking forward (R_b_c: x_c = -y_b, y_c = -z_b, z_c = x_b).
Isometry3 bodyFromCamera0();
Isometry3 bodyFromVelodyne();

// Lighting of one frame: sun colour/intensity, ambient and the exposure scale applied to all.
struct FrameLighting {
  Lighting pov;
  double sun_zenith_deg = 0.0, sun_azimuth_deg = 0.0;
  double exposure_scale = 1.0;  // POV value per cd/m^2
  double sky_illuminance_lux = 0.0, sun_normal_illuminance_lux = 0.0;
};
FrameLighting computeLighting(const Eigen::Vector3d& sun_enu, const SkyOptions& sky,
                              double exposure_target);

// Writes the KITTI calibration files into date_dir.
Status writeKittiCalibration(const std::string& date_dir, const StereoCamera& cam,
                             const CalibErrorOptions& err);

// "YYYY-MM-DD HH:MM:SS.nnnnnnnnn" (UTC).
std::string kittiTimestamp(TimeNs t);

struct DriveProgress {
  std::size_t done = 0, total = 0;  // povray renders of this run
  std::size_t kept_frames = 0;      // frames a resumed render found done
};

// Renders the whole drive (2 povray renders per frame) with `jobs` parallel povray children.
// Returns the drive folder. Every image is written under a temporary name and renamed, so an
// image that exists is whole. A fresh render (resume = false) first removes the drive's images
// and scene files. resume = true continues a render that stopped part-way (a killed run, the end
// of a session): the folder's render_manifest.txt (the render format, the scenario's text, the
// camera and the render quality) must be this run's, and a frame is kept when its four images
// exist and its POV-Ray scene (frame_NNNNNN.pov) is the one this run writes, byte for byte; the
// rest is rendered; a folder without this drive is rendered whole, as a fresh render. The ground
// truth, OXTS and calibration are written again either way.
Expected<std::string> renderDrive(const Scenario& s, const std::string& out_root, int jobs,
                                  const std::function<void(const DriveProgress&)>& progress,
                                  bool resume = false);

}  // namespace sunvo::render
