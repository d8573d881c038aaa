// V4l2StereoSource against the emulated V4L2 devices: formats and conversion, pairing, every fault
// path with its counter, reopen with backoff, resource release, allocations per frame.

#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include <chrono>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#include "sunvo/sysio/sysio.hpp"
#endif

namespace sunvo::v4l2 {
namespace {

using emulated::EmulatedCameraConfig;
using emulated::EmulatedV4l2;

constexpr int kW = 64;  // per eye, px
constexpr int kH = 32;
constexpr TimeNs kPeriod = 100'000'000;            // 10 Hz
constexpr TimeNs kT0 = 1'700'000'000'000'000'000;  // a trigger time, ns (whole microseconds)
const std::string kLeft = "/dev/video0";
const std::string kRight = "/dev/video1";

std::vector<cv::Mat> randomImages(int n, int w, int h, int seed) {
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  std::vector<cv::Mat> images;
  for (int i = 0; i < n; ++i) {
    cv::Mat m(h, w, CV_8UC1);
    rng.fill(m, cv::RNG::UNIFORM, 0, 256);
    images.push_back(m);
  }
  return images;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

V4l2Options fastOptions(V4l2Layout layout, V4l2PixelFormat format) {
  V4l2Options o;
  o.layout = layout;
  o.left_device = kLeft;
  o.right_device = kRight;
  o.pixel_format = format;
  o.width = kW;
  o.height = kH;
  o.buffer_count = 4;
  o.dequeue_timeout_ms = 30;
  o.reopen_after_timeouts = 0;
  o.reopen_backoff_initial_ms = 10;
  o.reopen_backoff_max_ms = 40;
  o.max_pair_skew_ns = 1'000'000;
  return o;
}

// Two cameras (or one side-by-side camera) serving known random images.
struct Rig {
  EmulatedV4l2 emu;
  std::vector<cv::Mat> left_images = randomImages(5, kW, kH, 1);
  std::vector<cv::Mat> right_images = randomImages(5, kW, kH, 2);
  std::vector<cv::Mat> sbs_images;

  explicit Rig(V4l2Layout layout, int line_padding = 0) {
    if (layout == V4l2Layout::kTwoDevices) {
      EXPECT_TRUE(emu.addCamera({kLeft, kW, kH, true, true, line_padding, 0,
                                 emulated::imageSequence(left_images)})
                      .isOk());
      EXPECT_TRUE(emu.addCamera({kRight, kW, kH, true, true, line_padding, 0,
                                 emulated::imageSequence(right_images)})
                      .isOk());
    } else {
      for (std::size_t i = 0; i < left_images.size(); ++i) {
        cv::Mat both;
        cv::hconcat(left_images[i], right_images[i], both);
        sbs_images.push_back(both);
      }
      EXPECT_TRUE(emu.addCamera({kLeft, 2 * kW, kH, true, true, line_padding, 0,
                                 emulated::imageSequence(sbs_images)})
                      .isOk());
    }
  }
  // The images of trigger number k.
  const cv::Mat& left(std::uint64_t k) const { return left_images[k % left_images.size()]; }
  const cv::Mat& right(std::uint64_t k) const { return right_images[k % right_images.size()]; }
};

std::unique_ptr<V4l2StereoSource> openOrFail(const V4l2Options& o, sysio::SysIo& io) {
  auto s = V4l2StereoSource::open(o, io);
  EXPECT_TRUE(s.hasValue()) << s.status().toString();
  return s.hasValue() ? std::move(s).value() : nullptr;
}

TEST(V4l2Options, DefaultsAreValidAndBadKeysAreNamed) {
  EXPECT_TRUE(V4l2Options{}.validate().isOk());
  auto bad = [](auto change) {
    V4l2Options o;
    change(o);
    return o.validate().message();
  };
  EXPECT_NE(bad([](V4l2Options& o) { o.width = 8; }).find("v4l2.width"), std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.height = 9000; }).find("v4l2.height"), std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) {
              o.pixel_format = V4l2PixelFormat::kYuyv;
              o.width = 641;
            }).find("v4l2.width"),
            std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.fps = 0.0; }).find("v4l2.fps"), std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.buffer_count = 1; }).find("v4l2.buffer_count"),
            std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.dequeue_timeout_ms = 0; }).find("dequeue_timeout_ms"),
            std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) {
              o.reopen_backoff_initial_ms = 100;
              o.reopen_backoff_max_ms = 50;
            }).find("v4l2.reopen_backoff_max_ms"),
            std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.max_pair_skew_ns = -1; }).find("max_pair_skew_ns"),
            std::string::npos);
  EXPECT_NE(bad([](V4l2Options& o) { o.right_device = o.left_device; }).find("v4l2.right_device"),
            std::string::npos);
  V4l2Options sbs;
  sbs.layout = V4l2Layout::kSideBySide;
  sbs.right_device = sbs.left_device;  // unused in this layout
  EXPECT_TRUE(sbs.validate().isOk());
}

