#pragma once
// EmulatedV4l2: Video4Linux2 capture devices in user space, behind the sysio::SysIo seam.
//
// It implements the kernel ABI of the calls sunvo's V4L2 driver makes, with videobuf2's semantics,
// so that the driver runs unchanged:
// - open/close of registered paths ("/dev/video0"); fds are private numbers (from 1000);
// - VIDIOC_QUERYCAP; VIDIOC_G_FMT/S_FMT/TRY_FMT (the size is the sensor's, an unsupported pixel
//   format becomes the default one, as drivers adjust rather than fail; EBUSY with buffers);
//   VIDIOC_G_PARM/S_PARM; VIDIOC_REQBUFS (MMAP only; count clamped to [2, 32]; 0 frees; EBUSY
//   while streaming or mapped); VIDIOC_QUERYBUF; mmap/munmap by the buffer's m.offset;
//   VIDIOC_QBUF (EINVAL for a buffer already queued); VIDIOC_DQBUF (EAGAIN when non-blocking and
//   nothing is done); VIDIOC_STREAMON/STREAMOFF (STREAMOFF returns every buffer to the user);
//   other requests ENOTTY; the fd that allocated the buffers owns the queue (EBUSY for others);
// - poll: POLLIN|POLLRDNORM when a buffer is done, POLLERR when not streaming, POLLERR|POLLHUP
//   once the device is unplugged; poll with no fds sleeps.
//
// Frames are made by trigger(time): every streaming camera takes its oldest queued buffer, fills
// it from its content generator (GREY, or YUYV with a non-constant chroma that a converter must
// ignore), stamps it time + timestamp_offset_ns, and numbers it with a per-stream sequence that
// also counts frames lost for want of a queued buffer. No trigger = no frame (a stall).
// Faults: flagged buffers (V4L2_BUF_FLAG_ERROR), short buffers (bytesused half the image), frames
// dropped on one camera, unplug for a time
// (open fails ENOENT, open fds fail ENODEV / poll POLLERR|POLLHUP; afterwards open works again).
// Thread-safe: a test thread may trigger while the driver polls.

#include <poll.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/sysio/sysio.hpp"

namespace sunvo::emulated {

// Fills gray (height x width, CV_8UC1, already allocated) for the frame of trigger number frame.
using FrameContent = std::function<void(std::uint64_t frame, cv::Mat& gray)>;

// A content generator that cycles through images (each CV_8UC1 of the camera's size).
FrameContent imageSequence(std::vector<cv::Mat> images);
// The default content: a deterministic pattern of (x, y, frame, seed).
FrameContent patternContent(int seed);
// The chroma of YUYV frames: U of the pixel pair starting at (x, y) (x even); V = 255 - U.
std::uint8_t yuyvChroma(int x, int y);

struct EmulatedCameraConfig {
  std::string path = "/dev/video0";
  int width = 1242;  // px of the whole sensor image (both eyes for a side-by-side camera)
  int height = 375;  // px
  bool offer_grey = true;
  bool offer_yuyv = true;
  int line_padding = 0;            // bytes after each line: bytesperline = width * bpp + padding
  TimeNs timestamp_offset_ns = 0;  // added to the trigger time (skew between two cameras)
  FrameContent content;            // empty: patternContent(0)
};

// Calls counted since construction.
struct EmulatedV4l2Stats {
  std::uint64_t opens = 0;
  std::uint64_t failed_opens = 0;
  std::uint64_t ioctls = 0;
  std::uint64_t polls = 0;
  std::uint64_t sleeps = 0;     // poll() with no fds
  std::uint64_t waited_ms = 0;  // sum of the timeouts asked in poll() calls (how long the caller
                                // was willing to block, independent of the machine's load)
  std::uint64_t frames_made = 0;
  std::uint64_t frames_lost = 0;  // no queued buffer, or dropped by dropFrames()
};

class EmulatedV4l2 final : public sysio::SysIo {
 public:
  EmulatedV4l2();
  ~EmulatedV4l2() override;

  // kInvalidArgument for a path already added or a size below 2x2.
  Status addCamera(EmulatedCameraConfig config);

  // One exposure on every present, streaming camera, stamped time_ns (+ the camera's offset).
  void trigger(TimeNs time_ns);

  // Faults, each on the named camera (kInvalidArgument for an unknown path):
  Status injectBufferErrors(const std::string& path, int frames);  // next frames flagged ERROR
  Status injectShortFrames(const std::string& path, int frames);   // next frames half as long
  Status dropFrames(const std::string& path, int frames);          // next frames never delivered
  Status unplug(const std::string& path, std::chrono::milliseconds duration);  // gone, then back
  Status setTimestampOffset(const std::string& path, TimeNs offset_ns);

  // Introspection for tests (an unknown path reads as empty, false or 0).
  EmulatedV4l2Stats stats() const;
  int openFds() const;
  int liveMappings() const;
  std::vector<TimeNs> openAttempts(
      const std::string& path) const;  // monotonic ns (sysio::monotonicNowNs)
  bool streaming(const std::string& path) const;
  std::uint32_t pixelFormat(const std::string& path) const;

  // sysio::SysIo
  sysio::SysResult open(const char* path, int flags) override;
  sysio::SysResult close(int fd) override;
  sysio::SysResult ioctl(int fd, unsigned long request, void* arg) override;
  sysio::MapResult mmap(void* addr, std::size_t length, int prot, int flags, int fd,
                        off_t offset) override;
  sysio::SysResult munmap(void* addr, std::size_t length) override;
  sysio::SysResult poll(pollfd* fds, nfds_t nfds, int timeout_ms) override;

 private:
  struct Camera;
  struct OpenFile;
  struct Mapping;

  Camera* find(const std::string& path) const;
  // Runs change on the named camera under the lock, then wakes waiters.
  Status withCamera(const std::string& path, const std::function<void(Camera&)>& change);
  bool present(const Camera& c) const;
  void resetQueue(Camera& c);
  int fileError(const OpenFile* f) const;
  int doIoctl(OpenFile& f, unsigned long request, void* arg);
  void capture(Camera& c, TimeNs time_ns, std::uint64_t frame);

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::map<int, OpenFile> files_;
  std::map<const void*, Mapping> mappings_;
  int next_fd_ = 1000;
  std::uint64_t triggers_ = 0;
  EmulatedV4l2Stats stats_;
};

}  // namespace sunvo::emulated
