#include "sunvo/kitti/timestamps.hpp"

#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"

namespace sunvo::kitti {
namespace {

const std::string kDrive =
    std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26/2011_09_26_drive_0001_sync";

TEST(KittiTimestamps, RealCameraTimestampsAsUtcNs) {
  auto t = readRawTimestamps(kDrive + "/image_00/timestamps.txt", 0);
  ASSERT_TRUE(t) << t.status().toString();
  ASSERT_EQ(t->size(), 108u);
  // First line "2011-09-26 13:02:25.967790592", read as UTC.
  EXPECT_EQ(t->front(), civilToUtcNs(2011, 9, 26, 13, 2, 25, 967790592));
  EXPECT_EQ(t->front(), 1317042145967790592LL);
  // Last line "2011-09-26 13:02:37.006893056"? Checked through the formatter instead.
  EXPECT_EQ(formatRawTimestamp(t->at(1), 0), "2011-09-26 13:02:26.070920448");
  // The same file read as UTC+2 (Central European Summer Time) is two hours earlier in UTC.
  auto cest = readRawTimestamps(kDrive + "/image_00/timestamps.txt", 7200);
  ASSERT_TRUE(cest);
  EXPECT_EQ(t->front() - cest->front(), 7200 * kNsPerSecond);
  // OXTS timestamps of the same drive.
  auto oxts = readRawTimestamps(kDrive + "/oxts/timestamps.txt", 0);
  ASSERT_TRUE(oxts);
  EXPECT_EQ(oxts->size(), 108u);
  EXPECT_EQ(oxts->front(), civilToUtcNs(2011, 9, 26, 13, 2, 25, 964389445));
}

TEST(KittiTimestamps, OdometryTimesAreRelativeToAnExplicitStart) {
  const TimeNs start = civilToUtcNs(2011, 10, 3, 12, 55, 34, 0);
  auto t = readOdometryTimes(
      std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames/times.txt", start);
  ASSERT_TRUE(t) << t.status().toString();
  ASSERT_EQ(t->size(), 11u);
  EXPECT_EQ(t->at(0), start);
  EXPECT_EQ(t->at(1), start + 103735900);    // 1.037359e-01 s
  EXPECT_EQ(t->at(10), start + 1036910000);  // 1.036910e+00 s
}

TEST(KittiTimestamps, ErrorsNameFileLineAndField) {
  testing::TempDir dir;
  const std::string path = dir.file("timestamps.txt");
  testing::writeText(path, "2011-09-26 13:02:25.967790592\n2011-09-26 13:62:26.070920448\n");
  auto t = readRawTimestamps(path, 0);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message().rfind(path + ":2: field 'timestamp': ", 0), 0u)
      << t.status().message();

  // A blank line followed by more timestamps would shift frames: rejected.
  testing::writeText(path, "2011-09-26 13:02:25.1\n\n2011-09-26 13:02:25.2\n");
  t = readRawTimestamps(path, 0);
  ASSERT_FALSE(t);
  EXPECT_NE(t.status().message().find(path + ":2: blank line"), std::string::npos);

  // Trailing blank lines are fine.
  testing::writeText(path, "2011-09-26 13:02:25.1\n2011-09-26 13:02:25.2\n\n\n");
  t = readRawTimestamps(path, 0);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->size(), 2u);

  // Found by fuzzing: a year beyond int64 ns is an error naming the line, not an overflow.
  testing::writeText(path, "2011-09-26 13:02:25.1\n2411-09-26 13:02:25.9677448\n");
  t = readRawTimestamps(path, 0);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message().rfind(path + ":2: field 'timestamp': ", 0), 0u)
      << t.status().message();
  EXPECT_NE(t.status().message().find("year out of range"), std::string::npos);

  testing::writeText(path, "0.0\n0.1 0.2\n");
  t = readOdometryTimes(path, 1);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message(), path + ":2: field 'time_s': expected 1 value, found 2");
  testing::writeText(path, "0.0\nx\n");
  t = readOdometryTimes(path, 1);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.status().message(), path + ":2: field 'time_s': not a number: 'x'");
}

TEST(KittiTimestamps, WriteReadRoundTripWithOffset) {
  testing::TempDir dir;
  const std::vector<TimeNs> times{1317042145967790592LL, 1317042146070920448LL,
                                  1317042146174361088LL};
  const std::string path = dir.file("timestamps.txt");
  ASSERT_TRUE(writeRawTimestamps(path, times, 3600));
  EXPECT_EQ(testing::readText(path).substr(0, 30), "2011-09-26 14:02:25.967790592\n");
  auto back = readRawTimestamps(path, 3600);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, times);
}

}  // namespace
}  // namespace sunvo::kitti