TEST(V4l2StereoSource, OpenFailsNamingTheDeviceAndStep) {
  EmulatedV4l2 emu;
  ASSERT_TRUE(emu.addCamera({kLeft, kW, kH, true, true, 0, 0, {}}).isOk());
  auto missing =
      V4l2StereoSource::open(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey), emu);
  ASSERT_FALSE(missing.hasValue());
  EXPECT_EQ(missing.status().code(), StatusCode::kDeviceError);
  EXPECT_NE(missing.status().message().find(kRight + ": open"), std::string::npos)
      << missing.status().message();
  // The left device that did open was released again.
  EXPECT_EQ(emu.openFds(), 0);
  EXPECT_EQ(emu.liveMappings(), 0);
}

TEST(V4l2StereoSource, FormatTheDeviceCannotGiveIsAnErrorNamingBoth) {
  EmulatedV4l2 emu;
  ASSERT_TRUE(emu.addCamera({kLeft, 2 * kW + 2, kH, true, false, 0, 0, {}}).isOk());
  V4l2Options o = fastOptions(V4l2Layout::kSideBySide, V4l2PixelFormat::kGrey);
  auto wrong_size = V4l2StereoSource::open(o, emu);
  ASSERT_FALSE(wrong_size.hasValue());
  EXPECT_NE(wrong_size.status().message().find("VIDIOC_S_FMT asked 128x32 GREY, the device set "
                                               "130x32 GREY"),
            std::string::npos)
      << wrong_size.status().message();

  EmulatedV4l2 grey_only;
  ASSERT_TRUE(grey_only.addCamera({kLeft, 2 * kW, kH, true, false, 0, 0, {}}).isOk());
  o.pixel_format = V4l2PixelFormat::kYuyv;
  auto wrong_format = V4l2StereoSource::open(o, grey_only);
  ASSERT_FALSE(wrong_format.hasValue());
  EXPECT_NE(wrong_format.status().message().find("asked 128x32 YUYV"), std::string::npos)
      << wrong_format.status().message();
  EXPECT_EQ(grey_only.openFds(), 0);
}

// Every layout and format delivers the exact images, with the driver's sequence and timestamp.
struct FormatCase {
  V4l2Layout layout;
  V4l2PixelFormat format;
  int line_padding;
};

class V4l2Formats : public ::testing::TestWithParam<FormatCase> {};

TEST_P(V4l2Formats, DeliversTheExactImages) {
  const FormatCase c = GetParam();
  Rig rig(c.layout, c.line_padding);
  auto source = openOrFail(fastOptions(c.layout, c.format), rig.emu);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(rig.emu.pixelFormat(kLeft),
            c.format == V4l2PixelFormat::kGrey ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_YUYV);
  StereoFrame frame;
  for (std::uint64_t k = 0; k < 7; ++k) {
    const TimeNs t = kT0 + static_cast<TimeNs>(k) * kPeriod;
    rig.emu.trigger(t);
    ASSERT_TRUE(source->next(frame).isOk());
    EXPECT_TRUE(sameImage(frame.left, rig.left(k))) << "frame " << k;
    EXPECT_TRUE(sameImage(frame.right, rig.right(k))) << "frame " << k;
    EXPECT_EQ(frame.sequence, k);
    EXPECT_EQ(frame.trigger_time_ns, t);
    EXPECT_EQ(source->lastPair().left_time_ns, t);
    EXPECT_EQ(source->lastPair().right_time_ns, t);
  }
  EXPECT_EQ(source->counters().frames, 7u);
  EXPECT_EQ(source->counters().pairing_drops, 0u);
  EXPECT_EQ(source->counters().sequence_gaps, 0u);
}

INSTANTIATE_TEST_SUITE_P(
    All, V4l2Formats,
    ::testing::Values(FormatCase{V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey, 0},
                      FormatCase{V4l2Layout::kTwoDevices, V4l2PixelFormat::kYuyv, 0},
                      FormatCase{V4l2Layout::kSideBySide, V4l2PixelFormat::kGrey, 0},
                      FormatCase{V4l2Layout::kSideBySide, V4l2PixelFormat::kYuyv, 0},
                      FormatCase{V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey, 24},
                      FormatCase{V4l2Layout::kSideBySide, V4l2PixelFormat::kYuyv, 12}));

