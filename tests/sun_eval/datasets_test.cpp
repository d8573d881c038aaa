// The image sets sunvo_sun_eval reads (hil/tools/sun_eval/src/datasets.hpp): DIR:CSV, and a
// KITTI odometry folder with a sun file but no poses.

#include "datasets.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace {
namespace fs = std::filesystem;
using sunvo::suneval::CameraChoice;
using sunvo::suneval::EvalSetOptions;
using sunvo::suneval::loadEvalDataset;
using sunvo::suneval::parseSetSpec;
const std::string kOdometry = std::string(SUNVO_DATA_DIR) + "/kitti_odometry";
const std::string kFrames = kOdometry + "/00_first_frames";

TEST(SunEvalDatasets, ParsesDirAndDirColonCsv) {
  EXPECT_EQ(parseSetSpec("/a/b").dir, "/a/b");
  EXPECT_EQ(parseSetSpec("/a/b").sun_csv, "");
  EXPECT_EQ(parseSetSpec("/a/b:/c/sun.csv").dir, "/a/b");
  EXPECT_EQ(parseSetSpec("/a/b:/c/sun.csv").sun_csv, "/c/sun.csv");
  EXPECT_EQ(parseSetSpec("/a/b:").dir, "/a/b:");  // nothing after the colon: no CSV
  EXPECT_EQ(parseSetSpec(kFrames).sun_csv, "");
}

TEST(SunEvalDatasets, AnExplicitSunFileGivesTheSameSunAsTheFoundOne) {
  auto found = loadEvalDataset(kFrames);
  EvalSetOptions o;
  o.sun_csv = kOdometry + "/00_sun_cam.csv";
  auto given = loadEvalDataset(kFrames, o);
  ASSERT_TRUE(found) << found.status().toString();
  ASSERT_TRUE(given) << given.status().toString();
  ASSERT_EQ(found->frames.size(), 11u);
  ASSERT_EQ(given->frames.size(), 11u);
  for (std::size_t k = 0; k < 11; ++k) {
    EXPECT_LT((found->frames[k].true_sun_c - given->frames[k].true_sun_c).norm(), 1e-12);
  }
  EXPECT_EQ(found->name, "00_first_frames");
}

TEST(SunEvalDatasets, TheCameraChoice) {
  // The real frames are gray only: auto and gray give camera 0, color is an error naming the set.
  for (CameraChoice c : {CameraChoice::kAuto, CameraChoice::kGray}) {
    EvalSetOptions o;
    o.camera = c;
    auto ds = loadEvalDataset(kFrames, o);
    ASSERT_TRUE(ds) << ds.status().toString();
    EXPECT_FALSE(ds->color);
    EXPECT_NE(ds->frames[0].image_path.find("image_0/"), std::string::npos);
  }
  EvalSetOptions o;
  o.camera = CameraChoice::kColor;
  auto ds = loadEvalDataset(kFrames, o);
  ASSERT_FALSE(ds);
  EXPECT_NE(ds.status().message().find("00_first_frames: no colour camera"), std::string::npos)
      << ds.status().message();
}

TEST(SunEvalDatasets, ASunFileWithoutPosesTakesTheRigAsLevel) {
  // A copy of the frames alone (no poses, no sun file next to it).
  const fs::path dir = fs::path(SUNVO_BINARY_DIR) /
                       ("sun_eval_datasets_test_" + std::to_string(::getpid())) / "frames";
  fs::remove_all(dir.parent_path());
  fs::create_directories(dir);
  fs::copy(kFrames, dir, fs::copy_options::recursive);
  EvalSetOptions o;
  o.max_frames = 3;
  EXPECT_FALSE(loadEvalDataset(dir.string(), o));  // no sun: an error
  o.sun_csv = kOdometry + "/00_sun_cam.csv";
  auto ds = loadEvalDataset(dir.string(), o);
  ASSERT_TRUE(ds) << ds.status().toString();
  ASSERT_EQ(ds->frames.size(), 3u);
  EXPECT_TRUE(ds->level_assumed);
  EXPECT_EQ(ds->frames[2].true_up_c, Eigen::Vector3d(0.0, -1.0, 0.0));
  // Row 2 of 00_sun_cam.csv.
  EXPECT_LT(
      (ds->frames[2].true_sun_c - Eigen::Vector3d(0.23384, -0.57352, -0.78511).normalized()).norm(),
      1e-9);
  // A sun file with fewer rows than frames: an error naming it.
  const fs::path short_csv = dir.parent_path() / "short.csv";
  std::ofstream(short_csv) << "frame,sx,sy,sz\n0,0.23639,-0.57199,-0.78546\n";
  o.sun_csv = short_csv.string();
  auto bad = loadEvalDataset(dir.string(), o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("short.csv"), std::string::npos) << bad.status().message();
  if (!::testing::Test::HasFailure()) fs::remove_all(dir.parent_path());
}

}  // namespace
