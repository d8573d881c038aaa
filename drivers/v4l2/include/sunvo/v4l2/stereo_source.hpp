#pragma once
// V4l2StereoSource: a stereo pair from Video4Linux2 capture devices, MMAP streaming.
//
// Two layouts: two devices (left and right cameras, each width x height) or one side-by-side
// device (2*width x height, the left eye in the left half). Pixel formats GREY (8-bit) and YUYV
// (4:2:2; the luma bytes are the gray image; optionally the left eye in colour too). The kernel is
// reached only through a sysio::SysIo&, so tests run this code unchanged against
// hil/sim/emulated_devices.
//
// Life of a device: open(O_RDWR|O_NONBLOCK) → VIDIOC_QUERYCAP → S_FMT → S_PARM (frame rate)
// → REQBUFS (MMAP) → QUERYBUF + mmap once per buffer → QBUF all → STREAMON; per frame poll (with
// the dequeue timeout) → DQBUF → copy/convert → QBUF back; at the end STREAMOFF → munmap → close.
//
// Faults (each has a counter in V4l2Counters):
// - a buffer with V4L2_BUF_FLAG_ERROR (or fewer bytes than the format needs) is queued back and
//   its frame skipped;
// - no frame within dequeue_timeout_ms: next() returns kTimeout; after reopen_after_timeouts of
//   them in a row the devices are reset as if lost;
// - device loss (ENODEV, EIO, ... from an ioctl or poll, or POLLERR/POLLHUP): every device of the
//   pair is closed, next() returns kDeviceError naming the device, and later calls reopen it with
//   exponential backoff (reopen_backoff_initial_ms doubling up to reopen_backoff_max_ms). next()
//   never blocks longer than dequeue_timeout_ms and never ends the process;
// - two devices: the left and right buffers are paired by their driver timestamps; when the two
//   oldest differ by more than max_pair_skew_ns the older one is queued back (a pairing drop);
// - a jump in a device's buffer sequence numbers counts the frames the kernel lost.
//
// Memory: buffers are mapped once per (re)open; next() writes into out.left / out.right, which are
// (re)allocated only when their size or type differs from the configured one, so after the first
// frame a delivered frame allocates nothing (error paths build a message and may allocate).
// Not thread-safe: one capture thread owns the source.

#include <linux/videodev2.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/sysio/sysio.hpp"

namespace sunvo::v4l2 {

enum class V4l2Layout {
  kTwoDevices,  // left_device and right_device, each width x height
  kSideBySide,  // left_device only, 2*width x height, left eye in the left half
};

enum class V4l2PixelFormat {
  kGrey,  // V4L2_PIX_FMT_GREY, 1 byte per pixel
  kYuyv,  // V4L2_PIX_FMT_YUYV, Y0 U Y1 V per two pixels; the Y bytes become the gray image
};

struct V4l2Options {
  V4l2Layout layout = V4l2Layout::kTwoDevices;
  std::string left_device = "/dev/video0";   // path; the only device in kSideBySide
  std::string right_device = "/dev/video1";  // path; unused in kSideBySide
  V4l2PixelFormat pixel_format = V4l2PixelFormat::kGrey;
  int width = 1242;                     // px per eye, [16, 8192]; even for YUYV
  int height = 375;                     // px, [16, 8192]
  double fps = 10.0;                    // frames per second asked with S_PARM, (0, 1000]
  int buffer_count = 4;                 // MMAP buffers per device, [2, 32]
  int dequeue_timeout_ms = 200;         // watchdog: longest wait in one next(), [1, 60000]
  int reopen_after_timeouts = 10;       // consecutive timeouts that reset the devices; 0 = never,
                                        // [0, 100000]
  int reopen_backoff_initial_ms = 100;  // first wait before reopening a lost device, [1, 60000]
  int reopen_backoff_max_ms = 5000;     // the wait doubles up to this, [initial, 600000]
  TimeNs max_pair_skew_ns = 2'000'000;  // largest left/right timestamp difference, [0, 1e9] ns
  // YUYV only: also convert the left eye to colour (BGR, CV_8UC3) into StereoFrame::left_color
  // with cv::cvtColor(COLOR_YUV2BGR_YUYV), for the colour image sun estimators. Off: grey only.
  bool left_color = false;

