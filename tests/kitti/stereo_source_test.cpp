#include "sunvo/kitti/stereo_source.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "../support/temp_dir.hpp"
#include "sunvo/kitti/timestamps.hpp"

namespace sunvo::kitti {
namespace {

namespace fs = std::filesystem;

const std::string kOdometry = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";
const std::string kRawDay = std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26";
// An arbitrary, explicit UTC start for the odometry sample (the layout has none of its own).
const TimeNs kOdometryStart = civilToUtcNs(2011, 10, 3, 12, 55, 34, 0);

KittiSourceOptions odometryOptions() {
  KittiSourceOptions o;
  o.root = kOdometry;
  o.odometry_start_time_ns = kOdometryStart;
  return o;
}

TEST(KittiStereoSource, ReadsTheElevenRealOdometryFramesInOrder) {
  auto src = KittiStereoSource::open(odometryOptions());
  ASSERT_TRUE(src) << src.status().toString();
  EXPECT_EQ(src->layout(), KittiLayout::kOdometry);
  EXPECT_EQ(src->frameCount(), 11);
  EXPECT_EQ(src->camera().width, 1241);
  EXPECT_EQ(src->camera().height, 376);
  EXPECT_DOUBLE_EQ(src->camera().fu, 718.856);
  auto rel = readOdometryTimes(kOdometry + "/times.txt", kOdometryStart);
  ASSERT_TRUE(rel);

  StereoFrame frame;
  const unsigned char* left_data = nullptr;
  const unsigned char* right_data = nullptr;
  for (std::uint64_t k = 0; k < 11; ++k) {
    ASSERT_TRUE(src->next(frame)) << k;
    EXPECT_EQ(frame.sequence, k);
    EXPECT_EQ(frame.trigger_time_ns, rel->at(k));
    ASSERT_EQ(frame.left.type(), CV_8UC1);
    ASSERT_EQ(frame.right.type(), CV_8UC1);
    EXPECT_EQ(frame.left.size(), cv::Size(1241, 376));
    EXPECT_TRUE(frame.left_color.empty());
    // Pixels as an independent cv::imread gives them.
    char name[32];
    std::snprintf(name, sizeof(name), "/%06d.png", static_cast<int>(k));
    const cv::Mat ref_l = cv::imread(kOdometry + "/image_0" + name, cv::IMREAD_UNCHANGED);
    const cv::Mat ref_r = cv::imread(kOdometry + "/image_1" + name, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(cv::norm(frame.left, ref_l, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(frame.right, ref_r, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(frame.left, ref_r, cv::NORM_L1), 0.0);  // left and right differ
    // The frame's buffers are reused from the second frame on.
    if (k == 0) {
      left_data = frame.left.data;
      right_data = frame.right.data;
    } else {
      EXPECT_EQ(frame.left.data, left_data);
      EXPECT_EQ(frame.right.data, right_data);
    }
  }
  EXPECT_FALSE(src->finished());
  const Status end = src->next(frame);
  EXPECT_EQ(end.code(), StatusCode::kNotFound);
  EXPECT_EQ(end.message(), "end of sequence");
  EXPECT_TRUE(src->finished());
  EXPECT_TRUE(src->next(frame).code() == StatusCode::kNotFound);
}

TEST(KittiStereoSource, SharedBuffersAreNotOverwritten) {
  auto src = KittiStereoSource::open(odometryOptions());
  ASSERT_TRUE(src);
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));
  const cv::Mat kept = frame.left;  // a shallow copy the caller holds on to
  const cv::Mat kept_copy = frame.left.clone();
  ASSERT_TRUE(src->next(frame));
  EXPECT_NE(frame.left.data, kept.data);
  EXPECT_EQ(cv::norm(kept, kept_copy, cv::NORM_INF), 0.0);
}

TEST(KittiStereoSource, FrameRange) {
  KittiSourceOptions o = odometryOptions();
  o.first_frame = 3;
  o.last_frame = 5;
  auto src = KittiStereoSource::open(o);
  ASSERT_TRUE(src) << src.status().toString();
  StereoFrame frame;
  std::vector<std::uint64_t> seqs;
  while (src->next(frame)) seqs.push_back(frame.sequence);
  EXPECT_TRUE(src->finished());
  EXPECT_EQ(seqs, (std::vector<std::uint64_t>{3, 4, 5}));
  o.last_frame = 11;
  auto bad = KittiStereoSource::open(o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("first_frame/last_frame"), std::string::npos);
}

TEST(KittiStereoSource, OptionsNameTheBadKey) {
  KittiSourceOptions o = odometryOptions();
  o.odometry_start_time_ns.reset();
  auto src = KittiStereoSource::open(o);
  ASSERT_FALSE(src);
  EXPECT_EQ(src.status().message().rfind("odometry_start_time_ns:", 0), 0u);
  o = odometryOptions();
  o.utc_offset_s = 20 * 3600;
  EXPECT_EQ(o.validate().message().rfind("utc_offset_s:", 0), 0u);
  o = odometryOptions();
  o.first_frame = -1;
  EXPECT_EQ(o.validate().message().rfind("first_frame:", 0), 0u);
  o = odometryOptions();
  o.first_frame = 4;
  o.last_frame = 2;
  EXPECT_EQ(o.validate().message().rfind("last_frame:", 0), 0u);
  o = odometryOptions();
  o.root = "";
  EXPECT_EQ(o.validate().message().rfind("root:", 0), 0u);
  o.root = "/nonexistent/sunvo";
  EXPECT_EQ(KittiStereoSource::open(o).status().code(), StatusCode::kNotFound);
  o = odometryOptions();
  o.use_color = true;  // the sample has no image_2/image_3
  src = KittiStereoSource::open(o);
  ASSERT_FALSE(src);
  EXPECT_NE(src.status().message().find("image_2"), std::string::npos);
}

// A raw-layout drive made at test time: the real 2011_09_26 calibration, `frames` frames of
// 1242x375 images whose pixels encode (frame, camera), and the real image timestamps.
class RawDrive {
 public:
  explicit RawDrive(int frames) {
    fs::create_directories(dir_.file("2011_09_26"));
    for (const char* f :
         {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"}) {
      fs::copy_file(kRawDay + "/" + f, dir_.file(std::string("2011_09_26/") + f));
    }
    drive_ = dir_.file("2011_09_26/2011_09_26_drive_0001_sync");
    for (int c = 0; c < 4; ++c) {
      const std::string cam = drive_ + "/image_0" + std::to_string(c);
      fs::create_directories(cam + "/data");
      auto t = readRawTimestamps(
          kRawDay + "/2011_09_26_drive_0001_sync/image_0" + std::to_string(c) + "/timestamps.txt",
          0);
      EXPECT_TRUE(t);
      t->resize(static_cast<std::size_t>(frames));
      EXPECT_TRUE(writeRawTimestamps(cam + "/timestamps.txt", *t, 0));
      if (c == 0) times_ = *t;
      for (int k = 0; k < frames; ++k) writeImage(c, k, cv::Size(1242, 375), c >= 2 ? 3 : 1);
    }
  }
  static int value(int camera, int frame) { return 10 * frame + camera + 1; }
  std::string imagePath(int camera, int frame) const {
    char name[64];
    std::snprintf(name, sizeof(name), "/image_%02d/data/%010d.png", camera, frame);
    return drive_ + name;
  }
  void writeImage(int camera, int frame, cv::Size size, int channels) const {
    cv::Mat img(size, CV_8UC(channels), cv::Scalar::all(value(camera, frame)));
    img.at<unsigned char>(0, 0) = 255;  // not a constant image
    ASSERT_TRUE(cv::imwrite(imagePath(camera, frame), img));
  }
  KittiSourceOptions options(bool color) const {
    KittiSourceOptions o;
    o.root = drive_;
    o.utc_offset_s = 0;
    o.use_color = color;
    return o;
  }
  const std::string& drive() const { return drive_; }
  const std::vector<TimeNs>& times() const { return times_; }

 private:
  testing::TempDir dir_;
  std::string drive_;
  std::vector<TimeNs> times_;
};

TEST(KittiStereoSource, RawLayoutWithColour) {
  RawDrive drive(4);
  auto src = KittiStereoSource::open(drive.options(true));
  ASSERT_TRUE(src) << src.status().toString();
  EXPECT_EQ(src->layout(), KittiLayout::kRaw);
  // Calibration comes from the drive's parent (the date folder), as the raw layout has it.
  EXPECT_EQ(fs::path(src->calibrationDir()).filename(), "2011_09_26");
  EXPECT_DOUBLE_EQ(src->camera().fu, 721.5377);
  ASSERT_TRUE(src->colorCamera().has_value());
  EXPECT_NEAR(src->colorCamera()->baseline_m, 0.5327, 1e-4);
  StereoFrame frame;
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(src->next(frame)) << k;
    EXPECT_EQ(frame.sequence, static_cast<std::uint64_t>(k));
    EXPECT_EQ(frame.trigger_time_ns, drive.times()[static_cast<std::size_t>(k)]);
    ASSERT_EQ(frame.left.type(), CV_8UC1);
    ASSERT_EQ(frame.left_color.type(), CV_8UC3);
    ASSERT_EQ(frame.right_color.type(), CV_8UC3);
    EXPECT_EQ(frame.left.size(), cv::Size(1242, 375));
    EXPECT_EQ(frame.left.at<unsigned char>(10, 10), RawDrive::value(0, k));
    EXPECT_EQ(frame.right.at<unsigned char>(10, 10), RawDrive::value(1, k));
    EXPECT_EQ(frame.left_color.at<cv::Vec3b>(10, 10)[2], RawDrive::value(2, k));
    EXPECT_EQ(frame.right_color.at<cv::Vec3b>(374, 1241)[0], RawDrive::value(3, k));
  }
  EXPECT_FALSE(src->next(frame));
  EXPECT_TRUE(src->finished());
  // Gray only: the colour Mats are emptied.
  auto gray = KittiStereoSource::open(drive.options(false));
  ASSERT_TRUE(gray);
  ASSERT_TRUE(gray->next(frame));
  EXPECT_TRUE(frame.left_color.empty());
  EXPECT_FALSE(gray->colorCamera().has_value());
}

TEST(KittiStereoSource, RawRequiresAnExplicitUtcOffset) {
  RawDrive drive(2);
  KittiSourceOptions o = drive.options(false);
  o.utc_offset_s.reset();
  auto src = KittiStereoSource::open(o);
  ASSERT_FALSE(src);
  EXPECT_EQ(src.status().message().rfind("utc_offset_s:", 0), 0u);
  o.utc_offset_s = 3600;  // recorded in UTC+1: one hour earlier in UTC
  src = KittiStereoSource::open(o);
  ASSERT_TRUE(src);
  EXPECT_EQ(src->frameTimes()[0], drive.times()[0] - 3600 * kNsPerSecond);
}

TEST(KittiStereoSource, MissingImageIsAnErrorNamingFileAndFrame) {
  RawDrive drive(4);
  const std::string missing = drive.imagePath(1, 2);
  fs::remove(missing);
  auto src = KittiStereoSource::open(drive.options(false));
  ASSERT_FALSE(src);
  EXPECT_EQ(src.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(src.status().message(), "frame 2: image file missing: " + missing);

  // Vanishing after open: next() fails on that frame, does not skip it, and is not the end.
  drive.writeImage(1, 2, cv::Size(1242, 375), 1);
  src = KittiStereoSource::open(drive.options(false));
  ASSERT_TRUE(src) << src.status().toString();
  fs::remove(missing);
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));
  ASSERT_TRUE(src->next(frame));
  const Status s = src->next(frame);
  ASSERT_FALSE(s);
  EXPECT_FALSE(src->finished());
  EXPECT_NE(s.message().find("frame 2"), std::string::npos);
  EXPECT_NE(s.message().find(missing), std::string::npos);
  EXPECT_FALSE(src->next(frame));  // still frame 2
  EXPECT_EQ(frame.sequence, 1u);
}

// drop_bad_frames: each kind of bad image drops its frame, the source moves on and counts it.
TEST(KittiStereoSource, DropBadFramesSkipsAndCountsEachBadImage) {
  RawDrive drive(7);
  fs::remove(drive.imagePath(0, 1));      // missing
  fs::resize_file(drive.imagePath(1, 2),  // truncated PNG
                  fs::file_size(drive.imagePath(1, 2)) / 2);
  drive.writeImage(0, 3, cv::Size(640, 480), 1);                // wrong size
  drive.writeImage(1, 4, cv::Size(1242, 375), 3);               // wrong channel count
  ASSERT_FALSE(KittiStereoSource::open(drive.options(false)));  // default: every file needed
  KittiSourceOptions o = drive.options(false);
  o.drop_bad_frames = true;
  auto src = KittiStereoSource::open(o);
  ASSERT_TRUE(src) << src.status().toString();
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));
  EXPECT_EQ(frame.sequence, 0u);
  for (int k = 1; k <= 4; ++k) {
    const Status s = src->next(frame);
    ASSERT_FALSE(s) << k;
    EXPECT_NE(s.message().find("frame " + std::to_string(k) + ": "), std::string::npos)
        << s.message();
    EXPECT_FALSE(src->finished());
    EXPECT_EQ(src->droppedFrames(), k);
  }
  for (std::uint64_t k = 5; k <= 6; ++k) {
    ASSERT_TRUE(src->next(frame)) << k;
    EXPECT_EQ(frame.sequence, k);
    EXPECT_EQ(frame.trigger_time_ns, drive.times()[k]);
    EXPECT_EQ(frame.left.at<unsigned char>(1, 1), RawDrive::value(0, static_cast<int>(k)));
  }
  EXPECT_EQ(src->next(frame).message(), "end of sequence");
  EXPECT_TRUE(src->finished());
  EXPECT_EQ(src->droppedFrames(), 4);