TEST(V4l2StereoSource, YuyvConversionKeepsLumaAndIgnoresChroma) {
  // Every luma value 0..255 in every position, against chroma that varies per pixel pair.
  cv::Mat ramp(kH, kW, CV_8UC1);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x)
      ramp.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(y * kW + x);
  }
  cv::Mat inverted = 255 - ramp;
  EmulatedV4l2 emu;
  ASSERT_TRUE(
      emu.addCamera({kLeft, kW, kH, false, true, 0, 0, emulated::imageSequence({ramp})}).isOk());
  ASSERT_TRUE(
      emu.addCamera({kRight, kW, kH, false, true, 0, 0, emulated::imageSequence({inverted})})
          .isOk());
  auto source = openOrFail(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kYuyv), emu);
  ASSERT_NE(source, nullptr);
  emu.trigger(kT0);
  StereoFrame frame;
  ASSERT_TRUE(source->next(frame).isOk());
  EXPECT_TRUE(sameImage(frame.left, ramp));
  EXPECT_TRUE(sameImage(frame.right, inverted));
}

// left_color: the left eye in BGR through cv::cvtColor(COLOR_YUV2BGR_YUYV) of the bytes the
// camera sent (rebuilt here from the grey image and the emulator's chroma), in both layouts and
// with line padding; the grey eyes stay the luma.
TEST(V4l2StereoSource, YuyvLeftColourIsOpenCvsConversion) {
  for (const V4l2Layout layout : {V4l2Layout::kTwoDevices, V4l2Layout::kSideBySide}) {
    Rig rig(layout, /*line_padding=*/6);
    V4l2Options o = fastOptions(layout, V4l2PixelFormat::kYuyv);
    o.left_color = true;
    auto source = openOrFail(o, rig.emu);
    ASSERT_NE(source, nullptr);
    rig.emu.trigger(kT0);
    StereoFrame frame;
    ASSERT_TRUE(source->next(frame).isOk());
    cv::Mat yuyv(kH, kW, CV_8UC2);
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; x += 2) {
        const std::uint8_t u = emulated::yuyvChroma(x, y);
        yuyv.at<cv::Vec2b>(y, x) = {rig.left(0).at<std::uint8_t>(y, x), u};
        yuyv.at<cv::Vec2b>(y, x + 1) = {rig.left(0).at<std::uint8_t>(y, x + 1),
                                        static_cast<std::uint8_t>(255 - u)};
      }
    }
    cv::Mat expected;
    cv::cvtColor(yuyv, expected, cv::COLOR_YUV2BGR_YUYV);
    EXPECT_TRUE(sameImage(frame.left_color, expected));
    EXPECT_TRUE(sameImage(frame.left, rig.left(0)));
    EXPECT_TRUE(sameImage(frame.right, rig.right(0)));
    EXPECT_TRUE(frame.right_color.empty());
  }
  V4l2Options grey = fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey);
  grey.left_color = true;
  EXPECT_NE(grey.validate().message().find("v4l2.left_color"), std::string::npos);
}

TEST(V4l2StereoSource, FlaggedBufferIsRequeuedSkippedAndCounted) {
  for (V4l2Layout layout : {V4l2Layout::kTwoDevices, V4l2Layout::kSideBySide}) {
    Rig rig(layout);
    auto source = openOrFail(fastOptions(layout, V4l2PixelFormat::kGrey), rig.emu);
    ASSERT_NE(source, nullptr);
    ASSERT_TRUE(rig.emu.injectBufferErrors(kLeft, 1).isOk());
    rig.emu.trigger(kT0);
    rig.emu.trigger(kT0 + kPeriod);
    StereoFrame frame;
    ASSERT_TRUE(source->next(frame).isOk());
    // The first exposure's left buffer was bad: the pair is the second exposure's.
    EXPECT_EQ(frame.trigger_time_ns, kT0 + kPeriod);
    EXPECT_TRUE(sameImage(frame.left, rig.left(1)));
    EXPECT_TRUE(sameImage(frame.right, rig.right(1)));
    EXPECT_EQ(source->counters().buffer_errors, 1u);
    EXPECT_EQ(source->counters().pairing_drops, layout == V4l2Layout::kTwoDevices ? 1u : 0u);
    EXPECT_EQ(frame.sequence, 1u);
    // All buffers were queued back: the stream keeps going for more frames than there are
    // buffers.
    for (int k = 2; k < 12; ++k) {
      rig.emu.trigger(kT0 + k * kPeriod);
      ASSERT_TRUE(source->next(frame).isOk());
      EXPECT_EQ(frame.trigger_time_ns, kT0 + k * kPeriod);
    }
    EXPECT_EQ(rig.emu.stats().frames_lost, 0u);
  }
}

