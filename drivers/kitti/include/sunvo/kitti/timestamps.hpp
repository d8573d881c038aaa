#pragma once
// KITTI timestamp files.
//
// Raw layout: image_0x/timestamps.txt and oxts/timestamps.txt hold one civil time per line,
// "YYYY-MM-DD HH:MM:SS.nnnnnnnnn", in a zone the files do not name. The caller states the offset
// of that zone to UTC (utc_offset_s, e.g. 3600 for UTC+1); it is never guessed.
// Odometry layout: times.txt holds seconds since the first frame; the caller states the UTC time
// of the first frame (start_time_ns).

#include <cstdint>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::kitti {

// One UTC ns value per line. Trailing blank lines are allowed; a blank line followed by more
// timestamps is an error (it would shift every later frame). Errors name file, line and field.
Expected<std::vector<TimeNs>> readRawTimestamps(const std::string& path, std::int64_t utc_offset_s);

// Seconds since the first frame, one per line, mapped to UTC ns as
// start_time_ns + round(seconds * 1e9).
Expected<std::vector<TimeNs>> readOdometryTimes(const std::string& path, TimeNs start_time_ns);

// "YYYY-MM-DD HH:MM:SS.nnnnnnnnn" of UTC ns t_ns in the zone utc_offset_s ahead of UTC.
std::string formatRawTimestamp(TimeNs t_ns, std::int64_t utc_offset_s);

// Writes a raw-layout timestamps.txt (one formatRawTimestamp line per value).
Status writeRawTimestamps(const std::string& path, const std::vector<TimeNs>& times_ns,
                          std::int64_t utc_offset_s);

}  // namespace sunvo::kitti