  // Preloaded: the dropped frames keep their place with empty images.
  auto all = loadAllFrames(o);
  ASSERT_TRUE(all) << all.status().toString();
  ASSERT_EQ(all->frames.size(), 7u);
  EXPECT_EQ(all->dropped, 4);
  for (std::size_t k = 0; k < 7; ++k) {
    EXPECT_EQ(all->frames[k].sequence, k);
    EXPECT_EQ(all->frames[k].trigger_time_ns, drive.times()[k]);
    EXPECT_EQ(all->frames[k].left.empty(), k >= 1 && k <= 4) << k;
  }
  // Still no more images than timestamps.
  drive.writeImage(0, 7, cv::Size(1242, 375), 1);  // 7 files again (frame 1 is missing)
  ASSERT_TRUE(KittiStereoSource::open(o));
  drive.writeImage(0, 8, cv::Size(1242, 375), 1);
  src = KittiStereoSource::open(o);
  ASSERT_FALSE(src);
  EXPECT_NE(src.status().message().find("holds 8 PNG images but the timestamps list 7"),
            std::string::npos)
      << src.status().message();
}

TEST(KittiStereoSource, TimestampCountMismatchAndExtraImages) {
  RawDrive drive(4);
  const std::string ts1 = drive.drive() + "/image_01/timestamps.txt";
  auto t = readRawTimestamps(ts1, 0);
  ASSERT_TRUE(t);
  t->pop_back();
  ASSERT_TRUE(writeRawTimestamps(ts1, *t, 0));
  auto src = KittiStereoSource::open(drive.options(false));
  ASSERT_FALSE(src);
  EXPECT_NE(src.status().message().find(ts1 + " has 3 timestamps but"), std::string::npos)
      << src.status().message();
  EXPECT_NE(src.status().message().find("image_00/timestamps.txt has 4"), std::string::npos);

  t->push_back(drive.times().back());
  ASSERT_TRUE(writeRawTimestamps(ts1, *t, 0));
  ASSERT_TRUE(KittiStereoSource::open(drive.options(false)));
  drive.writeImage(0, 4, cv::Size(1242, 375), 1);  // an image without a timestamp
  src = KittiStereoSource::open(drive.options(false));
  ASSERT_FALSE(src);
  EXPECT_NE(src.status().message().find("holds 5 PNG images but the timestamps list 4 frames"),
            std::string::npos)
      << src.status().message();
}

