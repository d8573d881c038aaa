#include "sunvo/core/time.hpp"

#include <array>
#include <charconv>
#include <cstdio>

namespace sunvo {
namespace {

// Days from 1970-01-01 to the given civil date (Howard Hinnant's algorithm, public domain facts).
std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

void civilFromDays(std::int64_t z, int& y, unsigned& m, unsigned& d) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const auto doe = static_cast<unsigned>(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t yy = static_cast<std::int64_t>(yoe) + era * 400;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  d = doy - (153 * mp + 2) / 5 + 1;
  m = mp < 10 ? mp + 3 : mp - 9;
  y = static_cast<int>(yy + (m <= 2 ? 1 : 0));
}

bool parseInt(std::string_view s, int& out) {
  if (s.empty()) return false;
  const auto* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && ptr == end;
}

bool isLeap(int y) {
  return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
}

}  // namespace

TimeNs civilToUtcNs(int year, int month, int day, int hour, int minute, int second,
                    std::int64_t nanosecond) {
  const std::int64_t days =
      daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day));
  return ((days * 24 + hour) * 60 + minute) * 60 * kNsPerSecond + second * kNsPerSecond +
         nanosecond;
}

Expected<TimeNs> parseCivilTime(std::string_view text, std::int64_t utc_offset_s) {
  // Trim surrounding whitespace (KITTI files end lines with '\n', sometimes '\r\n').
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\r' || text.back() == '\n' ||
                           text.back() == '\t')) {
    text.remove_suffix(1);
  }
  const std::string shown(text);
  auto bad = [&](const char* why) {
    return parseError("time '" + shown + "': " + why +
                      " (expected YYYY-MM-DD HH:MM:SS[.fffffffff])");
  };
  if (text.size() < 19 || text[4] != '-' || text[7] != '-' ||
      (text[10] != ' ' && text[10] != 'T') || text[13] != ':' || text[16] != ':') {
    return bad("bad layout");
  }
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  if (!parseInt(text.substr(0, 4), y) || !parseInt(text.substr(5, 2), mo) ||
      !parseInt(text.substr(8, 2), d) || !parseInt(text.substr(11, 2), h) ||
      !parseInt(text.substr(14, 2), mi) || !parseInt(text.substr(17, 2), s)) {
    return bad("non-numeric field");
  }
  static constexpr std::array<int, 12> kDays{31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  // int64 ns since the epoch spans 1677-09-21 .. 2262-04-11; whole years inside it leave room
  // for any UTC offset (found by fuzzing: year 2411 overflowed).
  if (y < 1678 || y > 2261) return bad("year out of range [1678, 2261]");
  if (mo < 1 || mo > 12) return bad("month out of range");
  const int mdays = kDays[static_cast<std::size_t>(mo - 1)] + (mo == 2 && isLeap(y) ? 1 : 0);
  if (d < 1 || d > mdays) return bad("day out of range");
  if (h > 23 || mi > 59 || s > 60) return bad("time of day out of range");
  std::int64_t ns = 0;
  std::string_view frac = text.substr(19);
  if (!frac.empty()) {
    if (frac.front() != '.' || frac.size() < 2 || frac.size() > 10) return bad("bad fraction");
    frac.remove_prefix(1);
    std::int64_t scale = kNsPerSecond;
    for (char c : frac) {
      if (c < '0' || c > '9') return bad("bad fraction");
      scale /= 10;
      ns += (c - '0') * scale;
    }
  }
  return civilToUtcNs(y, mo, d, h, mi, s, ns) - utc_offset_s * kNsPerSecond;
}

std::string formatUtcIso(TimeNs t_ns) {
  std::int64_t secs = t_ns / kNsPerSecond;
  std::int64_t ns = t_ns % kNsPerSecond;
  if (ns < 0) {
    ns += kNsPerSecond;
    secs -= 1;
  }
  std::int64_t days = secs / 86400;
  std::int64_t sod = secs % 86400;
  if (sod < 0) {
    sod += 86400;
    days -= 1;
  }
  int y = 0;
  unsigned m = 0, d = 0;
  civilFromDays(days, y, m, d);
  std::array<char, 48> buf{};
  std::snprintf(buf.data(), buf.size(), "%04d-%02u-%02uT%02d:%02d:%02d.%09lldZ", y, m, d,
                static_cast<int>(sod / 3600), static_cast<int>((sod / 60) % 60),
                static_cast<int>(sod % 60), static_cast<long long>(ns));
  return buf.data();
}

}  // namespace sunvo
