#include "sunvo/kitti/oxts.hpp"

#include <charconv>
#include <cstdio>
#include <fstream>

#include "sunvo/kitti/timestamps.hpp"

namespace sunvo::kitti {
namespace {

constexpr std::size_t kRealCount = 25;
using RealField = double OxtsRecord::*;
using IntField = std::int64_t OxtsRecord::*;

constexpr std::array<RealField, kRealCount> kReals{
    &OxtsRecord::lat,         &OxtsRecord::lon, &OxtsRecord::alt, &OxtsRecord::roll,
    &OxtsRecord::pitch,       &OxtsRecord::yaw, &OxtsRecord::vn,  &OxtsRecord::ve,
    &OxtsRecord::vf,          &OxtsRecord::vl,  &OxtsRecord::vu,  &OxtsRecord::ax,
    &OxtsRecord::ay,          &OxtsRecord::az,  &OxtsRecord::af,  &OxtsRecord::al,
    &OxtsRecord::au,          &OxtsRecord::wx,  &OxtsRecord::wy,  &OxtsRecord::wz,
    &OxtsRecord::wf,          &OxtsRecord::wl,  &OxtsRecord::wu,  &OxtsRecord::pos_accuracy,
    &OxtsRecord::vel_accuracy};
constexpr std::array<IntField, kOxtsFieldCount - kRealCount> kInts{
    &OxtsRecord::navstat, &OxtsRecord::numsats, &OxtsRecord::posmode, &OxtsRecord::velmode,
    &OxtsRecord::orimode};

}  // namespace

const std::array<std::string_view, kOxtsFieldCount>& oxtsFieldNames() {
  static constexpr std::array<std::string_view, kOxtsFieldCount> kNames{
      "lat",          "lon",     "alt",     "roll",    "pitch",   "yaw",    "vn", "ve",
      "vf",           "vl",      "vu",      "ax",      "ay",      "az",     "af", "al",
      "au",           "wx",      "wy",      "wz",      "wf",      "wl",     "wu", "pos_accuracy",
      "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"};
  return kNames;
}

Expected<OxtsRecord> parseOxtsRecord(files::TextFile& file) {
  const auto& names = oxtsFieldNames();
  std::string_view line;
  bool have_record = false;
  OxtsRecord rec;
  while (file.nextLine(line)) {
    if (files::isBlank(line)) continue;
    if (have_record) return file.lineError("more than one OXTS record in the file");
    have_record = true;
    const auto fields = files::splitFields(line);
    if (fields.size() != kOxtsFieldCount) {
      // Name the first absent field (or say which ones are extra).
      if (fields.size() < kOxtsFieldCount) {
        return file.error(names[fields.size()],
                          "missing: expected " + std::to_string(kOxtsFieldCount) +
                              " fields, found " + std::to_string(fields.size()));
      }
      return file.lineError("expected " + std::to_string(kOxtsFieldCount) + " fields, found " +
                            std::to_string(fields.size()));
    }
    for (std::size_t i = 0; i < kRealCount; ++i) {
      auto v = file.parseDouble(fields[i], names[i]);
      if (!v) return v.status();
      rec.*kReals[i] = *v;
    }
    for (std::size_t i = 0; i < kInts.size(); ++i) {
      auto v = file.parseInt(fields[kRealCount + i], names[kRealCount + i]);
      if (!v) return v.status();
      rec.*kInts[i] = *v;
    }
  }
  if (!have_record) return parseError(file.path() + ": empty OXTS record file");
  return rec;
}

Expected<OxtsRecord> readOxtsRecord(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  return parseOxtsRecord(*file);
}

std::string formatOxtsRecord(const OxtsRecord& record) {
  std::string out;
  out.reserve(512);
  std::array<char, 32> buf{};
  for (std::size_t i = 0; i < kRealCount; ++i) {
    // Shortest representation that parses back to the identical double.
    auto [ptr, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), record.*kReals[i]);
    (void)ec;  // 32 chars always suffice for a double
    if (i > 0) out += ' ';
    out.append(buf.data(), ptr);
  }
  for (IntField f : kInts) {
    out += ' ';
    out += std::to_string(record.*f);
  }
  out += '\n';
  return out;
}

Status writeOxtsRecord(const std::string& path, const OxtsRecord& record) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return ioError(path + ": cannot open for writing");
  out << formatOxtsRecord(record);
  out.flush();
  if (!out) return ioError(path + ": write failed");
  return Status::ok();
}

std::string oxtsRecordPath(const std::string& drive_dir, std::int64_t index) {
  std::array<char, 32> name{};
  std::snprintf(name.data(), name.size(), "%010lld", static_cast<long long>(index));
  return drive_dir + "/oxts/data/" + name.data() + ".txt";
}

Expected<std::vector<OxtsSample>> readOxtsSequence(const std::string& drive_dir,
                                                   std::int64_t utc_offset_s) {
  auto times = readRawTimestamps(drive_dir + "/oxts/timestamps.txt", utc_offset_s);
  if (!times) return times.status();
  std::vector<OxtsSample> out;
  out.reserve(times->size());
  for (std::size_t i = 0; i < times->size(); ++i) {
    const std::string path = oxtsRecordPath(drive_dir, static_cast<std::int64_t>(i));
    auto rec = readOxtsRecord(path);
    if (!rec) {
      return Status(rec.status().code(),
                    "OXTS record " + std::to_string(i) + ": " + rec.status().message());
    }
    out.push_back({(*times)[i], *rec});
  }
  return out;
}

}  // namespace sunvo::kitti
