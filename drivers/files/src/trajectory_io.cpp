#include "sunvo/files/trajectory_io.hpp"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>

namespace sunvo::files {
namespace {

constexpr std::array<const char*, 12> kKittiFieldNames = {"r11", "r12", "r13", "tx",  "r21", "r22",
                                                          "r23", "ty",  "r31", "r32", "r33", "tz"};
constexpr std::array<const char*, 8> kTumFieldNames = {"t",  "tx", "ty", "tz",
                                                       "qx", "qy", "qz", "qw"};

bool isComment(std::string_view line) {
  for (char c : line) {
    if (c == ' ' || c == '\t') continue;
    return c == '#';
  }
  return false;
}

void appendDouble(std::string& out, double v) {
  std::array<char, 32> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  out.append(buf.data(), res.ptr);
}

}  // namespace

void appendSecondsFromNs(std::string& out, TimeNs t_ns) {
  if (t_ns < 0) {
    out.push_back('-');
    // -(INT64_MIN) overflows; such a time is never meaningful, clamp it to the next value.
    t_ns = t_ns == INT64_MIN ? INT64_MAX : -t_ns;
  }
  const TimeNs whole = t_ns / kNsPerSecond;
  const TimeNs frac = t_ns % kNsPerSecond;
  std::string frac_text = std::to_string(frac);
  out += std::to_string(whole);
  out.push_back('.');
  out.append(9 - frac_text.size(), '0');
  out += frac_text;
}

const char* toString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kKitti:
      return "KITTI";
    case TrajectoryFormat::kTum:
      return "TUM";
  }
  return "unknown";
}

Expected<TimeNs> parseSecondsToNs(const TextFile& file, std::string_view text,
                                  std::string_view field) {
  if (text.find_first_of("eE") != std::string_view::npos) {
    auto v = file.parseDouble(text, field);
    if (!v) return v.status();
    // 9.2e9 s is the int64 ns range.
    if (std::abs(*v) > 9.0e9)
      return file.error(field, "time out of range: '" + std::string(text) + "'");
    return static_cast<TimeNs>(std::llround(*v * 1e9));
  }
  // Plain decimal: [-]digits[.digits], converted exactly.
  std::string_view rest = text;
  bool negative = false;
  if (!rest.empty() && (rest.front() == '-' || rest.front() == '+')) {
    negative = rest.front() == '-';
    rest.remove_prefix(1);
  }
  const std::size_t dot = rest.find('.');
  const std::string_view int_part = rest.substr(0, dot);
  const std::string_view frac_part =
      dot == std::string_view::npos ? std::string_view() : rest.substr(dot + 1);
  auto all_digits = [](std::string_view s) {
    for (char c : s) {
      if (c < '0' || c > '9') return false;
    }
    return true;
  };
  if ((int_part.empty() && frac_part.empty()) || !all_digits(int_part) || !all_digits(frac_part)) {
    return file.error(field, "not a number: '" + std::string(text) + "'");
  }
  std::int64_t whole = 0;
  if (!int_part.empty()) {
    const auto res = std::from_chars(int_part.data(), int_part.data() + int_part.size(), whole);
    if (res.ec != std::errc() || whole > 9'000'000'000) {
      return file.error(field, "time out of range: '" + std::string(text) + "'");
    }
  }
  std::int64_t frac_ns = 0;
  for (std::size_t i = 0; i < 9; ++i) {
    frac_ns = frac_ns * 10 + (i < frac_part.size() ? frac_part[i] - '0' : 0);
  }
  if (frac_part.size() > 9 && frac_part[9] >= '5') ++frac_ns;  // round half up on the 10th digit
  const TimeNs t = whole * kNsPerSecond + frac_ns;
  return negative ? -t : t;
}

Expected<Trajectory> parseKittiPoses(TextFile& file) {
  Trajectory traj;
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 12) {
      return file.lineError("expected 12 fields (3x4 row-major [R|t]), found " +
                            std::to_string(fields.size()));
    }
    Eigen::Matrix<double, 3, 4> Rt;
    for (int i = 0; i < 12; ++i) {
      auto v = file.parseDouble(fields[static_cast<std::size_t>(i)],
                                kKittiFieldNames[static_cast<std::size_t>(i)]);
      if (!v) return v.status();
      Rt(i / 4, i % 4) = *v;
    }
    const double det = Rt.leftCols<3>().determinant();
    if (!(det > 0.5 && det < 1.5)) {  // far from a rotation: a corrupted or transposed line
      return file.error(
          "r11", "rotation block is not a rotation (determinant " + std::to_string(det) + ")");
    }
    traj.t_ns.push_back(static_cast<TimeNs>(traj.T_w_c.size()) * kKittiNominalFramePeriodNs);
    traj.T_w_c.push_back(isometryFrom3x4(Rt));
  }
  if (traj.T_w_c.empty()) return parseError(file.path() + ": no poses");
  return traj;
}

