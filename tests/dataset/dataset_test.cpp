#include "sunvo/dataset/dataset.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "../support/temp_dir.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/kitti/oxts.hpp"
#include "sunvo/kitti/timestamps.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::dataset {
namespace {
namespace fs = std::filesystem;
using sunvo::testing::TempDir;
using sunvo::testing::writeText;

const std::string kData = SUNVO_DATA_DIR;
const std::string kRawDay = kData + "/kitti_raw_sample/2011_09_26";
constexpr int kFrames = 3;

// A KITTI raw drive of three frames in a temporary folder: the real calibration of 2011_09_26,
// blank images, the recording's timestamps written in UTC+2 and OXTS records of a car driving
// north at 1 m per frame. Returns the drive folder.
std::string writeRawDrive(const TempDir& dir, const TimeNs t0_utc_ns) {
  const fs::path day = fs::path(dir.str()) / "2011_09_26";
  const fs::path drive = day / "2011_09_26_drive_0099_sync";
  fs::create_directories(drive);
  for (const char* f : {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"}) {
    fs::copy_file(fs::path(kRawDay) / f, day / f);
  }
  std::vector<TimeNs> times;
  for (int k = 0; k < kFrames; ++k) times.push_back(t0_utc_ns + k * 100'000'000LL);
  const cv::Mat gray(375, 1242, CV_8UC1, cv::Scalar(90));
  const cv::Mat colour(375, 1242, CV_8UC3, cv::Scalar(90, 100, 110));
  for (int cam = 0; cam < 4; ++cam) {
    char folder[24];  // room for any int (gcc -O1 checks the whole range)
    std::snprintf(folder, sizeof(folder), "image_%02d", cam);
    fs::create_directories(drive / folder / "data");
    EXPECT_TRUE(
        kitti::writeRawTimestamps((drive / folder / "timestamps.txt").string(), times, 7200));
    for (int k = 0; k < kFrames; ++k) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.png", k);
      cv::imwrite((drive / folder / "data" / name).string(), cam < 2 ? gray : colour);
    }
  }
  fs::create_directories(drive / "oxts" / "data");
  EXPECT_TRUE(kitti::writeRawTimestamps((drive / "oxts" / "timestamps.txt").string(), times, 7200));
  auto first =
      kitti::readOxtsRecord(kitti::oxtsRecordPath(kRawDay + "/2011_09_26_drive_0001_sync", 0));
  EXPECT_TRUE(first);
  for (int k = 0; k < kFrames; ++k) {
    kitti::OxtsRecord r = *first;
    r.lat += k * 1.0 / 111'200.0;  // about 1 m north per frame
    r.yaw = M_PI / 2.0;            // facing north
    r.roll = 0.0;
    r.pitch = 0.0;
    EXPECT_TRUE(kitti::writeOxtsRecord(kitti::oxtsRecordPath(drive.string(), k), r));
  }
  return drive.string();
}

const TimeNs kT0 = civilToUtcNs(2011, 9, 26, 11, 2, 25, 0);  // 13:02:25 in UTC+2

TEST(Dataset, KittiRawDriveWithoutAZoneLoadsWithoutTheSun) {
  TempDir dir;
  const std::string drive = writeRawDrive(dir, kT0);
  DatasetOptions o;
  o.path = drive;
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->kind(), DatasetKind::kKittiRaw);
  EXPECT_EQ(ds->size(), static_cast<std::size_t>(kFrames));
  EXPECT_TRUE(ds->hasImages());
  EXPECT_FALSE(ds->hasFeatures());
  EXPECT_FALSE(ds->utcKnown());
  EXPECT_FALSE(ds->sunKnown());
  EXPECT_TRUE(ds->ephemerisSunWorld().empty());
  EXPECT_NE(ds->sunUnknownReason().find("utc_offset_s"), std::string::npos);
  EXPECT_EQ(ds->world(), WorldFrame::kEnu);
  EXPECT_DOUBLE_EQ(ds->camera().fu, 721.5377);
  ASSERT_TRUE(ds->colorCamera());
  // Ground truth from OXTS: the car moves 1 m north per frame, the camera looks north.
  ASSERT_EQ(ds->groundTruth().size(), static_cast<std::size_t>(kFrames));
  const Eigen::Vector3d step =
      ds->groundTruth()[2].translation() - ds->groundTruth()[1].translation();
  EXPECT_NEAR(step.y(), 1.0, 0.01);
  EXPECT_NEAR(step.x(), 0.0, 0.01);
  const Eigen::Vector3d forward_w = ds->T_w_c0().linear() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(forward_w.y(), 0.99);
  EXPECT_TRUE(ds->T_w_c0().isApprox(ds->groundTruth()[0], 1e-12));
}

