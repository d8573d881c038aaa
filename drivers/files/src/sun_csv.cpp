#include "sunvo/files/sun_csv.hpp"

#include <array>
#include <cmath>
#include <cstdio>

#include "sunvo/files/text_file.hpp"
#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::files {

Expected<SunCsv> readSunCsv(const std::string& path, double unit_tolerance) {
  auto file = TextFile::open(path);
  if (!file) return file.status();
  std::string_view line;
  if (!file->nextLine(line))
    return parseError(path + ": empty file (expected header frame,sx,sy,sz)");
  const auto header = splitFields(line, ',');
  static constexpr std::array<const char*, 4> kNames{"frame", "sx", "sy", "sz"};
  if (header.size() != 4 || header[0] != "frame" || header[1] != "sx" || header[2] != "sy" ||
      header[3] != "sz") {
    return file->lineError("header must be 'frame,sx,sy,sz'");
  }
  SunCsv out;
  while (file->nextLine(line)) {
    if (isBlank(line)) continue;
    const auto f = splitFields(line, ',');
    if (f.size() != 4) {
      return file->lineError("expected 4 fields, found " + std::to_string(f.size()));
    }
    auto frame = file->parseInt(f[0], kNames[0]);
    if (!frame) return frame.status();
    if (*frame != static_cast<std::int64_t>(out.sun_c.size())) {
      return file->error("frame", "expected frame " + std::to_string(out.sun_c.size()) +
                                      ", found " + std::to_string(*frame));
    }
    Eigen::Vector3d s;
    for (int i = 0; i < 3; ++i) {
      auto v = file->parseDouble(f[static_cast<std::size_t>(i + 1)],
                                 kNames[static_cast<std::size_t>(i + 1)]);
      if (!v) return v.status();
      s[i] = *v;
    }
    if (std::abs(s.norm() - 1.0) > unit_tolerance) {
      return file->error("sx,sy,sz", "not a unit vector (norm " + std::to_string(s.norm()) + ")");
    }
    out.sun_c.push_back(s.normalized());
  }
  if (out.sun_c.empty()) return parseError(path + ": no data rows");
  return out;
}

Status writeSunCsv(const std::string& path, const SunCsv& sun) {
  std::string text = "frame,sx,sy,sz\n";
  char line[128];
  for (std::size_t k = 0; k < sun.sun_c.size(); ++k) {
    const Eigen::Vector3d& s = sun.sun_c[k];
    std::snprintf(line, sizeof(line), "%zu,%.9f,%.9f,%.9f\n", k, s.x(), s.y(), s.z());
    text += line;
  }
  return writeWholeFile(path, text);
}

}  // namespace sunvo::files
