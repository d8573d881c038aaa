#pragma once
// KITTI raw OXTS (GPS/INS) records: oxts/data/NNNNNNNNNN.txt, one line of 30 space-separated
// fields in the order of oxts/dataformat.txt (25 reals, then 5 integers). Angles in rad, with
// yaw 0 = east, counter-clockwise positive; roll positive = left side up; pitch positive = front
// down. The IMU frame is x forward, y left, z up.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/files/text_file.hpp"

namespace sunvo::kitti {

struct OxtsRecord {
  double lat = 0.0;           // deg
  double lon = 0.0;           // deg
  double alt = 0.0;           // m
  double roll = 0.0;          // rad, 0 = level, positive = left side up
  double pitch = 0.0;         // rad, 0 = level, positive = front down
  double yaw = 0.0;           // rad, 0 = east, positive = counter-clockwise
  double vn = 0.0;            // m/s north
  double ve = 0.0;            // m/s east
  double vf = 0.0;            // m/s forward (parallel to the earth surface)
  double vl = 0.0;            // m/s leftward
  double vu = 0.0;            // m/s upward
  double ax = 0.0;            // m/s^2, vehicle x (front)
  double ay = 0.0;            // m/s^2, vehicle y (left)
  double az = 0.0;            // m/s^2, vehicle z (top)
  double af = 0.0;            // m/s^2 forward
  double al = 0.0;            // m/s^2 leftward
  double au = 0.0;            // m/s^2 upward
  double wx = 0.0;            // rad/s around x
  double wy = 0.0;            // rad/s around y
  double wz = 0.0;            // rad/s around z
  double wf = 0.0;            // rad/s around forward
  double wl = 0.0;            // rad/s around leftward
  double wu = 0.0;            // rad/s around upward
  double pos_accuracy = 0.0;  // m (north/east)
  double vel_accuracy = 0.0;  // m/s (north/east)
  std::int64_t navstat = 0;   // navigation status
  std::int64_t numsats = 0;   // satellites tracked by the primary receiver
  std::int64_t posmode = 0;   // position mode of the primary receiver
  std::int64_t velmode = 0;   // velocity mode
  std::int64_t orimode = 0;   // orientation mode
};

inline constexpr std::size_t kOxtsFieldCount = 30;
// The field names in file order, as in dataformat.txt.
const std::array<std::string_view, kOxtsFieldCount>& oxtsFieldNames();

// Parses the record in `file` (one non-blank line; blank lines around it are allowed). Errors name
// the file, the line and the field ("0000000000.txt:1: field 'pitch': not a number: 'x'").
Expected<OxtsRecord> parseOxtsRecord(files::TextFile& file);
Expected<OxtsRecord> readOxtsRecord(const std::string& path);

// One line, fields in file order, reals in the shortest form that reads back to the same double,
// ending with '\n'.
std::string formatOxtsRecord(const OxtsRecord& record);
Status writeOxtsRecord(const std::string& path, const OxtsRecord& record);

// oxts/data/NNNNNNNNNN.txt for a drive folder (10-digit zero-padded index).
std::string oxtsRecordPath(const std::string& drive_dir, std::int64_t index);

struct OxtsSample {
  TimeNs time_ns = 0;  // UTC
  OxtsRecord record;
};
// Every record of a drive: oxts/timestamps.txt (read with utc_offset_s) and one data file per line;
// a missing data file is an error naming it.
Expected<std::vector<OxtsSample>> readOxtsSequence(const std::string& drive_dir,
                                                   std::int64_t utc_offset_s);

}  // namespace sunvo::kitti