TEST(KittiStereoSource, WrongSizeOrChannelsIsAnError) {
  RawDrive drive(3);
  drive.writeImage(1, 1, cv::Size(640, 480), 1);
  drive.writeImage(0, 2, cv::Size(1242, 375), 3);
  auto src = KittiStereoSource::open(drive.options(false));
  ASSERT_TRUE(src);
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));
  Status s = src->next(frame);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(),
            "frame 1: " + drive.imagePath(1, 1) + ": image is 640x480, calibration says 1242x375");
  // The frame cannot be skipped: it fails again.
  EXPECT_FALSE(src->next(frame));

  KittiSourceOptions o = drive.options(false);
  o.first_frame = 2;
  src = KittiStereoSource::open(o);
  ASSERT_TRUE(src);
  s = src->next(frame);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "frame 2: " + drive.imagePath(0, 2) +
                             ": expected depth 0 with 1 channel(s), got depth 0 with 3 channel(s)");
}

// A fake clock: time moves only when the source sleeps.
class FakeClock final : public PacingClock {
 public:
  TimeNs nowNs() override { return now_; }
  void sleepUntilNs(TimeNs t) override {
    sleeps.push_back(t);
    if (t > now_) now_ = t;
  }
  void advance(TimeNs dt) { now_ += dt; }
  std::vector<TimeNs> sleeps;

