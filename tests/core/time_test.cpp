#include "sunvo/core/time.hpp"

#include <gtest/gtest.h>

namespace sunvo {
namespace {

TEST(Time, CivilToUtcKnownEpochs) {
  EXPECT_EQ(civilToUtcNs(1970, 1, 1, 0, 0, 0, 0), 0);
  // 2011-09-30 00:00:00 UTC = 1317340800 s (date -u -d 2011-09-30 +%s).
  EXPECT_EQ(civilToUtcNs(2011, 9, 30, 0, 0, 0, 0), 1317340800LL * kNsPerSecond);
  EXPECT_EQ(civilToUtcNs(2000, 2, 29, 12, 0, 0, 5), 951825600LL * kNsPerSecond + 5);
}

TEST(Time, ParsesKittiTimestampWithNanoseconds) {
  auto t = parseCivilTime("2011-09-26 13:02:25.964389445", 0);
  ASSERT_TRUE(t) << t.status().toString();
  EXPECT_EQ(*t, civilToUtcNs(2011, 9, 26, 13, 2, 25, 964389445));
}

TEST(Time, AppliesUtcOffset) {
  auto local = parseCivilTime("2011-10-03 12:55:34.5", 3600);  // recorded in UTC+1
  ASSERT_TRUE(local);
  EXPECT_EQ(*local, civilToUtcNs(2011, 10, 3, 11, 55, 34, 500000000));
}

TEST(Time, RejectsMalformedText) {
  for (const char* bad :
       {"", "2011-09-26", "2011-13-26 13:02:25", "2011-02-30 13:02:25", "2011-09-26 25:02:25",
        "2011-09-26 13:02:25,5", "2011-09-26 13:0x:25", "2011-09-26 13:02:25.1234567890"}) {
    auto t = parseCivilTime(bad, 0);
    EXPECT_FALSE(t) << bad;
    if (!t) {
      EXPECT_NE(t.status().message().find("time '"), std::string::npos);
    }
  }
}

// Found by fuzzing (tests/fuzz/fuzz_kitti_timestamps): a year beyond int64 ns overflowed
// (signed overflow, undefined) instead of being an error.
TEST(Time, YearsBeyondInt64NanosecondsAreRejected) {
  for (const char* far : {"2411-09-26 13:02:25.9677448", "1677-01-01 00:00:00",
                          "-999-01-01 00:00:00", "9999-12-31 23:59:59"}) {
    auto t = parseCivilTime(far, 0);
    ASSERT_FALSE(t) << far;
    EXPECT_NE(t.status().message().find("year out of range"), std::string::npos)
        << t.status().message();
  }
  // The ends of the accepted range, with the largest UTC offsets.
  auto first = parseCivilTime("1678-01-01 00:00:00", 50400);
  ASSERT_TRUE(first);
  EXPECT_EQ(*first, civilToUtcNs(1678, 1, 1, 0, 0, 0, 0) - 50400 * kNsPerSecond);
  auto last = parseCivilTime("2261-12-31 23:59:60.999999999", -50400);
  ASSERT_TRUE(last);
  EXPECT_GT(*last, civilToUtcNs(2261, 12, 31, 0, 0, 0, 0));
}

TEST(Time, FormatRoundTrip) {
  const TimeNs t = civilToUtcNs(2026, 11, 21, 23, 59, 59, 123456789);
  EXPECT_EQ(formatUtcIso(t), "2026-11-21T23:59:59.123456789Z");
  EXPECT_EQ(*parseCivilTime(formatUtcIso(t).substr(0, 29), 0), t);
}

}  // namespace
}  // namespace sunvo
