#pragma once
// The three rectified stereo rigs that recorded the KITTI odometry sequences with ground truth
// (00-10), for routes that come as poses, times and sun without a calibration file. Values are
// KITTI's own rectified projections P0/P1 of each recording day (P_rect_00/01 of its
// calib_cam_to_cam.txt) and the odometry images' size; tests/dataset checks each against the
// real files in shared/data where they exist.
//   2011_10_03 (sequences 00-02): 1241x376, fu 718.856, (cu, cv) (607.1928, 185.2157), P1 tx
//   -386.1448 2011_09_26 (sequence 03):     1242x375, fu 721.5377, (609.5593, 172.854),        P1
//   tx -387.5744 2011_09_30 (sequences 04-10): 1226x370, fu 707.0912, (601.8873, 183.1104), P1 tx
//   -379.8145

#include <optional>
#include <string>

#include "sunvo/core/camera.hpp"

namespace sunvo::dataset {

struct KittiRig {
  const char* date = "";  // recording day, e.g. "2011_09_30"
  double fu = 0.0;        // px (fv = fu)
  double cu = 0.0;        // px
  double cv = 0.0;        // px
  double p1_tx = 0.0;     // px*m: P1(0, 3) = -fu * baseline
  int width = 0;          // px, the odometry sequence's images
  int height = 0;

  StereoCamera camera() const;
};

// The rig of KITTI odometry sequence "00".."10" (also "0".."10"); nullopt for any other name.
std::optional<KittiRig> kittiOdometryRig(const std::string& sequence);

// The rig of a KITTI recording day, from a name that starts with it ("2011_10_03",
// "2011_10_03_drive_0027_sync", a track folder named after its drive); nullopt for other names.
std::optional<KittiRig> kittiRigOfDay(const std::string& name);

// The KITTI raw drive that KITTI odometry sequence "00".."10" was cut from (the odometry
// development kit's table), e.g. "05" -> "2011_09_30_drive_0018"; nullopt for any other name.
std::optional<std::string> kittiOdometryDrive(const std::string& sequence);

}  // namespace sunvo::dataset
