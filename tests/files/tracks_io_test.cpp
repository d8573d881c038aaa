#include "sunvo/files/tracks_io.hpp"

#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::files {
namespace {

const std::vector<TimeNs> kTimes = {1'000'000'000, 1'100'000'000, 1'200'000'000};

Expected<std::vector<FrameFeatures>> parse(const std::string& text) {
  auto f = TextFile::fromString("tracks.csv", text);
  auto r = parseTracks(f, kTimes, TrackBounds{1242, 375, 2.0});
  if (!r) return r.status();
  return std::move(r->frames);
}

// A track folder of three frames with the given calib.txt line and tracks.csv rows.
std::string writeFolder(const testing::TempDir& dir, const std::string& calib,
                        const std::string& rows) {
  testing::writeText(dir.file("calib.txt"), calib + "\n");
  testing::writeText(dir.file("times.txt"), "1.0\n1.1\n1.2\n");
  testing::writeText(dir.file("tracks.csv"), "frame,landmark,uL,vL,uR,vR\n" + rows);
  return dir.str();
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
  expectError(h + "0,1,1,2,3,400\n",
              "tracks.csv:2: field 'vR': outside the image [0, 375) by more than the 2.000 px "
              "tolerance: 400");
  expectError(h + "0,1,-2.5,2,3,4\n",
              "tracks.csv:2: field 'uL': outside the image [0, 1242) by more than the 2.000 px "
              "tolerance: -2.5");
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
            "calib.txt:1: expected 5 fields 'fu fv cu cv baseline_m' or 7 with 'width height', "
            "got 4");
  // A size on the line wins over the caller's.
  auto sized = TextFile::fromString("calib.txt", "718.856 718.856 607.19 185.22 0.537 1241 376\n");
  auto cam_sized = parseTrackCalib(sized, 1242, 375);
  ASSERT_TRUE(cam_sized) << cam_sized.status().toString();
  EXPECT_EQ(cam_sized->width, 1241);
  EXPECT_EQ(cam_sized->height, 376);
  auto bad_size = TextFile::fromString("calib.txt", "718 718 607 185 0.5 1241 3.5\n");
  EXPECT_EQ(parseTrackCalib(bad_size, 1242, 375).status().message(),
            "calib.txt:1: field 'height': not an integer: '3.5'");
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

TEST(TracksIo, DropsAndCountsObservationsJustPastTheBorder) {
  const std::string h = "frame,landmark,uL,vL,uR,vR\n";
  auto f = TextFile::fromString("tracks.csv", h + "0,1,100,375.4,90,375.3\n"  // 0.4 px below
                                                  "0,2,100,200,90,200\n"
                                                  "1,1,-0.3,20,-1,20\n"        // left of the image
                                                  "1,2,1241.9,20,1230,20\n"    // inside
                                                  "2,3,1242.0,20,1230,20\n");  // at the border
  auto r = parseTracks(f, kTimes, TrackBounds{1242, 375, 2.0});
  ASSERT_TRUE(r) << r.status().toString();
  EXPECT_EQ(r->dropped_past_border, 3u);
  EXPECT_NEAR(r->max_outside_px, 1.0, 1e-12);
  ASSERT_EQ(r->frames[0].observations.size(), 1u);
  EXPECT_EQ(r->frames[0].observations[0].landmark_id, 2);
  ASSERT_EQ(r->frames[1].observations.size(), 1u);
  EXPECT_DOUBLE_EQ(r->frames[1].observations[0].u_left, 1241.9);
  EXPECT_TRUE(r->frames[2].observations.empty());
  // The strict form (and tolerance 0): the same 0.4 px is an error naming the row and field.
  auto strict_form = TextFile::fromString("tracks.csv", h + "0,1,100,375.4,90,375.3\n");
  EXPECT_EQ(parseTracks(strict_form, kTimes, 1242, 375).status().message(),
            "tracks.csv:2: field 'vL': outside the image [0, 375) by more than the 0.000 px "
            "tolerance: 375.4");
  // Tolerance 0: the same 0.4 px is an error naming the row and field.
  auto strict = TextFile::fromString("tracks.csv", h + "0,1,100,375.4,90,375.3\n");
  auto e = parseTracks(strict, kTimes, TrackBounds{1242, 375, 0.0});
  ASSERT_FALSE(e);
  EXPECT_EQ(e.status().message(),
            "tracks.csv:2: field 'vL': outside the image [0, 375) by more than the 0.000 px "
            "tolerance: 375.4");
}

TEST(TracksIo, ImageSizeFromOptionsCalibOrTheTracksExtent) {
  // A 2011_10_03-like rig, 1241x376: a row at v = 375.441 is inside that image.
  const std::string calib = "718.856 718.856 607.1928 185.2157 0.5371";
  const std::string rows = "0,1,100,375.441,90,375.2\n0,2,1240.5,20,1230,20\n2,1,5,6,1,6\n";
  {
    testing::TempDir dir;
    auto seq = readTrackFolder(writeFolder(dir, calib, rows), TrackReadOptions{});
    ASSERT_TRUE(seq) << seq.status().toString();
    EXPECT_EQ(seq->camera.width, 1241);
    EXPECT_EQ(seq->camera.height, 376);
    EXPECT_EQ(seq->image_size_source, "extent of tracks.csv");
    EXPECT_EQ(seq->dropped_past_border, 0u);
    EXPECT_EQ(seq->frames[0].observations.size(), 2u);
  }
  {
    testing::TempDir dir;
    auto seq = readTrackFolder(writeFolder(dir, calib + " 1241 376", rows), TrackReadOptions{});
    ASSERT_TRUE(seq) << seq.status().toString();
    EXPECT_EQ(seq->image_size_source, "calib.txt");
    EXPECT_EQ(seq->camera.height, 376);
    EXPECT_EQ(seq->dropped_past_border, 0u);
  }
  {
    // KITTI's usual 1242x375 by option: the row 0.441 px past the bottom is dropped and counted.
    testing::TempDir dir;
    TrackReadOptions o;
    o.image_width = 1242;
    o.image_height = 375;
    auto seq = readTrackFolder(writeFolder(dir, calib, rows), o);
    ASSERT_TRUE(seq) << seq.status().toString();
    EXPECT_EQ(seq->image_size_source, "the options");
    EXPECT_EQ(seq->dropped_past_border, 1u);
    EXPECT_NEAR(seq->max_outside_px, 0.441, 1e-9);
    EXPECT_EQ(seq->frames[0].observations.size(), 1u);
  }
  {
    // Far outside an image whose size is stated: fails naming file, line and field.
    testing::TempDir dir;
    auto seq = readTrackFolder(writeFolder(dir, calib + " 1241 376", rows + "2,4,10,390,5,390\n"),
                               TrackReadOptions{});
    ASSERT_FALSE(seq);
    EXPECT_EQ(seq.status().message(),
              dir.file("tracks.csv") +
                  ":5: field 'vL': outside the image [0, 376) by more than the 2.000 px "
                  "tolerance: 390");
  }
  {
    // Far outside with the size from the extent: the principal point rules it out.
    testing::TempDir dir;
    auto seq = readTrackFolder(writeFolder(dir, calib, rows + "2,4,100000,20,99990,20\n"),
                               TrackReadOptions{});
    ASSERT_FALSE(seq);
    EXPECT_EQ(seq.status().message(),
              dir.file("tracks.csv") +
                  ":5: field 'uL': 100000.000 is far outside any image whose principal point is "
                  "607.193 px (the size is not stated; state it in calib.txt or the options)");
  }
  TrackReadOptions half;
  half.image_width = 1241;
  EXPECT_FALSE(half.validate().isOk());
  TrackReadOptions tol;
  tol.border_tolerance_px = -1.0;
  EXPECT_FALSE(tol.validate().isOk());
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
  EXPECT_EQ(seq->dropped_past_border, 0u);
  EXPECT_EQ(seq->image_size_source, "extent of tracks.csv");
  EXPECT_EQ(seq->camera.width, 1225);  // the largest u is 1224.469
  EXPECT_NEAR(seq->camera.fu, 707.0912, 1e-9);
  EXPECT_EQ(seq->frames[1].time_ns, 1317384506507502079);
  auto missing = readTrackFolder("/nonexistent/tracks", TrackReadOptions{});
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

// writeTrackFolder and readTrackFolder are inverses (to the 1e-4 px the csv keeps).
TEST(TracksIo, AWrittenFolderReadsBack) {
  sunvo::testing::TempDir dir;
  const StereoCamera camera{721.5377, 721.5377, 609.5593, 172.854, 0.537, 1242, 375};
  std::vector<FrameFeatures> frames(3);
  std::vector<Isometry3> gt(3, Isometry3::Identity());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k].time_ns = 1789035300000000000 + static_cast<TimeNs>(k) * 100000000 + 7;
    frames[k].sequence = 40 + k;  // the folder counts its own frames from 0
    gt[k].translation() = Eigen::Vector3d(0.1 * static_cast<double>(k), 0.0, 1.0 * k);
    for (int i = 0; i < 4; ++i) {
      StereoObservation o;
      o.landmark_id = static_cast<std::int64_t>(k) + i;
      o.u_left = 100.25 + 10 * i;
      o.v_left = 50.5 + i;
      o.u_right = o.u_left - 12.3456;
      o.v_right = o.v_left + 0.0625;
      frames[k].observations.push_back(o);
    }
  }
  frames[1].observations[2].landmark_id = -1;  // no landmark: not written
  frames[2].observations[1].v_right_measured = false;
  ASSERT_TRUE(writeTrackFolder(dir.str(), camera, frames, gt).isOk());
  auto seq = readTrackFolder(dir.str(), TrackReadOptions{});
  ASSERT_TRUE(seq) << seq.status().toString();
  EXPECT_EQ(seq->image_size_source, "calib.txt");
  EXPECT_EQ(seq->camera.width, 1242);
  EXPECT_DOUBLE_EQ(seq->camera.fu, 721.5377);
  ASSERT_EQ(seq->frames.size(), 3u);
  ASSERT_EQ(seq->gt_T_0_k.size(), 3u);
  EXPECT_NEAR((seq->gt_T_0_k[2].translation() - gt[2].translation()).norm(), 0.0, 1e-12);
  EXPECT_EQ(seq->frames[2].time_ns, frames[2].time_ns);  // exact to the nanosecond
  EXPECT_EQ(seq->frames[1].observations.size(), 3u);
  const StereoObservation& o = seq->frames[2].observations[3];
  EXPECT_EQ(o.landmark_id, 5);
  EXPECT_NEAR(o.u_right, frames[2].observations[3].u_right, 1e-4);
  EXPECT_NEAR(o.v_right, frames[2].observations[3].v_right, 1e-4);
  EXPECT_TRUE(o.v_right_measured);
  EXPECT_FALSE(seq->frames[2].observations[1].v_right_measured);
  // The optional column holds 0 or 1 only, and every row has it when the header does.
  sunvo::testing::writeText(dir.file("bad/tracks.csv"),
                            "frame,landmark,uL,vL,uR,vR,vR_measured\n0,1,10,10,5,10,2\n");
  auto bad = TextFile::open(dir.file("bad/tracks.csv"));
  ASSERT_TRUE(bad);
  EXPECT_EQ(parseTracks(*bad, {0}, 1242, 375).status().message(),
            dir.file("bad/tracks.csv") + ":2: field 'vR_measured': must be 0 or 1");
  sunvo::testing::writeText(dir.file("bad/tracks.csv"),
                            "frame,landmark,uL,vL,uR,vR,vR_measured\n0,1,10,10,5,10\n");
  auto short_row = TextFile::open(dir.file("bad/tracks.csv"));
  ASSERT_TRUE(short_row);
  EXPECT_FALSE(parseTracks(*short_row, {0}, 1242, 375));
  // A pose list of the wrong length is refused before anything is written.
  gt.pop_back();
  EXPECT_EQ(writeTrackFolder(dir.str(), camera, frames, gt).message(),
            "writeTrackFolder: 2 ground-truth poses for 3 frames");
}

}  // namespace
}  // namespace sunvo::files
