#pragma once
// Per-frame sun direction files: "frame,sx,sy,sz" with a header line, the unit vector toward the
// sun in the (rectified) camera frame of each frame, as in kitti_odometry/*_sun_cam.csv.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"

namespace sunvo::files {

struct SunCsv {
  std::vector<Eigen::Vector3d> sun_c;  // indexed by frame; frames are 0..N-1 without gaps
};

// Rejects a wrong header, wrong field counts, non-numbers, gaps or disorder in the frame column,
// and vectors whose norm is off 1 by more than unit_tolerance; errors name file, line and field.
Expected<SunCsv> readSunCsv(const std::string& path, double unit_tolerance = 0.01);

// Writes what readSunCsv reads: the header, then "k,sx,sy,sz" for k = 0..N-1 (9 decimals).
Status writeSunCsv(const std::string& path, const SunCsv& sun);

}  // namespace sunvo::files