 private:
  TimeNs now_ = 5'000'000'000;
};

TEST(KittiStereoSource, RecordedRatePacingWithInjectedClock) {
  RawDrive drive(4);
  auto clock = std::make_shared<FakeClock>();
  KittiSourceOptions o = drive.options(false);
  o.pacing = Pacing::kRecordedRate;
  auto src = KittiStereoSource::open(o, clock);
  ASSERT_TRUE(src);
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));  // the first frame starts the clock, no sleep
  EXPECT_TRUE(clock->sleeps.empty());
  clock->advance(30'000'000);  // the consumer takes 30 ms
  for (int k = 1; k < 4; ++k) ASSERT_TRUE(src->next(frame));
  const auto& t = drive.times();
  ASSERT_EQ(clock->sleeps.size(), 3u);
  for (std::size_t k = 1; k < 4; ++k) {
    EXPECT_EQ(clock->sleeps[k - 1], 5'000'000'000 + (t[k] - t[0])) << k;
  }
  // As fast as possible never sleeps.
  auto fast_clock = std::make_shared<FakeClock>();
  o.pacing = Pacing::kAsFastAsPossible;
  auto fast = KittiStereoSource::open(o, fast_clock);
  ASSERT_TRUE(fast);
  while (fast->next(frame)) {
  }
  EXPECT_TRUE(fast_clock->sleeps.empty());
}

TEST(KittiStereoSource, RecordedRatePacingWithTheSteadyClock) {
  RawDrive drive(3);
  KittiSourceOptions o = drive.options(false);
  o.pacing = Pacing::kRecordedRate;
  auto src = KittiStereoSource::open(o);
  ASSERT_TRUE(src);
  StereoFrame frame;
  ASSERT_TRUE(src->next(frame));
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(src->next(frame));
  ASSERT_TRUE(src->next(frame));
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double recorded_s = toSeconds(drive.times()[2] - drive.times()[0]);  // ~0.206 s
  // At least the recorded interval (minus the first frame's decode, < 50 ms), and not much more.
  EXPECT_GT(elapsed_s, recorded_s - 0.05);
  EXPECT_LT(elapsed_s, recorded_s + 0.5);
}

}  // namespace
}  // namespace sunvo::kitti
