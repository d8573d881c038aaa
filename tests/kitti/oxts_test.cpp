#include "sunvo/kitti/oxts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "../support/temp_dir.hpp"

namespace sunvo::kitti {
namespace {

const std::string kDrive =
    std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26/2011_09_26_drive_0001_sync";

std::vector<double> valuesOf(const OxtsRecord& r) {
  return {r.lat,
          r.lon,
          r.alt,
          r.roll,
          r.pitch,
          r.yaw,
          r.vn,
          r.ve,
          r.vf,
          r.vl,
          r.vu,
          r.ax,
          r.ay,
          r.az,
          r.af,
          r.al,
          r.au,
          r.wx,
          r.wy,
          r.wz,
          r.wf,
          r.wl,
          r.wu,
          r.pos_accuracy,
          r.vel_accuracy,
          static_cast<double>(r.navstat),
          static_cast<double>(r.numsats),
          static_cast<double>(r.posmode),
          static_cast<double>(r.velmode),
          static_cast<double>(r.orimode)};
}

TEST(KittiOxts, RealRecordAllThirtyFields) {
  const std::string path = oxtsRecordPath(kDrive, 0);
  EXPECT_EQ(path, kDrive + "/oxts/data/0000000000.txt");
  auto r = readOxtsRecord(path);
  ASSERT_TRUE(r) << r.status().toString();
  EXPECT_DOUBLE_EQ(r->lat, 49.015003823272);
  EXPECT_DOUBLE_EQ(r->lon, 8.4342971002335);
  EXPECT_DOUBLE_EQ(r->alt, 116.43032836914);
  EXPECT_DOUBLE_EQ(r->roll, 0.035752);
  EXPECT_DOUBLE_EQ(r->pitch, 0.00903);
  EXPECT_DOUBLE_EQ(r->yaw, -2.6087069803847);
  EXPECT_DOUBLE_EQ(r->az, 10.209865300506);
  EXPECT_DOUBLE_EQ(r->vel_accuracy, 0.012727922061358);
  EXPECT_EQ(r->navstat, 4);
  EXPECT_EQ(r->numsats, 11);
  EXPECT_EQ(r->posmode, 6);
  EXPECT_EQ(r->velmode, 6);
  EXPECT_EQ(r->orimode, 6);
  // Every field against an independent strtod of the file's tokens, in order.
  std::istringstream tokens(testing::readText(path));
  const std::vector<double> got = valuesOf(*r);
  std::string tok;
  std::size_t i = 0;
  while (tokens >> tok) {
    ASSERT_LT(i, got.size());
    EXPECT_EQ(got[i], std::strtod(tok.c_str(), nullptr)) << oxtsFieldNames()[i];
    ++i;
  }
  EXPECT_EQ(i, kOxtsFieldCount);
}

TEST(KittiOxts, FieldNamesFollowDataformatTxt) {
  // dataformat.txt lists "name: description" per field. Its 14th entry is a known typo in
  // KITTI's file ("ay:" again, described as "acceleration in z"); that field is az.
  std::istringstream lines(testing::readText(kDrive + "/oxts/dataformat.txt"));
  std::string line;
  std::size_t i = 0;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    ASSERT_LT(i, kOxtsFieldCount);
    const std::string name = line.substr(0, line.find(':'));
    if (i == 13) {
      EXPECT_EQ(name, "ay");
      EXPECT_NE(line.find("acceleration in z"), std::string::npos);
      EXPECT_EQ(oxtsFieldNames()[i], "az");
    } else {
      EXPECT_EQ(name, oxtsFieldNames()[i]);
    }
    ++i;
  }
  EXPECT_EQ(i, kOxtsFieldCount);
}

TEST(KittiOxts, NonNumericFieldNamesFileLineAndField) {
  testing::TempDir dir;
  std::string text = testing::readText(oxtsRecordPath(kDrive, 0));
  const std::string pitch = " 0.00903 ";
  const auto at = text.find(pitch);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, pitch.size(), " 0.0o903 ");
  const std::string path = dir.file("0000000000.txt");
  testing::writeText(path, "\n" + text);  // the record on line 2
  auto r = readOxtsRecord(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().message(), path + ":2: field 'pitch': not a number: '0.0o903'");
}

