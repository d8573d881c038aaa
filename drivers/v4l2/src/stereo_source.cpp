#include "sunvo/v4l2/stereo_source.hpp"

#include <fcntl.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace sunvo::v4l2 {
namespace {

// Milliseconds from now to deadline, rounded up so that a wait never ends before the deadline.
int msUntil(TimeNs deadline_ns, TimeNs now_ns) {
  if (deadline_ns <= now_ns) return 0;
  return static_cast<int>((deadline_ns - now_ns + 999'999) / 1'000'000);
}

Status deviceError(std::string message) {
  return {StatusCode::kDeviceError, std::move(message)};
}

std::string errnoText(int err) {
  return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")";
}

std::string fourcc(std::uint32_t f) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i)
    s[static_cast<std::size_t>(i)] = static_cast<char>((f >> (8 * i)) & 0xff);
  return s;
}

// The v4l2_buffer of a capture MMAP buffer, as QUERYBUF, QBUF and DQBUF take it.
v4l2_buffer mmapBuffer(std::uint32_t index) {
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  buf.index = index;
  return buf;
}

Status rangeError(const char* key, long long value, long long lo, long long hi) {
  return invalidArgument(std::string("v4l2.") + key + ": " + std::to_string(value) +
                         " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

}  // namespace

Status V4l2Options::validate() const {
  if (left_device.empty()) return invalidArgument("v4l2.left_device: empty path");
  if (layout == V4l2Layout::kTwoDevices) {
    if (right_device.empty()) return invalidArgument("v4l2.right_device: empty path");
    if (right_device == left_device) {
      return invalidArgument("v4l2.right_device: same device as v4l2.left_device (" + left_device +
                             "); use layout side_by_side for one device");
    }
  }
  if (width < 16 || width > 8192) return rangeError("width", width, 16, 8192);
  if (height < 16 || height > 8192) return rangeError("height", height, 16, 8192);
  if (pixel_format == V4l2PixelFormat::kYuyv && width % 2 != 0) {
    return invalidArgument("v4l2.width: " + std::to_string(width) +
                           " is odd; YUYV carries pixels in pairs");
  }
  if (left_color && pixel_format != V4l2PixelFormat::kYuyv) {
    return invalidArgument("v4l2.left_color: needs pixel_format YUYV (GREY has no colour)");
  }
  if (!(fps > 0.0 && fps <= 1000.0)) {
    return invalidArgument("v4l2.fps: " + std::to_string(fps) + " is outside (0, 1000]");
  }
  if (buffer_count < 2 || buffer_count > V4l2StereoSource::kMaxBuffers) {
    return rangeError("buffer_count", buffer_count, 2, V4l2StereoSource::kMaxBuffers);
  }
  if (dequeue_timeout_ms < 1 || dequeue_timeout_ms > 60000) {
    return rangeError("dequeue_timeout_ms", dequeue_timeout_ms, 1, 60000);
  }
  if (reopen_after_timeouts < 0 || reopen_after_timeouts > 100000) {
    return rangeError("reopen_after_timeouts", reopen_after_timeouts, 0, 100000);
  }
  if (reopen_backoff_initial_ms < 1 || reopen_backoff_initial_ms > 60000) {
    return rangeError("reopen_backoff_initial_ms", reopen_backoff_initial_ms, 1, 60000);
  }
  if (reopen_backoff_max_ms < reopen_backoff_initial_ms || reopen_backoff_max_ms > 600000) {
    return rangeError("reopen_backoff_max_ms", reopen_backoff_max_ms, reopen_backoff_initial_ms,
                      600000);
  }
  if (max_pair_skew_ns < 0 || max_pair_skew_ns > kNsPerSecond) {
    return rangeError("max_pair_skew_ns", max_pair_skew_ns, 0, kNsPerSecond);
  }
  return Status::ok();
}

V4l2StereoSource::V4l2StereoSource(const V4l2Options& options, sysio::SysIo& io)
    : options_(options), io_(io) {
  const bool sbs = options_.layout == V4l2Layout::kSideBySide;
  devices_[0].path = options_.left_device;
  devices_[0].width = sbs ? 2 * options_.width : options_.width;
  devices_[1].path = options_.right_device;
  devices_[1].width = options_.width;
  pixel_format_ =
      options_.pixel_format == V4l2PixelFormat::kGrey ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_YUYV;
  bytes_per_pixel_ = options_.pixel_format == V4l2PixelFormat::kGrey ? 1 : 2;
  backoff_ms_ = options_.reopen_backoff_initial_ms;
}

Expected<std::unique_ptr<V4l2StereoSource>> V4l2StereoSource::open(const V4l2Options& options,
                                                                   sysio::SysIo& io) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<V4l2StereoSource> source(new V4l2StereoSource(options, io));
  SUNVO_RETURN_IF_ERROR(source->openAll());
  return source;
}

V4l2StereoSource::~V4l2StereoSource() {
  closeAll();
}

int V4l2StereoSource::deviceCount() const {
  return options_.layout == V4l2Layout::kSideBySide ? 1 : 2;
}

Status V4l2StereoSource::openDevice(Device& d) {
  const std::string& path = d.path;
  const sysio::SysResult fd = io_.open(path.c_str(), O_RDWR | O_NONBLOCK);
  if (!fd.ok()) return deviceError(path + ": open: " + errnoText(fd.err));
  d.fd = static_cast<int>(fd.value);
  auto fail = [&](const std::string& step, int err) {
    closeDevice(d);
    return deviceError(path + ": " + step + ": " + errnoText(err));
  };

  v4l2_capability cap{};
  sysio::SysResult r = sysio::ioctlRetry(io_, d.fd, VIDIOC_QUERYCAP, &cap);
  if (!r.ok()) return fail("VIDIOC_QUERYCAP", r.err);
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0 || (caps & V4L2_CAP_STREAMING) == 0) {
    closeDevice(d);
    return deviceError(path + ": not a streaming video capture device (capabilities 0x" +
                       std::to_string(caps) + ")");
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<std::uint32_t>(d.width);
  fmt.fmt.pix.height = static_cast<std::uint32_t>(options_.height);
  fmt.fmt.pix.pixelformat = pixel_format_;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  r = sysio::ioctlRetry(io_, d.fd, VIDIOC_S_FMT, &fmt);
  if (!r.ok()) return fail("VIDIOC_S_FMT", r.err);
  // The kernel adjusts a format it cannot deliver instead of failing: check what was set.
  if (fmt.fmt.pix.width != static_cast<std::uint32_t>(d.width) ||
      fmt.fmt.pix.height != static_cast<std::uint32_t>(options_.height) ||
      fmt.fmt.pix.pixelformat != pixel_format_) {
    const std::string want = std::to_string(d.width) + "x" + std::to_string(options_.height) + " " +
                             fourcc(pixel_format_);
    const std::string got = std::to_string(fmt.fmt.pix.width) + "x" +
                            std::to_string(fmt.fmt.pix.height) + " " +
                            fourcc(fmt.fmt.pix.pixelformat);
    closeDevice(d);
    return deviceError(path + ": VIDIOC_S_FMT asked " + want + ", the device set " + got +
                       " (check v4l2.width, v4l2.height, v4l2.pixel_format)");
  }
  const std::uint32_t min_line = static_cast<std::uint32_t>(d.width * bytes_per_pixel_);
  d.bytes_per_line = std::max(fmt.fmt.pix.bytesperline, min_line);
  d.size_image = d.bytes_per_line * static_cast<std::uint32_t>(options_.height);

  // Frame rate: many triggered or fixed-rate devices do not implement S_PARM; that is no error.
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe.numerator = 1000;
  parm.parm.capture.timeperframe.denominator =
      static_cast<std::uint32_t>(std::lround(options_.fps * 1000.0));
  r = sysio::ioctlRetry(io_, d.fd, VIDIOC_S_PARM, &parm);
  if (!r.ok() && r.err != ENOTTY && r.err != EINVAL) return fail("VIDIOC_S_PARM", r.err);

  v4l2_requestbuffers req{};
  req.count = static_cast<std::uint32_t>(options_.buffer_count);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  r = sysio::ioctlRetry(io_, d.fd, VIDIOC_REQBUFS, &req);
  if (!r.ok()) return fail("VIDIOC_REQBUFS", r.err);
  if (req.count < 2 || req.count > static_cast<std::uint32_t>(kMaxBuffers)) {
    closeDevice(d);
    return deviceError(path + ": VIDIOC_REQBUFS granted " + std::to_string(req.count) +
                       " buffers, need 2.." + std::to_string(kMaxBuffers));
  }
  d.buffer_count = static_cast<int>(req.count);

  for (int i = 0; i < d.buffer_count; ++i) {
    v4l2_buffer buf = mmapBuffer(static_cast<std::uint32_t>(i));
    r = sysio::ioctlRetry(io_, d.fd, VIDIOC_QUERYBUF, &buf);
    if (!r.ok()) return fail("VIDIOC_QUERYBUF", r.err);
    if (buf.length < d.size_image) {
      closeDevice(d);
      return deviceError(path + ": buffer " + std::to_string(i) + " holds " +
                         std::to_string(buf.length) + " bytes, the format needs " +
                         std::to_string(d.size_image));
    }
    const sysio::MapResult m = io_.mmap(nullptr, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED,
                                        d.fd, static_cast<off_t>(buf.m.offset));
    if (!m.ok()) return fail("mmap of buffer " + std::to_string(i), m.err);
    d.buffers[static_cast<std::size_t>(i)] = {m.addr, buf.length};
  }
  for (int i = 0; i < d.buffer_count; ++i) {
    v4l2_buffer buf = mmapBuffer(static_cast<std::uint32_t>(i));
    r = sysio::ioctlRetry(io_, d.fd, VIDIOC_QBUF, &buf);
    if (!r.ok()) return fail("VIDIOC_QBUF", r.err);
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  r = sysio::ioctlRetry(io_, d.fd, VIDIOC_STREAMON, &type);
  if (!r.ok()) return fail("VIDIOC_STREAMON", r.err);
  d.streaming = true;
  d.held = Held{};
  d.have_sequence = false;
  return Status::ok();
}

void V4l2StereoSource::closeDevice(Device& d) {
  if (d.fd < 0) return;
  // Best effort: on a lost device these fail with ENODEV, and close() still frees everything.
  if (d.streaming) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)sysio::ioctlRetry(io_, d.fd, VIDIOC_STREAMOFF, &type);
    d.streaming = false;
  }
  for (Buffer& b : d.buffers) {
    if (b.addr != nullptr) (void)io_.munmap(b.addr, b.length);
    b = Buffer{};
  }
  d.buffer_count = 0;
  (void)io_.close(d.fd);
  d.fd = -1;
  d.held = Held{};
}

