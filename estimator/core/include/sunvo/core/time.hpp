#pragma once
// Time inside sunvo: UTC nanoseconds since the Unix epoch, int64, everywhere.
// Latency is measured on the monotonic clock, also in int64 nanoseconds.

#include <cstdint>
#include <string>
#include <string_view>

#include "sunvo/core/status.hpp"

namespace sunvo {

using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerSecond = 1'000'000'000;

inline constexpr double toSeconds(TimeNs t) {
  return static_cast<double>(t) * 1e-9;
}

// Civil date/time -> ns since epoch, treating the fields as UTC (proleptic Gregorian).
TimeNs civilToUtcNs(int year, int month, int day, int hour, int minute, int second,
                    std::int64_t nanosecond);

// Parses "YYYY-MM-DD HH:MM:SS[.fffffffff]" (KITTI raw timestamps; 'T' also accepted between
// date and time) as a local time that is utc_offset_s ahead of UTC, and returns UTC ns.
// Example: a recording made in UTC+1 is read with utc_offset_s = 3600. Years outside
// [1678, 2261] (beyond int64 ns) are a parse error.
Expected<TimeNs> parseCivilTime(std::string_view text, std::int64_t utc_offset_s);

// Formats UTC ns as "YYYY-MM-DDTHH:MM:SS.fffffffffZ".
std::string formatUtcIso(TimeNs t_ns);

}  // namespace sunvo
