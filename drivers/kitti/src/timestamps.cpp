#include "sunvo/kitti/timestamps.hpp"

#include <cmath>
#include <fstream>

#include "sunvo/files/text_file.hpp"

namespace sunvo::kitti {
namespace {

// Reads the non-blank lines of `file` through `parse_line`; rejects blank lines in the middle.
template <typename ParseLine>
Expected<std::vector<TimeNs>> readLines(const std::string& path, ParseLine parse_line) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  std::vector<TimeNs> out;
  std::string_view line;
  int blank_line = 0;  // first blank line seen, 0 = none
  while (file->nextLine(line)) {
    if (files::isBlank(line)) {
      if (blank_line == 0) blank_line = file->lineNumber();
      continue;
    }
    if (blank_line != 0) {
      return parseError(path + ":" + std::to_string(blank_line) +
                        ": blank line before more timestamps (a missing timestamp?)");
    }
    auto t = parse_line(*file, line);
    if (!t) return t.status();
    out.push_back(*t);
  }
  return out;
}

}  // namespace

Expected<std::vector<TimeNs>> readRawTimestamps(const std::string& path,
                                                std::int64_t utc_offset_s) {
  return readLines(path, [&](const files::TextFile& f, std::string_view line) -> Expected<TimeNs> {
    auto t = parseCivilTime(line, utc_offset_s);
    if (!t) return f.error("timestamp", t.status().message());
    return *t;
  });
}

Expected<std::vector<TimeNs>> readOdometryTimes(const std::string& path, TimeNs start_time_ns) {
  return readLines(path, [&](const files::TextFile& f, std::string_view line) -> Expected<TimeNs> {
    const auto fields = files::splitFields(line);
    if (fields.size() != 1) {
      return f.error("time_s", "expected 1 value, found " + std::to_string(fields.size()));
    }
    auto s = f.parseDouble(fields[0], "time_s");
    if (!s) return s.status();
    if (*s < 0.0 || *s > 1e7) return f.error("time_s", "out of range [0, 1e7] s");
    return start_time_ns + std::llround(*s * 1e9);
  });
}

std::string formatRawTimestamp(TimeNs t_ns, std::int64_t utc_offset_s) {
  // formatUtcIso gives "YYYY-MM-DDTHH:MM:SS.nnnnnnnnnZ"; KITTI writes a space and no zone.
  std::string s = formatUtcIso(t_ns + utc_offset_s * kNsPerSecond);
  s[10] = ' ';
  s.pop_back();
  return s;
}

Status writeRawTimestamps(const std::string& path, const std::vector<TimeNs>& times_ns,
                          std::int64_t utc_offset_s) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return ioError(path + ": cannot open for writing");
  for (TimeNs t : times_ns) out << formatRawTimestamp(t, utc_offset_s) << '\n';
  out.flush();
  if (!out) return ioError(path + ": write failed");
  return Status::ok();
}

}  // namespace sunvo::kitti