Status V4l2StereoSource::openAll() {
  for (int i = 0; i < deviceCount(); ++i) {
    Status s = openDevice(devices_[static_cast<std::size_t>(i)]);
    if (!s.isOk()) {
      closeAll();
      return s;
    }
  }
  consecutive_timeouts_ = 0;
  return Status::ok();
}

void V4l2StereoSource::closeAll() {
  for (Device& d : devices_) closeDevice(d);
}

void V4l2StereoSource::markLost(const Device& d, const char* what, int err) {
  lost_reason_ = d.path + ": " + what + (err != 0 ? ": " + errnoText(err) : std::string());
  closeAll();
  lost_ = true;
  ++counters_.device_losses;
  backoff_ms_ = options_.reopen_backoff_initial_ms;
  next_reopen_ns_ = sysio::monotonicNowNs() + static_cast<TimeNs>(backoff_ms_) * 1'000'000;
  sequence_base_ = next_sequence_;
}

bool V4l2StereoSource::requeue(Device& d, Held& held) {
  v4l2_buffer buf = mmapBuffer(held.index);
  held.valid = false;
  const sysio::SysResult r = sysio::ioctlRetry(io_, d.fd, VIDIOC_QBUF, &buf);
  if (!r.ok()) {
    markLost(d, "VIDIOC_QBUF", r.err);
    return false;
  }
  return true;
}