TEST(Dataset, KittiRawDriveSunFromTheEphemerisAtEachFix) {
  TempDir dir;
  DatasetOptions o;
  o.path = writeRawDrive(dir, kT0);
  o.utc_offset_s = 7200;
  o.first_frame = 1;
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  ASSERT_TRUE(ds->sunKnown());
  ASSERT_EQ(ds->size(), 2u);
  EXPECT_EQ(ds->timesNs()[0], kT0 + 100'000'000LL);
  EXPECT_EQ(ds->recordingIndex(0), 1);
  // The world's origin is the fix of the range's first frame; the sun there from the SPA.
  sun::SpaOptions spa;
  spa.latitude_deg = ds->origin()->lat_deg;
  spa.longitude_deg = ds->origin()->lon_deg;
  spa.elevation_m = ds->origin()->alt_m;
  auto sp = sun::computeSolarPosition(ds->timesNs()[0], spa);
  ASSERT_TRUE(sp);
  EXPECT_LT((ds->trueSun()[0].sun_w - sp->sun_enu).norm(), 1e-9);
  EXPECT_GT(sp->sun_enu.z(), 0.5);  // late morning in Karlsruhe in September
  ASSERT_EQ(ds->ephemerisSunWorld().size(), ds->size());
  EXPECT_LT((ds->ephemerisSunWorld()[1] - ds->trueSun()[1].sun_w).norm(), 1e-15);
  for (std::size_t k = 0; k < ds->size(); ++k) {
    const Eigen::Vector3d back = ds->groundTruth()[k].linear() * ds->trueSun()[k].sun_c;
    EXPECT_LT((back - ds->trueSun()[k].sun_w).norm(), 1e-12);
  }
}

TEST(Dataset, RenderGroundTruthAndSunFromItsGtFolder) {
  TempDir dir;
  const std::string drive = writeRawDrive(dir, kT0);
  DatasetOptions o;
  o.path = drive;
  o.utc_offset_s = 7200;
  auto raw = Dataset::open(o);
  ASSERT_TRUE(raw);
  // gt/ in the ENU frame of the first fix (the scene's origin = the world's), a sun file.
  files::Trajectory gt;
  std::string sun = "frame,sx,sy,sz\n";
  for (int k = 0; k < kFrames; ++k) {
    gt.T_w_c.push_back(raw->groundTruth()[static_cast<std::size_t>(k)]);
    gt.t_ns.push_back(0);
    const Eigen::Vector3d s = raw->trueSun()[static_cast<std::size_t>(k)].sun_c;
    char line[128];
    std::snprintf(line, sizeof(line), "%d,%.12f,%.12f,%.12f\n", k, s.x(), s.y(), s.z());
    sun += line;
  }
  fs::create_directories(drive + "/gt");
  ASSERT_TRUE(files::writeKittiPoses(drive + "/gt/poses_cam0_enu.txt", gt));
  char origin[128];
  std::snprintf(origin, sizeof(origin), "%.12f %.12f %.6f\n", raw->origin()->lat_deg,
                raw->origin()->lon_deg, raw->origin()->alt_m);
  writeText(drive + "/gt/origin.txt", origin);
  writeText(drive + "/gt/sun_cam0.csv", sun);

  DatasetOptions r;
  r.path = fs::path(drive).parent_path().parent_path().string();  // sunvo_render's output folder
  auto ds = Dataset::open(r);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->kind(), DatasetKind::kSunvoRender);
  EXPECT_TRUE(ds->utcKnown());  // a render writes UTC: offset 0 unless stated
  ASSERT_TRUE(ds->sunKnown());
  EXPECT_EQ(ds->ephemerisSunWorld().size(), ds->size());
  for (std::size_t k = 0; k < ds->size(); ++k) {
    EXPECT_LT((ds->groundTruth()[k].translation() - raw->groundTruth()[k].translation()).norm(),
              1e-6);
    EXPECT_LT((ds->trueSun()[k].sun_c - raw->trueSun()[k].sun_c).norm(), 1e-9);
  }
}