Expected<Trajectory> parseTumTrajectory(TextFile& file) {
  Trajectory traj;
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line) || isComment(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 8) {
      return file.lineError("expected 8 fields (t tx ty tz qx qy qz qw), found " +
                            std::to_string(fields.size()));
    }
    auto t = parseSecondsToNs(file, fields[0], kTumFieldNames[0]);
    if (!t) return t.status();
    std::array<double, 7> v{};
    for (std::size_t i = 0; i < 7; ++i) {
      auto x = file.parseDouble(fields[i + 1], kTumFieldNames[i + 1]);
      if (!x) return x.status();
      v[i] = *x;
    }
    Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // (w, x, y, z)
    const double n = q.norm();
    if (!(n > 1e-12)) return file.error("qw", "quaternion of zero norm");
    q.coeffs() /= n;
    if (!traj.t_ns.empty() && *t <= traj.t_ns.back()) {
      return file.error("t", "time does not increase: '" + std::string(fields[0]) + "'");
    }
    Isometry3 T = Isometry3::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    traj.t_ns.push_back(*t);
    traj.T_w_c.push_back(T);
  }
  if (traj.T_w_c.empty()) return parseError(file.path() + ": no poses");
  return traj;
}

Expected<std::vector<TimeNs>> parseTimes(TextFile& file) {
  std::vector<TimeNs> times;
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line) || isComment(line)) continue;
    const auto fields = splitFields(line);
    if (fields.size() != 1) {
      return file.lineError("expected 1 field (time in s), found " + std::to_string(fields.size()));
    }
    auto t = parseSecondsToNs(file, fields[0], "t");
    if (!t) return t.status();
    if (!times.empty() && *t <= times.back()) {
      return file.error("t", "time does not increase: '" + std::string(fields[0]) + "'");
    }
    times.push_back(*t);
  }
  if (times.empty()) return parseError(file.path() + ": no times");
  return times;
}

Expected<Trajectory> readKittiPoses(const std::string& path) {
  auto file = TextFile::open(path);
  if (!file) return file.status();
  return parseKittiPoses(*file);
}

Expected<Trajectory> readTumTrajectory(const std::string& path) {
  auto file = TextFile::open(path);
  if (!file) return file.status();
  return parseTumTrajectory(*file);
}

Expected<std::vector<TimeNs>> readTimes(const std::string& path) {
  auto file = TextFile::open(path);
  if (!file) return file.status();
  return parseTimes(*file);
}

Expected<TrajectoryFormat> detectTrajectoryFormat(TextFile& file) {
  std::string_view line;
  while (file.nextLine(line)) {
    if (isBlank(line) || isComment(line)) continue;
    const std::size_t n = splitFields(line).size();
    if (n == 12) return TrajectoryFormat::kKitti;
    if (n == 8) return TrajectoryFormat::kTum;
    return file.lineError("cannot tell the trajectory format: " + std::to_string(n) +
                          " fields (KITTI has 12, TUM has 8)");
  }
  return parseError(file.path() + ": no poses");
}

Expected<Trajectory> loadTrajectory(const std::string& path, const std::string& times_path) {
  auto probe = TextFile::open(path);
  if (!probe) return probe.status();
  auto format = detectTrajectoryFormat(*probe);
  if (!format) return format.status();
  auto file = TextFile::open(path);  // parse from the first line again
  if (!file) return file.status();
  if (*format == TrajectoryFormat::kTum) {
    if (!times_path.empty()) {
      return invalidArgument(path + ": a TUM trajectory carries its own times; times file '" +
                             times_path + "' not allowed");
    }
    return parseTumTrajectory(*file);
  }
  auto traj = parseKittiPoses(*file);
  if (!traj || times_path.empty()) return traj;
  auto times = readTimes(times_path);
  if (!times) return times.status();
  if (times->size() != traj->size()) {
    return parseError(times_path + ": " + std::to_string(times->size()) + " times for " +
                      std::to_string(traj->size()) + " poses in " + path);
  }
  traj->t_ns = std::move(*times);
  return traj;
}

std::string formatKittiPoses(const Trajectory& trajectory) {
  std::string out;
  out.reserve(trajectory.size() * 200);
  for (const Isometry3& T : trajectory.T_w_c) {
    for (int i = 0; i < 12; ++i) {
      if (i > 0) out.push_back(' ');
      appendDouble(out, T.matrix()(i / 4, i % 4));
    }
    out.push_back('\n');
  }
  return out;
}

Expected<std::string> formatTumTrajectory(const Trajectory& trajectory) {
  if (trajectory.t_ns.size() != trajectory.T_w_c.size()) {
    return invalidArgument("TUM trajectory: " + std::to_string(trajectory.t_ns.size()) +
                           " times for " + std::to_string(trajectory.T_w_c.size()) + " poses");
  }
  std::string out = "# t tx ty tz qx qy qz qw\n";
  out.reserve(trajectory.size() * 160);
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    const Isometry3& T = trajectory.T_w_c[k];
    const Eigen::Quaterniond q(Eigen::Matrix3d(T.linear()));
    appendSecondsFromNs(out, trajectory.t_ns[k]);
    for (double v : {T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(),
                     q.z(), q.w()}) {
      out.push_back(' ');
      appendDouble(out, v);
    }
    out.push_back('\n');
  }
  return out;
}

Status writeWholeFile(const std::string& path, std::string_view content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return ioError(path + ": cannot open for writing: " + std::strerror(errno));
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out) return ioError(path + ": write failed");
  return Status::ok();
}

Status writeKittiPoses(const std::string& path, const Trajectory& trajectory) {
  return writeWholeFile(path, formatKittiPoses(trajectory));
}

Status writeTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  auto text = formatTumTrajectory(trajectory);
  if (!text) return text.status();
  return writeWholeFile(path, *text);
}

Status writeTrajectoryFiles(const std::string& base, const Trajectory& trajectory) {
  SUNVO_RETURN_IF_ERROR(writeKittiPoses(base + ".txt", trajectory));
  return writeTumTrajectory(base + "_tum.txt", trajectory);
}

}  // namespace sunvo::files