V4l2StereoSource::Take V4l2StereoSource::takeBuffer(Device& d) {
  for (;;) {
    v4l2_buffer buf = mmapBuffer(0);
    const sysio::SysResult r = sysio::ioctlRetry(io_, d.fd, VIDIOC_DQBUF, &buf);
    if (r.err == EAGAIN) return Take::kNone;
    if (!r.ok()) {
      markLost(d, "VIDIOC_DQBUF", r.err);
      return Take::kLost;
    }
    if (buf.index >= static_cast<std::uint32_t>(d.buffer_count)) {
      markLost(d, "VIDIOC_DQBUF returned an unknown buffer index", 0);
      return Take::kLost;
    }
    // Lost frames: the driver's sequence counts every frame, delivered or not.
    if (d.have_sequence && buf.sequence > d.last_sequence + 1) {
      counters_.sequence_gaps += buf.sequence - d.last_sequence - 1;
    }
    d.have_sequence = true;
    d.last_sequence = buf.sequence;
    Held held{true, buf.index, buf.sequence,
              static_cast<TimeNs>(buf.timestamp.tv_sec) * kNsPerSecond +
                  static_cast<TimeNs>(buf.timestamp.tv_usec) * 1000};
    const bool flagged = (buf.flags & V4L2_BUF_FLAG_ERROR) != 0;
    // bytesused 0: a driver that does not fill it in; the buffer is taken as whole.
    const bool short_buffer = buf.bytesused != 0 && buf.bytesused < d.size_image;
    if (flagged || short_buffer) {
      ++(flagged ? counters_.buffer_errors : counters_.short_buffers);
      if (!requeue(d, held)) return Take::kLost;
      continue;
    }
    d.held = held;
    return Take::kGot;
  }
}

