#include "sunvo/dataset/track_folder.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "../support/temp_dir.hpp"
#include "sunvo/dataset/dataset.hpp"

namespace sunvo::dataset {
namespace {
namespace fs = std::filesystem;
using sunvo::testing::TempDir;
using sunvo::testing::writeText;

const std::string kData = SUNVO_DATA_DIR;

// A synthetic track folder of the 2011_10_03 rig (1241x376, calib.txt without a size) under
// `parent`, with a row at v = 375.441 (inside a 376-row image, 0.441 px past a 375-row one) and
// one at u = 1240.6; `extra` rows follow. Returns the folder.
std::string writeTracks(const fs::path& parent, const std::string& name,
                        const std::string& extra = "") {
  const fs::path dir = parent / name;
  writeText((dir / "calib.txt").string(), "718.856 718.856 607.1928 185.2157 0.537166\n");
  writeText((dir / "times.txt").string(), "1317646000.0\n1317646000.1\n1317646000.2\n");
  writeText((dir / "gt_poses.txt").string(),
            "1 0 0 0 0 1 0 0 0 0 1 0\n"
            "1 0 0 0 0 1 0 0 0 0 1 0.8\n"
            "1 0 0 0 0 1 0 0 0 0 1 1.6\n");
  writeText((dir / "tracks.csv").string(),
            "frame,landmark,uL,vL,uR,vR\n"
            "0,1,100.0,375.441,90.0,375.3\n"
            "0,2,1240.6,20.0,1230.0,20.1\n"
            "1,1,101.0,370.0,91.0,370.0\n"
            "2,2,600.0,180.0,580.0,180.0\n" +
                extra);
  return dir.string();
}

TEST(TrackFolder, A2011_10_03FolderLoadsWithItsRigSize) {
  TempDir tmp;
  DatasetOptions o;
  o.path = writeTracks(tmp.str(), "2011_10_03_drive_0042_sync");
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->kind(), DatasetKind::kTrackFolder);
  EXPECT_EQ(ds->camera().width, 1241);
  EXPECT_EQ(ds->camera().height, 376);
  EXPECT_EQ(ds->imageSizeSource(), "the KITTI 2011_10_03 rig");
  EXPECT_EQ(ds->droppedPastBorder(), 0u);
  EXPECT_EQ(ds->features()[0].observations.size(), 2u);
  EXPECT_NE(ds->describe().find("0 observations dropped past the border"), std::string::npos);
  // The folder's name also when it is given as "<folder>/." or with a trailing '/'.
  for (const std::string& spelling : {o.path + "/.", o.path + "/"}) {
    auto seq = dataset::readTrackFolder(spelling, files::TrackReadOptions{});
    ASSERT_TRUE(seq) << spelling << ": " << seq.status().toString();
    EXPECT_EQ(seq->image_size_source, "the KITTI 2011_10_03 rig") << spelling;
  }
}

TEST(TrackFolder, KittiCamToCamSizeDropsAndCountsTheRowJustPastTheBorder) {
  // calib_cam_to_cam.txt of 2011_09_26 (S_rect_00 1242x375) in the parent, as in KITTI raw.
  TempDir tmp;
  fs::copy_file(kData + "/kitti_raw_sample/2011_09_26/calib_cam_to_cam.txt",
                tmp.file("calib_cam_to_cam.txt"));
  const std::string folder = writeTracks(tmp.str(), "my_route");
  auto seq = dataset::readTrackFolder(folder, files::TrackReadOptions{});
  ASSERT_TRUE(seq) << seq.status().toString();
  EXPECT_EQ(seq->camera.width, 1242);
  EXPECT_EQ(seq->camera.height, 375);
  EXPECT_EQ(seq->image_size_source, tmp.file("calib_cam_to_cam.txt") + " S_rect_00");
  EXPECT_EQ(seq->dropped_past_border, 1u);
  EXPECT_NEAR(seq->max_outside_px, 0.441, 1e-9);
  EXPECT_EQ(seq->frames[0].observations.size(), 1u);

  // Through the dataset seam, the count is reported too.
  DatasetOptions o;
  o.path = folder;
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->droppedPastBorder(), 1u);
  EXPECT_NE(ds->describe().find("1 observations dropped past the border"), std::string::npos);
}

TEST(TrackFolder, OptionsWinAndTheExtentIsTheLastResort) {
  TempDir tmp;
  DatasetOptions o;
  o.path = writeTracks(tmp.str(), "2011_10_03_drive_0042_sync");
  o.image_width = 1300;
  o.image_height = 400;
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->camera().width, 1300);
  EXPECT_EQ(ds->imageSizeSource(), "the options");
  o.image_height = 0;
  EXPECT_EQ(Dataset::open(o).status().code(), StatusCode::kInvalidArgument);

  // A name that is no KITTI day and no calibration beside it: the tracks' extent.
  auto seq = dataset::readTrackFolder(writeTracks(tmp.str(), "route_b"), files::TrackReadOptions{});
  ASSERT_TRUE(seq) << seq.status().toString();
  EXPECT_EQ(seq->camera.width, 1241);
  EXPECT_EQ(seq->camera.height, 376);
  EXPECT_EQ(seq->image_size_source, "extent of tracks.csv");
}

TEST(TrackFolder, FarOutsideStillFailsNamingFileLineAndField) {
  TempDir tmp;
  const std::string folder =
      writeTracks(tmp.str(), "2011_10_03_drive_0042_sync", "2,3,700.0,381.5,690.0,381.0\n");
  DatasetOptions o;
  o.path = folder;
  auto ds = Dataset::open(o);
  ASSERT_FALSE(ds);
  EXPECT_EQ(ds.status().code(), StatusCode::kParseError);
  EXPECT_EQ(ds.status().message(),
            folder +
                "/tracks.csv:6: field 'vL': outside the image [0, 376) by more than the "
                "2.000 px tolerance: 381.5");
  // A malformed line as well.
  const std::string bad = writeTracks(tmp.str(), "2011_10_03_drive_0043_sync", "2,3,7x,1,2,3\n");
  o.path = bad;
  EXPECT_EQ(Dataset::open(o).status().message(),
            bad + "/tracks.csv:6: field 'uL': not a number: '7x'");
}

TEST(TrackFolder, TheReal0020TracksFitThe2011_09_30Rig) {
  auto seq = dataset::readTrackFolder(kData + "/kitti_tracks/2011_09_30_drive_0020",
                                      files::TrackReadOptions{});
  ASSERT_TRUE(seq) << seq.status().toString();
  EXPECT_EQ(seq->image_size_source, "the KITTI 2011_09_30 rig");
  EXPECT_EQ(seq->camera.width, 1226);
  EXPECT_EQ(seq->camera.height, 370);
  EXPECT_EQ(seq->dropped_past_border, 0u);
}

}  // namespace
}  // namespace sunvo::dataset