  // Names the first bad key, e.g. "v4l2.width: 7 is outside [16, 8192]".
  Status validate() const;
};

struct V4l2Counters {
  std::uint64_t frames = 0;           // stereo frames delivered
  std::uint64_t timeouts = 0;         // next() calls that ended at dequeue_timeout_ms
  std::uint64_t buffer_errors = 0;    // buffers flagged V4L2_BUF_FLAG_ERROR: requeued, skipped
  std::uint64_t short_buffers = 0;    // buffers with fewer bytes than the format: requeued, skipped
  std::uint64_t device_losses = 0;    // losses (ioctl/poll errors, POLLERR/HUP) and watchdog resets
  std::uint64_t watchdog_resets = 0;  // of device_losses: after reopen_after_timeouts timeouts
  std::uint64_t reopens = 0;          // successful reopens after a loss
  std::uint64_t reopen_failures = 0;  // failed reopen attempts
  std::uint64_t pairing_drops = 0;    // buffers queued back unpaired (skew > max_pair_skew_ns)
  std::uint64_t sequence_gaps = 0;    // frames the kernel skipped (jumps in buffer sequence)
};

// What the last delivered frame was made of (both eyes; equal in kSideBySide).
struct V4l2PairInfo {
  TimeNs left_time_ns = 0;  // driver buffer timestamp (CLOCK_MONOTONIC for most drivers), ns
  TimeNs right_time_ns = 0;
  std::uint32_t left_sequence = 0;  // driver buffer sequence
  std::uint32_t right_sequence = 0;
};

class V4l2StereoSource {
 public:
  // The most MMAP buffers per device (the upper bound of buffer_count).
  static constexpr int kMaxBuffers = 32;

  // Validates the options, opens and starts streaming every device. Fails with the option's key
  // or the device path and the failed step.
  static Expected<std::unique_ptr<V4l2StereoSource>> open(const V4l2Options& options,
                                                          sysio::SysIo& io);

  V4l2StereoSource(const V4l2StereoSource&) = delete;
  V4l2StereoSource& operator=(const V4l2StereoSource&) = delete;
  ~V4l2StereoSource();  // STREAMOFF, munmap, close

  // Waits at most dequeue_timeout_ms for the next stereo pair and writes it into out:
  // left/right CV_8UC1 width x height, trigger_time_ns = the left buffer's driver timestamp (ns;
  // the program replaces it with the matched GPIO trigger time, see gpio::TriggerPairer),
  // sequence = the left device's buffer sequence since STREAMON, continued across reopens (gaps =
  // lost frames).
  // Errors: kTimeout (no pair in time), kDeviceError (a device is lost or being reopened; the
  // message names it). out's colour Mats are left untouched.
  Status next(StereoFrame& out);

  const V4l2Counters& counters() const { return counters_; }
  const V4l2PairInfo& lastPair() const { return last_pair_; }
  const V4l2Options& options() const { return options_; }
  bool deviceLost() const { return lost_; }

 private:
  struct Buffer {
    void* addr = nullptr;
    std::size_t length = 0;
  };
  // A buffer taken with DQBUF and not yet queued back.
  struct Held {
    bool valid = false;
    std::uint32_t index = 0;
    std::uint32_t sequence = 0;
    TimeNs time_ns = 0;
  };
  struct Device {
    std::string path;
    int fd = -1;
    int width = 0;  // px of the whole device image
    std::uint32_t bytes_per_line = 0;
    std::uint32_t size_image = 0;
    std::array<Buffer, kMaxBuffers> buffers{};
    int buffer_count = 0;
    bool streaming = false;
    Held held;
    bool have_sequence = false;
    std::uint32_t last_sequence = 0;
  };
  enum class Take { kGot, kNone, kLost };

  V4l2StereoSource(const V4l2Options& options, sysio::SysIo& io);
  int deviceCount() const;
  Status openDevice(Device& d);
  void closeDevice(Device& d);
  Status openAll();
  void closeAll();
  Take takeBuffer(Device& d);
  bool requeue(Device& d, Held& held);
  void markLost(const Device& d, const char* what, int err);
  Status waitForReopen(TimeNs deadline);
  Status deliver(StereoFrame& out);
  void copyEye(const Device& d, const Held& held, int x0, cv::Mat& eye) const;
  void colorEye(const Device& d, const Held& held, cv::Mat& bgr) const;  // the left eye, YUYV

  V4l2Options options_;
  sysio::SysIo& io_;
  std::array<Device, 2> devices_;
  V4l2Counters counters_;
  V4l2PairInfo last_pair_;
  std::uint32_t pixel_format_ = 0;  // V4L2_PIX_FMT_*
  int bytes_per_pixel_ = 1;
  bool lost_ = false;
  std::string lost_reason_;
  TimeNs next_reopen_ns_ = 0;  // sysio::monotonicNowNs()
  int backoff_ms_ = 0;
  int consecutive_timeouts_ = 0;
  // StereoFrame::sequence = sequence_base_ + the left buffer's sequence (which STREAMON restarts
  // at 0); a reopen moves the base past the last frame delivered.
  std::uint64_t sequence_base_ = 0;
  std::uint64_t next_sequence_ = 0;
};

}  // namespace sunvo::v4l2