void V4l2StereoSource::copyEye(const Device& d, const Held& held, int x0, cv::Mat& eye) const {
  const auto* base = static_cast<const std::uint8_t*>(d.buffers[held.index].addr);
  const int w = options_.width;
  for (int y = 0; y < options_.height; ++y) {
    const std::uint8_t* src = base + static_cast<std::size_t>(y) * d.bytes_per_line +
                              static_cast<std::size_t>(x0 * bytes_per_pixel_);
    std::uint8_t* dst = eye.ptr<std::uint8_t>(y);
    if (bytes_per_pixel_ == 1) {
      std::memcpy(dst, src, static_cast<std::size_t>(w));
    } else {
      // YUYV: Y0 U0 Y1 V0 | Y2 U2 Y3 V2 ...: luma of pixel i is byte 2i.
      for (int i = 0; i < w; ++i) dst[i] = src[2 * i];
    }
  }
}

void V4l2StereoSource::colorEye(const Device& d, const Held& held, cv::Mat& bgr) const {
  auto* base = static_cast<std::uint8_t*>(d.buffers[held.index].addr);
  // The left eye's YUYV pixels in place (2 bytes per pixel, the device's line stride). Converted
  // in row bands of at most 2^16 pixels: cvtColor asks parallel_for_ for pixels / 2^16 stripes,
  // so each band runs inline on the capture thread (no worker threads, no allocation).
  const cv::Mat yuyv(options_.height, options_.width, CV_8UC2, base, d.bytes_per_line);
  const int band_rows = std::max(1, (1 << 16) / options_.width);
  for (int r0 = 0; r0 < options_.height; r0 += band_rows) {
    const cv::Range rows(r0, std::min(options_.height, r0 + band_rows));
    cv::Mat dst = bgr.rowRange(rows);
    cv::cvtColor(yuyv.rowRange(rows), dst, cv::COLOR_YUV2BGR_YUYV);
  }
}

Status V4l2StereoSource::deliver(StereoFrame& out) {
  Device& left = devices_[0];
  const bool sbs = options_.layout == V4l2Layout::kSideBySide;
  Device& right = sbs ? devices_[0] : devices_[1];
  out.left.create(options_.height, options_.width, CV_8UC1);
  out.right.create(options_.height, options_.width, CV_8UC1);
  copyEye(left, left.held, 0, out.left);
  copyEye(right, right.held, sbs ? options_.width : 0, out.right);
  if (options_.left_color) {
    out.left_color.create(options_.height, options_.width, CV_8UC3);
    colorEye(left, left.held, out.left_color);
  }

  out.sequence = sequence_base_ + left.held.sequence;
  next_sequence_ = out.sequence + 1;
  out.trigger_time_ns = left.held.time_ns;
  last_pair_ = {left.held.time_ns, right.held.time_ns, left.held.sequence, right.held.sequence};
  ++counters_.frames;
  consecutive_timeouts_ = 0;

  // The frame is out; a failed requeue marks the device lost for the next call.
  if (requeue(left, left.held) && !sbs) (void)requeue(right, right.held);
  return Status::ok();
}

