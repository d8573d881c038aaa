#include "sunvo/dataset/kitti_rigs.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "sunvo/files/text_file.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/kitti/calibration.hpp"

namespace sunvo::dataset {
namespace {

const std::string kData = SUNVO_DATA_DIR;

void expectSame(const StereoCamera& a, const StereoCamera& b) {
  EXPECT_NEAR(a.fu, b.fu, 1e-9);
  EXPECT_NEAR(a.fv, b.fv, 1e-9);
  EXPECT_NEAR(a.cu, b.cu, 1e-9);
  EXPECT_NEAR(a.cv, b.cv, 1e-9);
  EXPECT_NEAR(a.baseline_m, b.baseline_m, 1e-8);
}

// Each rig against KITTI's own files for that recording day.
TEST(KittiRigs, Rig20111003MatchesSequence00Calibration) {
  auto calib = kitti::readOdometryCalibration(kData + "/kitti_odometry/00_first_frames/calib.txt");
  ASSERT_TRUE(calib);
  auto cam = kitti::odometryStereoCamera(*calib, 0, 1, 1241, 376);
  ASSERT_TRUE(cam);
  for (const char* seq : {"00", "01", "02", "0", "2"}) {
    const auto rig = kittiOdometryRig(seq);
    ASSERT_TRUE(rig) << seq;
    expectSame(rig->camera(), *cam);
    EXPECT_EQ(rig->width, 1241);
    EXPECT_EQ(rig->height, 376);
  }
}

TEST(KittiRigs, Rig20110930MatchesTheDrive0020Tracks) {
  auto file = files::TextFile::open(kData + "/kitti_tracks/2011_09_30_drive_0020/calib.txt");
  ASSERT_TRUE(file);
  auto cam = files::parseTrackCalib(*file, 1226, 370);
  ASSERT_TRUE(cam);
  for (const char* seq : {"04", "05", "06", "10"}) {
    const auto rig = kittiOdometryRig(seq);
    ASSERT_TRUE(rig) << seq;
    expectSame(rig->camera(), *cam);
    EXPECT_STREQ(rig->date, "2011_09_30");
  }
}

TEST(KittiRigs, Rig20110926MatchesTheRawSampleCalibration) {
  auto calib = kitti::readCamToCam(kData + "/kitti_raw_sample/2011_09_26/calib_cam_to_cam.txt");
  ASSERT_TRUE(calib);
  auto cam = kitti::rawStereoCamera(*calib, 0, 1);
  ASSERT_TRUE(cam);
  const auto rig = kittiOdometryRig("03");
  ASSERT_TRUE(rig);
  expectSame(rig->camera(), *cam);
  EXPECT_EQ(rig->width, cam->width);
  EXPECT_EQ(rig->height, cam->height);
}

TEST(KittiRigs, SequencesNameTheirRawDrives) {
  EXPECT_EQ(kittiOdometryDrive("00"), "2011_10_03_drive_0027");
  EXPECT_EQ(kittiOdometryDrive("05"), "2011_09_30_drive_0018");
  EXPECT_EQ(kittiOdometryDrive("06"), "2011_09_30_drive_0020");
  // Each drive was recorded on its rig's day.
  for (int n = 0; n <= 10; ++n) {
    char seq[16];  // room for any int (gcc -O1 checks the whole range)
    std::snprintf(seq, sizeof(seq), "%02d", n);
    EXPECT_EQ(kittiOdometryDrive(seq)->substr(0, 10), kittiOdometryRig(seq)->date) << seq;
  }
  EXPECT_FALSE(kittiOdometryDrive("11"));
}

TEST(KittiRigs, UnknownSequencesHaveNoRig) {
  for (const char* seq : {"", "11", "21", "x", "005", "-1"})
    EXPECT_FALSE(kittiOdometryRig(seq)) << seq;
}

}  // namespace
}  // namespace sunvo::dataset