TEST(V4l2StereoSource, ShortBufferIsRequeuedSkippedAndCounted) {
  Rig rig(V4l2Layout::kTwoDevices);
  auto source = openOrFail(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kYuyv), rig.emu);
  ASSERT_NE(source, nullptr);
  ASSERT_TRUE(rig.emu.injectShortFrames(kRight, 1).isOk());
  rig.emu.trigger(kT0);
  rig.emu.trigger(kT0 + kPeriod);
  StereoFrame frame;
  ASSERT_TRUE(source->next(frame).isOk());
  EXPECT_EQ(frame.trigger_time_ns, kT0 + kPeriod);
  EXPECT_TRUE(sameImage(frame.right, rig.right(1)));
  EXPECT_EQ(source->counters().short_buffers, 1u);
  EXPECT_EQ(source->counters().buffer_errors, 0u);
  EXPECT_EQ(source->counters().pairing_drops, 1u);  // the left buffer of exposure 0
}

TEST(V4l2StereoSource, FrameDroppedOnOneEyeIsDroppedFromTheOtherAndCounted) {
  Rig rig(V4l2Layout::kTwoDevices);
  auto source = openOrFail(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey), rig.emu);
  ASSERT_NE(source, nullptr);
  StereoFrame frame;
  rig.emu.trigger(kT0);
  ASSERT_TRUE(source->next(frame).isOk());
  ASSERT_TRUE(rig.emu.dropFrames(kRight, 1).isOk());
  rig.emu.trigger(kT0 + kPeriod);  // the right camera loses this one
  rig.emu.trigger(kT0 + 2 * kPeriod);
  ASSERT_TRUE(source->next(frame).isOk());
  EXPECT_EQ(frame.trigger_time_ns, kT0 + 2 * kPeriod);
  EXPECT_TRUE(sameImage(frame.left, rig.left(2)));
  EXPECT_TRUE(sameImage(frame.right, rig.right(2)));
  EXPECT_EQ(source->counters().pairing_drops, 1u);  // the lonely left buffer of exposure 1
  EXPECT_EQ(source->counters().sequence_gaps, 1u);  // the right driver's sequence jumped by 2
  EXPECT_EQ(frame.sequence, 2u);                    // the gap shows in the frame sequence
  EXPECT_EQ(source->lastPair().right_sequence, 2u);
}