Status V4l2StereoSource::waitForReopen(TimeNs deadline) {
  for (;;) {
    const TimeNs now = sysio::monotonicNowNs();
    if (now >= next_reopen_ns_) {
      Status s = openAll();
      if (s.isOk()) {
        lost_ = false;
        ++counters_.reopens;
        backoff_ms_ = options_.reopen_backoff_initial_ms;
        return Status::ok();
      }
      ++counters_.reopen_failures;
      backoff_ms_ = std::min(2 * backoff_ms_, options_.reopen_backoff_max_ms);
      // The wait counts from the end of the failed attempt.
      next_reopen_ns_ = sysio::monotonicNowNs() + static_cast<TimeNs>(backoff_ms_) * 1'000'000;
      lost_reason_ = s.message();
    }
    // Sleep until the next attempt; if that is after the deadline, sleep until the deadline only.
    const TimeNs t = sysio::monotonicNowNs();
    if (next_reopen_ns_ > deadline) {
      if (deadline > t) (void)io_.poll(nullptr, 0, msUntil(deadline, t));
      return deviceError("device lost, reopening in " +
                         std::to_string(msUntil(next_reopen_ns_, sysio::monotonicNowNs())) +
                         " ms: " + lost_reason_);
    }
    if (next_reopen_ns_ > t) (void)io_.poll(nullptr, 0, msUntil(next_reopen_ns_, t));
  }
}

Status V4l2StereoSource::next(StereoFrame& out) {
  const TimeNs deadline =
      sysio::monotonicNowNs() + static_cast<TimeNs>(options_.dequeue_timeout_ms) * 1'000'000;
  if (lost_) SUNVO_RETURN_IF_ERROR(waitForReopen(deadline));

  const int n = deviceCount();
  for (;;) {
    // Take one buffer per device that holds none.
    for (int i = 0; i < n; ++i) {
      Device& d = devices_[static_cast<std::size_t>(i)];
      if (!d.held.valid && takeBuffer(d) == Take::kLost) {
        return deviceError("device lost: " + lost_reason_);
      }
    }
    if (n == 1) {
      if (devices_[0].held.valid) return deliver(out);
    } else if (devices_[0].held.valid && devices_[1].held.valid) {
      Held& l = devices_[0].held;
      Held& r = devices_[1].held;
      const TimeNs skew = l.time_ns - r.time_ns;
      if (std::abs(skew) <= options_.max_pair_skew_ns) return deliver(out);
      // The older one's partner never came: queue it back and try its successor.
      ++counters_.pairing_drops;
      Device& older = skew < 0 ? devices_[0] : devices_[1];
      if (!requeue(older, older.held)) return deviceError("device lost: " + lost_reason_);
      continue;
    }

    // Wait for the devices that hold no buffer yet.
    std::array<pollfd, 2> fds{};
    std::array<int, 2> which{};
    nfds_t count = 0;
    for (int i = 0; i < n; ++i) {
      const Device& d = devices_[static_cast<std::size_t>(i)];
      if (d.held.valid) continue;
      fds[count] = pollfd{d.fd, POLLIN, 0};
      which[count] = i;
      ++count;
    }
    const TimeNs now = sysio::monotonicNowNs();
    if (now >= deadline) {
      ++counters_.timeouts;
      ++consecutive_timeouts_;
      if (options_.reopen_after_timeouts > 0 &&
          consecutive_timeouts_ >= options_.reopen_after_timeouts) {
        ++counters_.watchdog_resets;
        markLost(devices_[static_cast<std::size_t>(which[0])], "watchdog: no frame", 0);
        lost_reason_ += " in " + std::to_string(consecutive_timeouts_) + " timeouts";
        consecutive_timeouts_ = 0;
      }
      return {StatusCode::kTimeout, "no stereo frame within " +
                                        std::to_string(options_.dequeue_timeout_ms) + " ms from " +
                                        devices_[static_cast<std::size_t>(which[0])].path};
    }
    const sysio::SysResult pr = io_.poll(fds.data(), count, msUntil(deadline, now));
    if (!pr.ok() && pr.err != EINTR) {
      markLost(devices_[static_cast<std::size_t>(which[0])], "poll", pr.err);
      return deviceError("device lost: " + lost_reason_);
    }
    for (nfds_t k = 0; k < count; ++k) {
      if ((fds[k].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
        markLost(devices_[static_cast<std::size_t>(which[k])],
                 (fds[k].revents & POLLHUP) != 0 ? "poll: POLLHUP" : "poll: POLLERR", 0);
        return deviceError("device lost: " + lost_reason_);
      }
    }
  }
}

}  // namespace sunvo::v4l2