TEST(Dataset, BadRawDrivesFailAtOpenNamingTheFile) {
  TempDir dir;
  const std::string drive = writeRawDrive(dir, kT0);
  DatasetOptions o;
  o.path = drive;
  fs::remove(kitti::oxtsRecordPath(drive, 1));
  auto missing_oxts = Dataset::open(o);
  ASSERT_FALSE(missing_oxts);
  EXPECT_NE(missing_oxts.status().message().find("0000000001.txt"), std::string::npos)
      << missing_oxts.status().toString();

  TempDir dir2;
  o.path = writeRawDrive(dir2, kT0);
  fs::remove(o.path + "/image_01/data/0000000002.png");
  auto missing_image = Dataset::open(o);
  ASSERT_FALSE(missing_image);
  EXPECT_NE(missing_image.status().message().find("0000000002.png"), std::string::npos)
      << missing_image.status().toString();

  TempDir dir3;
  o.path = writeRawDrive(dir3, kT0);
  writeText(dir3.str() + "/2011_09_26/calib_cam_to_cam.txt", "P_rect_00: 1 2 3\n");
  auto bad_calib = Dataset::open(o);
  ASSERT_FALSE(bad_calib);
  EXPECT_NE(bad_calib.status().message().find("calib_cam_to_cam.txt"), std::string::npos)
      << bad_calib.status().toString();

  o.utc_offset_s = 100'000;
  EXPECT_EQ(Dataset::open(o).status().code(), StatusCode::kInvalidArgument);
  DatasetOptions none;
  none.path = dir3.str() + "/nothing_here";
  EXPECT_EQ(Dataset::open(none).status().code(), StatusCode::kNotFound);
}

TEST(Dataset, RealTrackFolderWithTheSunOfSequence06) {
  DatasetOptions o;
  o.path = kData + "/kitti_tracks/2011_09_30_drive_0020";
  o.sun_csv = kData + "/kitti_odometry/06_sun_cam.csv";
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->kind(), DatasetKind::kTrackFolder);
  EXPECT_EQ(ds->size(), 1000u);
  ASSERT_TRUE(ds->hasFeatures());
  EXPECT_EQ(ds->features().size(), 1000u);
  EXPECT_FALSE(ds->hasImages());
  EXPECT_EQ(ds->world(), WorldFrame::kFirstCamera);
  ASSERT_TRUE(ds->sunKnown());
  // The data README: the true sun rotated into frame 0 by the ground truth stays within ~1 deg.
  for (const TrueSun& s : ds->trueSun()) {
    EXPECT_LT(std::acos(std::min(1.0, s.sun_w.dot(ds->trueSun()[0].sun_w))), 2.0 * M_PI / 180.0);
  }
}

TEST(Dataset, TrajectoryRoutesFromKittiOdometryPrefixes) {
  DatasetOptions o;
  o.path = kData + "/kitti_odometry/00";
  auto r00 = Dataset::open(o);
  ASSERT_TRUE(r00) << r00.status().toString();
  EXPECT_EQ(r00->kind(), DatasetKind::kTrajectory);
  EXPECT_EQ(r00->size(), 4541u);
  EXPECT_EQ(r00->camera().width, 1241);  // 00_first_frames/calib.txt, KITTI's 2011_10_03 rig
  EXPECT_DOUBLE_EQ(r00->camera().fu, 718.856);
  EXPECT_TRUE(r00->sunKnown());
  EXPECT_FALSE(r00->hasImages());
  EXPECT_FALSE(r00->hasFeatures());

  o.path = kData + "/kitti_odometry/06";
  o.first_frame = 100;
  o.last_frame = 199;
  auto r06 = Dataset::open(o);
  ASSERT_TRUE(r06) << r06.status().toString();
  EXPECT_EQ(r06->size(), 100u);
  EXPECT_EQ(r06->camera().width, 1226);  // no calibration file: the rig of sequence 06
  EXPECT_NEAR(r06->camera().baseline_m, 0.537150653, 1e-8);
  EXPECT_TRUE(r06->T_w_c0().isApprox(r06->groundTruth()[0]));

  o.last_frame = 5000;
  auto past = Dataset::open(o);
  ASSERT_FALSE(past);
  EXPECT_NE(past.status().message().find("dataset.last_frame"), std::string::npos);
}

TEST(Dataset, RealOdometryFramesFindTheirSequenceFiles) {
  DatasetOptions o;
  o.path = kData + "/kitti_odometry/00_first_frames";
  auto ds = Dataset::open(o);
  ASSERT_TRUE(ds) << ds.status().toString();
  EXPECT_EQ(ds->kind(), DatasetKind::kKittiOdometry);
  EXPECT_EQ(ds->size(), 11u);
  EXPECT_TRUE(ds->hasImages());
  EXPECT_FALSE(ds->utcKnown());
  ASSERT_EQ(ds->groundTruth().size(), 11u);  // ../00_gt_poses.txt, cut to the frames
  EXPECT_TRUE(ds->sunKnown());               // ../00_sun_cam.csv
  const kitti::KittiSourceOptions so = ds->imageSourceOptions();
  EXPECT_EQ(so.layout, kitti::KittiLayout::kOdometry);
  EXPECT_EQ(so.last_frame, 10);
}

}  // namespace
}  // namespace sunvo::dataset