TEST(KittiOxts, MissingFieldsIntegerFieldsAndExtraLines) {
  testing::TempDir dir;
  const std::string path = dir.file("r.txt");
  std::string text = testing::readText(oxtsRecordPath(kDrive, 0));
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();

  testing::writeText(path, text.substr(0, text.rfind(' ')) + "\n");  // 29 fields
  auto r = readOxtsRecord(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().message(),
            path + ":1: field 'orimode': missing: expected 30 fields, found 29");

  std::string real_navstat = text;
  real_navstat.replace(real_navstat.rfind(" 4 11 "), 6, " 4.0 11 ");
  testing::writeText(path, real_navstat + "\n");
  r = readOxtsRecord(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().message(), path + ":1: field 'navstat': not an integer: '4.0'");

  testing::writeText(path, text + " 7\n");
  r = readOxtsRecord(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().message(), path + ":1: expected 30 fields, found 31");

  testing::writeText(path, text + "\n" + text + "\n");
  r = readOxtsRecord(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().message(), path + ":2: more than one OXTS record in the file");

  testing::writeText(path, "\n");
  EXPECT_FALSE(readOxtsRecord(path));
}

TEST(KittiOxts, WriteReadRoundTripIsExact) {
  testing::TempDir dir;
  auto real = readOxtsRecord(oxtsRecordPath(kDrive, 0));
  ASSERT_TRUE(real);
  OxtsRecord r = *real;
  r.lat = 0.1 + 0.2;  // not exactly representable in short decimal
  r.lon = -179.99999999999997;
  r.alt = 1e-300;
  r.yaw = std::nextafter(M_PI, 4.0);
  r.wu = -0.0;
  r.numsats = -3;
  const std::string path = oxtsRecordPath(dir.str(), 7);
  std::filesystem::create_directories(dir.str() + "/oxts/data");
  ASSERT_TRUE(writeOxtsRecord(path, r));
  auto back = readOxtsRecord(path);
  ASSERT_TRUE(back) << back.status().toString();
  const auto a = valuesOf(r);
  const auto b = valuesOf(*back);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i], b[i]) << oxtsFieldNames()[i];
    EXPECT_EQ(std::signbit(a[i]), std::signbit(b[i])) << oxtsFieldNames()[i];
  }
  // The real record also survives the writer unchanged in value.
  ASSERT_TRUE(writeOxtsRecord(path, *real));
  back = readOxtsRecord(path);
  ASSERT_TRUE(back);
  EXPECT_EQ(valuesOf(*back), valuesOf(*real));
}

TEST(KittiOxts, SequenceReaderNamesAMissingRecord) {
  testing::TempDir dir;
  auto real = readOxtsRecord(oxtsRecordPath(kDrive, 0));
  ASSERT_TRUE(real);
  testing::writeText(dir.file("oxts/timestamps.txt"),
                     "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.074347616\n");
  std::filesystem::create_directories(dir.file("oxts/data"));
  ASSERT_TRUE(writeOxtsRecord(oxtsRecordPath(dir.str(), 0), *real));
  auto seq = readOxtsSequence(dir.str(), 0);
  ASSERT_FALSE(seq);
  EXPECT_EQ(seq.status().code(), StatusCode::kNotFound);
  EXPECT_NE(seq.status().message().find("OXTS record 1"), std::string::npos);
  EXPECT_NE(seq.status().message().find("0000000001.txt"), std::string::npos);
  OxtsRecord second = *real;
  second.lat += 1e-5;
  ASSERT_TRUE(writeOxtsRecord(oxtsRecordPath(dir.str(), 1), second));
  seq = readOxtsSequence(dir.str(), 0);
  ASSERT_TRUE(seq) << seq.status().toString();
  ASSERT_EQ(seq->size(), 2u);
  EXPECT_EQ(seq->at(1).time_ns, civilToUtcNs(2011, 9, 26, 13, 2, 26, 74347616));
  EXPECT_EQ(seq->at(1).record.lat, second.lat);
}

}  // namespace
}  // namespace sunvo::kitti