TEST(V4l2StereoSource, PairsWithinTheSkewBoundAndDropsBeyondIt) {
  Rig rig(V4l2Layout::kTwoDevices);
  auto source = openOrFail(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey), rig.emu);
  ASSERT_NE(source, nullptr);
  StereoFrame frame;
  ASSERT_TRUE(rig.emu.setTimestampOffset(kRight, 900'000).isOk());  // 0.9 ms < 1 ms bound
  rig.emu.trigger(kT0);
  ASSERT_TRUE(source->next(frame).isOk());
  EXPECT_EQ(source->lastPair().right_time_ns - source->lastPair().left_time_ns, 900'000);
  EXPECT_EQ(source->counters().pairing_drops, 0u);

  // Beyond the bound no pair forms: each exposure's older buffer is dropped, and next() times
  // out without delivering a wrong pair.
  ASSERT_TRUE(rig.emu.setTimestampOffset(kRight, 1'500'000).isOk());
  rig.emu.trigger(kT0 + kPeriod);
  const Status s = source->next(frame);
  EXPECT_EQ(s.code(), StatusCode::kTimeout) << s.toString();
  EXPECT_EQ(source->counters().pairing_drops, 1u);
  EXPECT_EQ(source->counters().frames, 1u);
}

TEST(V4l2StereoSource, StallTimesOutWithinTheWatchdogAndResetsAfterRepeats) {
  Rig rig(V4l2Layout::kSideBySide);
  V4l2Options o = fastOptions(V4l2Layout::kSideBySide, V4l2PixelFormat::kGrey);
  o.reopen_after_timeouts = 3;
  auto source = openOrFail(o, rig.emu);
  ASSERT_NE(source, nullptr);
  StereoFrame frame;
  for (int i = 0; i < 3; ++i) {
    const std::uint64_t waited_before = rig.emu.stats().waited_ms;
    const TimeNs start = sysio::monotonicNowNs();
    const Status s = source->next(frame);
    const TimeNs took = sysio::monotonicNowNs() - start;
    EXPECT_EQ(s.code(), StatusCode::kTimeout);
    EXPECT_NE(s.message().find(kLeft), std::string::npos) << s.message();
    // The driver asked the kernel to block for the dequeue timeout and no longer (each wait
    // rounds up to a whole ms); the wall time adds only this shared machine's scheduling delay.
    const std::uint64_t waited = rig.emu.stats().waited_ms - waited_before;
    EXPECT_GE(waited, 30u);
    EXPECT_LE(waited, 32u);
    EXPECT_GE(took, 30'000'000);
    EXPECT_LT(took, 30'000'000 + 200'000'000);
  }
  EXPECT_EQ(source->counters().timeouts, 3u);
  // The third timeout in a row reset the device.
  EXPECT_EQ(source->counters().watchdog_resets, 1u);
  EXPECT_EQ(source->counters().device_losses, 1u);
  EXPECT_TRUE(source->deviceLost());
  EXPECT_EQ(rig.emu.openFds(), 0);
  // The next call reopens it after the initial backoff and frames flow again.
  rig.emu.trigger(kT0);                                             // nobody streams: lost
  ASSERT_TRUE(source->next(frame).code() == StatusCode::kTimeout);  // reopened, then no frame
  EXPECT_EQ(source->counters().reopens, 1u);
  rig.emu.trigger(kT0 + kPeriod);
  ASSERT_TRUE(source->next(frame).isOk());
  EXPECT_EQ(frame.trigger_time_ns, kT0 + kPeriod);
}

TEST(V4l2StereoSource, UnpluggedDeviceIsReopenedWithBoundedExponentialBackoff) {
  Rig rig(V4l2Layout::kTwoDevices);
  V4l2Options o = fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kGrey);
  o.reopen_backoff_initial_ms = 40;
  o.reopen_backoff_max_ms = 160;
  auto source = openOrFail(o, rig.emu);
  ASSERT_NE(source, nullptr);
  StereoFrame frame;
  TimeNs t = kT0;
  for (int k = 0; k < 3; ++k, t += kPeriod) {
    rig.emu.trigger(t);
    ASSERT_TRUE(source->next(frame).isOk());
  }
  const std::uint64_t sequence_before = frame.sequence;

  constexpr int kOutageMs = 500;
  const TimeNs unplugged_at = sysio::monotonicNowNs();
  ASSERT_TRUE(rig.emu.unplug(kLeft, std::chrono::milliseconds(kOutageMs)).isOk());
  const TimeNs back_at = unplugged_at + kOutageMs * 1'000'000LL;

  int errors = 0;
  std::uint64_t longest_wait_ms = 0;
  TimeNs loss_seen_at = 0;
  TimeNs first_frame_at = 0;
  while (sysio::monotonicNowNs() < unplugged_at + 5'000'000'000LL) {
    rig.emu.trigger(t);
    t += kPeriod;
    const std::uint64_t waited_before = rig.emu.stats().waited_ms;
    const Status s = source->next(frame);
    longest_wait_ms = std::max(longest_wait_ms, rig.emu.stats().waited_ms - waited_before);
    if (s.isOk()) {
      first_frame_at = sysio::monotonicNowNs();
      break;
    }
    if (errors++ == 0) loss_seen_at = sysio::monotonicNowNs();
    // kDeviceError while the device is gone; kTimeout right after the reopen, since the exposure
    // of this iteration came before the stream was back.
    EXPECT_TRUE(s.code() == StatusCode::kDeviceError || s.code() == StatusCode::kTimeout)
        << s.toString();
    EXPECT_NE(s.message().find(kLeft), std::string::npos) << s.message();
  }
  ASSERT_GT(first_frame_at, 0) << "never recovered";
  EXPECT_GT(errors, 0);
  // No next() asked to block beyond the dequeue timeout (sleeps and polls together; each wait
  // rounds up to a whole ms).
  EXPECT_LE(longest_wait_ms, static_cast<std::uint64_t>(o.dequeue_timeout_ms + 3));
  // Back within one maximal backoff and one dequeue timeout of the device's return, plus kSlack
  // for the scheduling delays of this shared 2-core machine (seen up to 64 ms at load 11).
  constexpr TimeNs kSlack = 150'000'000;
  EXPECT_GE(first_frame_at, back_at);
  EXPECT_LT(first_frame_at - back_at,
            (o.reopen_backoff_max_ms + o.dequeue_timeout_ms) * 1'000'000LL + kSlack);

  // Open attempts after the loss: the first one the initial backoff after the loss, then gaps
  // doubling up to the maximum: 40, 80, 160, 160, ... ms. Never early; late only by scheduling
  // delay, which stays below the next doubling (an uncapped backoff leaves a gap of 320 ms).
  std::vector<TimeNs> attempts;
  for (TimeNs a : rig.emu.openAttempts(kLeft)) {
    if (a > unplugged_at) attempts.push_back(a);
  }
  ASSERT_GE(attempts.size(), 4u);
  EXPECT_GE(attempts[0] - unplugged_at, o.reopen_backoff_initial_ms * 1'000'000LL);
  EXPECT_LT(attempts[0] - loss_seen_at, o.reopen_backoff_initial_ms * 1'000'000LL + kSlack);
  int expected_ms = o.reopen_backoff_initial_ms;
  for (std::size_t i = 1; i < attempts.size(); ++i) {
    expected_ms = std::min(2 * expected_ms, o.reopen_backoff_max_ms);
    const TimeNs gap = attempts[i] - attempts[i - 1];
    EXPECT_GE(gap, expected_ms * 1'000'000LL) << "attempt " << i;
    EXPECT_LT(gap, expected_ms * 1'000'000LL + kSlack) << "attempt " << i;
  }
  const V4l2Counters& c = source->counters();
  EXPECT_EQ(c.device_losses, 1u);
  EXPECT_EQ(c.reopens, 1u);
  EXPECT_EQ(c.reopen_failures, attempts.size() - 1);
  EXPECT_FALSE(source->deviceLost());
  // The frame sequence continues across the reopen.
  EXPECT_GT(frame.sequence, sequence_before);
  // Nothing leaked: two devices open, each buffer mapped once.
  EXPECT_EQ(rig.emu.openFds(), 2);
  EXPECT_EQ(rig.emu.liveMappings(), 2 * o.buffer_count);
}

TEST(V4l2StereoSource, DestructorStopsUnmapsAndCloses) {
  Rig rig(V4l2Layout::kTwoDevices);
  {
    auto source = openOrFail(fastOptions(V4l2Layout::kTwoDevices, V4l2PixelFormat::kYuyv), rig.emu);
    ASSERT_NE(source, nullptr);
    EXPECT_TRUE(rig.emu.streaming(kLeft));
    EXPECT_TRUE(rig.emu.streaming(kRight));
    EXPECT_EQ(rig.emu.liveMappings(), 8);
  }
  EXPECT_FALSE(rig.emu.streaming(kLeft));
  EXPECT_FALSE(rig.emu.streaming(kRight));
  EXPECT_EQ(rig.emu.openFds(), 0);
  EXPECT_EQ(rig.emu.liveMappings(), 0);
}

TEST(V4l2StereoSource, NoHeapAllocationPerFrameAfterTheFirst) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(runtime::allocCounterActive());
  for (V4l2Layout layout : {V4l2Layout::kTwoDevices, V4l2Layout::kSideBySide}) {
    for (V4l2PixelFormat format : {V4l2PixelFormat::kGrey, V4l2PixelFormat::kYuyv}) {
      Rig rig(layout);
      V4l2Options o = fastOptions(layout, format);
      o.left_color = format == V4l2PixelFormat::kYuyv;  // and the colour conversion
      auto source = openOrFail(o, rig.emu);
      ASSERT_NE(source, nullptr);
      StereoFrame frame;
      rig.emu.trigger(kT0);
      ASSERT_TRUE(source->next(frame).isOk());  // allocates frame.left / right / left_color
      const void* left_data = frame.left.data;
      std::uint64_t allocations = 0;
      // More frames than a std::deque block holds (128 ints), so that a container growing in
      // steps, in the driver or the emulated kernel, shows up.
      for (int k = 1; k <= 300; ++k) {
        rig.emu.trigger(kT0 + k * kPeriod);  // the emulated kernel's work is not counted
        runtime::AllocationScope scope;
        const Status s = source->next(frame);
        allocations += scope.count();
        ASSERT_TRUE(s.isOk());
      }
      EXPECT_EQ(allocations, 0u);
      EXPECT_EQ(frame.left.data, left_data);
    }
  }
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::v4l2
