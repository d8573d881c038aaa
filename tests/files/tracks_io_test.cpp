#include "sunvo/files/tracks_io.hpp"
#include "sunvo/files/trajectory_io.hpp"

#include <gtest/gtest.h>

namespace sunvo::files {
namespace {

const std::vector<TimeNs> kTimes = {1'000'000'000, 1'100'000'000, 1'200'000'000};

Expected<std::vector<FrameFeatures>> parse(const std::string& text) {
  auto f = TextFile::fromString("tracks.csv", text);
  return parseTracks(f, kTimes, 1242, 375);
}

void expectError(const std::string& text, const std::string& expected_message) {
  auto r = parse(text);
  ASSERT_FALSE(r) << text;
  EXPECT_EQ(r.status().code(), StatusCode::kParseError);
  EXPECT_EQ(r.status().message(), expected_message);
}

TEST(TracksIo, ParsesFramesAndKeepsEmptyOnes) {
  auto r = parse(
      "frame,landmark,uL,vL,uR,vR\n"
      "0,5,100.5,50.25,90.5,50.5\n"
      "0,7,200,60,195,60\n"
      "2,5,101,51,92,51\n"
      "2,9,10,10,12,10\n");  // negative disparity: accepted, the estimator decides
  ASSERT_TRUE(r) << r.status().toString();
  ASSERT_EQ(r->size(), 3u);
  EXPECT_EQ((*r)[0].observations.size(), 2u);
  EXPECT_TRUE((*r)[1].observations.empty());
  EXPECT_EQ((*r)[1].sequence, 1u);
  EXPECT_EQ((*r)[1].time_ns, 1'100'000'000);
  EXPECT_EQ((*r)[2].observations[0].landmark_id, 5);
  EXPECT_DOUBLE_EQ((*r)[0].observations[0].disparity(), 10.0);
  EXPECT_DOUBLE_EQ((*r)[2].observations[1].disparity(), -2.0);
}

TEST(TracksIo, RejectsMalformedRowsNamingFileLineAndField) {
  const std::string h = "frame,landmark,uL,vL,uR,vR\n";
  expectError(h + "0,1,1,2,3\n",
              "tracks.csv:2: expected 6 fields 'frame,landmark,uL,vL,uR,vR', got 5");
  expectError(h + "0,1,abc,2,3,4\n", "tracks.csv:2: field 'uL': not a number: 'abc'");
  expectError(h + "0,x,1,2,3,4\n", "tracks.csv:2: field 'landmark': not an integer: 'x'");
  expectError(h + "1,1,1,2,3,4\n0,2,1,2,3,4\n",
              "tracks.csv:3: field 'frame': frames out of order: 0 after 1");
  expectError(h + "3,1,1,2,3,4\n",
              "tracks.csv:2: field 'frame': out of range [0, 3) given by times.txt: 3");
  expectError(h + "0,1,1,2,3,400\n", "tracks.csv:2: field 'vR': outside the image [0, 375): 400");
  expectError(h + "0,1,1,2,3,4\n0,1,5,2,3,4\n",
              "tracks.csv:3: field 'landmark': duplicate in this frame");
  expectError("frame,lm,uL,vL,uR,vR\n",
              "tracks.csv:1: field 'landmark': unexpected header name 'lm'");
  expectError("", "tracks.csv: empty file, no header");
}

TEST(TracksIo, CalibTimesAndPoses) {
  auto c = TextFile::fromString("calib.txt", "707.0912 707.0912 601.8873 183.1104 0.5371\n");
  auto cam = parseTrackCalib(c, 1242, 375);
  ASSERT_TRUE(cam);
  EXPECT_DOUBLE_EQ(cam->baseline_m, 0.5371);
  EXPECT_EQ(cam->width, 1242);
  auto bad = TextFile::fromString("calib.txt", "707 707 601 183\n");
  EXPECT_EQ(parseTrackCalib(bad, 1242, 375).status().message(),
            "calib.txt:1: expected 5 fields 'fu fv cu cv baseline_m', got 4");
  auto neg = TextFile::fromString("calib.txt", "707 707 601 183 -0.5\n");
  EXPECT_EQ(parseTrackCalib(neg, 1242, 375).status().message(),
            "calib.txt:1: field 'baseline_m': must be > 0");

  // Track times go through trajectory_io's exact decimal parser: nanoseconds survive.
  auto t = TextFile::fromString("times.txt", "1317384506.402996540\n1317384506.5\n");
  auto times = parseTimes(t);
  ASSERT_TRUE(times);
  EXPECT_EQ((*times)[0], 1317384506402996540);
  EXPECT_EQ((*times)[1], 1317384506500000000);
  auto tb = TextFile::fromString("times.txt", "10.5\n10.4\n");
  EXPECT_FALSE(parseTimes(tb));
}

TEST(TracksIo, ReadsTheReal0020Folder) {
  const std::string dir = std::string(SUNVO_DATA_DIR) + "/kitti_tracks/2011_09_30_drive_0020";
  auto seq = readTrackFolder(dir, TrackReadOptions{});
  ASSERT_TRUE(seq) << seq.status().toString();
  ASSERT_EQ(seq->frames.size(), 1000u);
  ASSERT_EQ(seq->gt_T_0_k.size(), 1000u);
  std::size_t n = 0;
  for (const auto& f : seq->frames) n += f.observations.size();
  EXPECT_EQ(n, 64499u);  // data/README.md: 64,499 observations
  EXPECT_NEAR(seq->camera.fu, 707.0912, 1e-9);
  EXPECT_EQ(seq->frames[1].time_ns, 1317384506507502079);
  auto missing = readTrackFolder("/nonexistent/tracks", TrackReadOptions{});
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace sunvo::files
