#pragma once
// Trajectory files: KITTI odometry pose files and TUM RGB-D trajectory files.
//
// KITTI: one pose per line, 12 numbers, the 3x4 row-major [R | t] of T_w_c (camera-0 frame of
//   frame k into the world = camera-0 frame of frame 0):  r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33
//   tz. A KITTI file carries no times. Without a times file, t_ns[k] = k * 0.1 s (KITTI's nominal
//   10 Hz; kKittiNominalFramePeriodNs). With a times file (one number of seconds per line, as
//   KITTI's times.txt), t_ns[k] = that number in ns; the count must equal the number of poses.
// TUM:   one pose per line, 8 numbers "t tx ty tz qx qy qz qw" (t in seconds, quaternion of
//   C_w_c, Hamilton convention, any non-zero norm: it is normalised); lines whose first
//   non-blank character is '#' are comments.
// Both: blank lines are skipped; rotations are re-orthonormalised on load (core's
//   isometryFrom3x4 / quaternion normalisation); every number must be finite. Every error names
//   the file, the line and the field: "poses.txt:17: field 'r23': not a number: 'x'".

#include <string>
#include <string_view>
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/files/text_file.hpp"

namespace sunvo::files {

// Frame period assumed for a KITTI pose file read without a times file (10 Hz).
inline constexpr TimeNs kKittiNominalFramePeriodNs = 100'000'000;

// A sequence of poses T_w_c[k] with their times t_ns[k] (same length). For a KITTI file read
// without times, t_ns holds k * kKittiNominalFramePeriodNs (nominal, not measured).
struct Trajectory {
  std::vector<TimeNs> t_ns;
  std::vector<Isometry3> T_w_c;

  std::size_t size() const { return T_w_c.size(); }
};

enum class TrajectoryFormat { kKitti, kTum };

const char* toString(TrajectoryFormat format);

// Parsers over an already opened file (also usable with TextFile::fromString).
Expected<Trajectory> parseKittiPoses(TextFile& file);
Expected<Trajectory> parseTumTrajectory(TextFile& file);
// One time in seconds per line (KITTI times.txt) -> ns, rounded to the nearest ns.
Expected<std::vector<TimeNs>> parseTimes(TextFile& file);

// File readers (kNotFound / kIoError for a missing or unreadable file, kParseError otherwise).
Expected<Trajectory> readKittiPoses(const std::string& path);
Expected<Trajectory> readTumTrajectory(const std::string& path);
Expected<std::vector<TimeNs>> readTimes(const std::string& path);

// Detects the format from the first non-blank, non-comment line: 12 fields -> KITTI,
// 8 fields -> TUM, anything else is an error naming that line.
Expected<TrajectoryFormat> detectTrajectoryFormat(TextFile& file);

// Reads a KITTI or TUM file, detecting its format. When times_path is not empty the times are
// read from it (KITTI only; a TUM file carries its own times, so a times file is an error).
Expected<Trajectory> loadTrajectory(const std::string& path, const std::string& times_path = "");

// Writers. Numbers are printed in the shortest form that reads back to the same double; TUM
// times are printed as seconds with 9 decimals (exact in ns). The trajectory must have
// t_ns.size() == T_w_c.size() for TUM; KITTI ignores t_ns.
std::string formatKittiPoses(const Trajectory& trajectory);
Expected<std::string> formatTumTrajectory(const Trajectory& trajectory);
Status writeKittiPoses(const std::string& path, const Trajectory& trajectory);
Status writeTumTrajectory(const std::string& path, const Trajectory& trajectory);
// Both at once, for evaluation tools such as evo: <base>.txt (KITTI) and <base>_tum.txt (TUM, with
// the trajectory's times). Every sunvo program that writes poses writes this pair.
Status writeTrajectoryFiles(const std::string& base, const Trajectory& trajectory);

// Parses a number of seconds ("12.5", "1317384588.915486", "1.037359e-01") into ns. Plain
// decimal text is converted exactly (digits beyond the 9th decimal are rounded); text with an
// exponent goes through double. The error names `field` on the current line of `file`.
Expected<TimeNs> parseSecondsToNs(const TextFile& file, std::string_view text,
                                  std::string_view field);

// Writes `content` to `path` (replacing it). kIoError names the path on failure.
Status writeWholeFile(const std::string& path, std::string_view content);

// Appends t_ns as seconds with exactly 9 decimals (exact, no rounding through double): what
// parseTimes and the TUM reader read back to the nanosecond.
void appendSecondsFromNs(std::string& out, TimeNs t_ns);

}  // namespace sunvo::files
