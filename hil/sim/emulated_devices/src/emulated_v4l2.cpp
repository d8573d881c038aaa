#include "sunvo/emulated/emulated_v4l2.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <thread>
#include <utility>

namespace sunvo::emulated {
namespace {

constexpr std::uint32_t kMinBuffers = 2;
constexpr std::uint32_t kMaxBuffers = 32;
constexpr std::size_t kPage = 4096;

void copyName(std::uint8_t* dst, std::size_t size, const std::string& text) {
  std::memset(dst, 0, size);
  std::memcpy(dst, text.data(), std::min(size - 1, text.size()));
}

std::uint8_t chromaAt(int x, int y) {
  return yuyvChroma(x, y);
}

// A FIFO of buffer indices with room for every buffer: the emulated kernel's queues allocate
// nothing per frame (a std::deque would, every 128 entries).
class IndexFifo {
 public:
  bool empty() const { return size_ == 0; }
  int front() const { return items_[head_]; }
  void pop_front() {
    head_ = (head_ + 1) % items_.size();
    --size_;
  }
  void push_back(int index) {
    items_[(head_ + size_) % items_.size()] = index;
    ++size_;
  }
  void clear() { head_ = size_ = 0; }

 private:
  std::array<int, kMaxBuffers> items_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace

FrameContent imageSequence(std::vector<cv::Mat> images) {
  return [images = std::move(images)](std::uint64_t frame, cv::Mat& gray) {
    if (images.empty()) return;
    const cv::Mat& image = images[frame % images.size()];
    if (image.size() == gray.size() && image.type() == gray.type()) image.copyTo(gray);
  };
}

FrameContent patternContent(int seed) {
  return [seed](std::uint64_t frame, cv::Mat& gray) {
    const auto f = static_cast<int>(frame % 251);
    for (int y = 0; y < gray.rows; ++y) {
      auto* row = gray.ptr<std::uint8_t>(y);
      for (int x = 0; x < gray.cols; ++x) {
        row[x] = static_cast<std::uint8_t>((x * 3 + y * 5 + f * 11 + seed * 17 + (x ^ y)) & 0xff);
      }
    }
  };
}

struct EmulatedV4l2::Camera {
  struct Buffer {
    enum class State { kUser, kQueued, kDone };
    std::shared_ptr<std::vector<std::uint8_t>> memory;
    State state = State::kUser;
    std::uint32_t bytesused = 0;
    std::uint32_t flags = 0;
    std::uint32_t sequence = 0;
    TimeNs time_ns = 0;
    int mapped = 0;
  };

  EmulatedCameraConfig config;
  TimeNs replug_at_ns = 0;  // monotonic clock; the camera is present from then on
  std::uint64_t generation = 0;
  std::uint32_t pixelformat = 0;
  std::uint32_t bytesperline = 0;
  std::uint32_t sizeimage = 0;
  v4l2_fract timeperframe{1, 30};
  std::vector<Buffer> buffers;
  std::size_t buffer_stride = 0;  // m.offset of buffer i = i * buffer_stride
  IndexFifo queued;               // a buffer is in at most one of them, so kMaxBuffers each suffice
  IndexFifo done;
  int owner_fd = -1;
  bool streaming = false;
  std::uint32_t sequence = 0;
  int error_frames = 0;
  int short_frames = 0;
  int drop_frames = 0;
  std::vector<TimeNs> open_attempts;
  cv::Mat gray;

  int bytesPerPixel() const { return pixelformat == V4L2_PIX_FMT_YUYV ? 2 : 1; }
  void setFormat(std::uint32_t wanted) {
    const bool yuyv_ok = config.offer_yuyv;
    const bool grey_ok = config.offer_grey;
    if (wanted == V4L2_PIX_FMT_YUYV && yuyv_ok) {
      pixelformat = V4L2_PIX_FMT_YUYV;
    } else if (wanted == V4L2_PIX_FMT_GREY && grey_ok) {
      pixelformat = V4L2_PIX_FMT_GREY;
    } else {
      pixelformat = grey_ok ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_YUYV;  // the default format
    }
    bytesperline = static_cast<std::uint32_t>(config.width * bytesPerPixel() + config.line_padding);
    sizeimage = bytesperline * static_cast<std::uint32_t>(config.height);
  }
};

struct EmulatedV4l2::OpenFile {
  Camera* camera = nullptr;
  std::uint64_t generation = 0;
  bool nonblocking = false;
};

struct EmulatedV4l2::Mapping {
  Camera* camera = nullptr;
  int index = 0;
  std::size_t length = 0;
  std::shared_ptr<std::vector<std::uint8_t>> memory;  // keeps freed buffers alive until munmap
};

EmulatedV4l2::EmulatedV4l2() = default;
EmulatedV4l2::~EmulatedV4l2() = default;

Status EmulatedV4l2::addCamera(EmulatedCameraConfig config) {
  std::lock_guard lock(mutex_);
  if (find(config.path) != nullptr) return invalidArgument("camera " + config.path + " exists");
  if (config.width < 2 || config.height < 2 || (!config.offer_grey && !config.offer_yuyv)) {
    return invalidArgument("camera " + config.path + ": bad size or no pixel format");
  }
  auto c = std::make_unique<Camera>();
  if (!config.content) config.content = patternContent(0);
  c->config = std::move(config);
  c->setFormat(c->config.offer_grey ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_YUYV);
  cameras_.push_back(std::move(c));
  return Status::ok();
}

EmulatedV4l2::Camera* EmulatedV4l2::find(const std::string& path) const {
  for (const auto& c : cameras_) {
    if (c->config.path == path) return c.get();
  }
  return nullptr;
}

bool EmulatedV4l2::present(const Camera& c) const {
  return sysio::monotonicNowNs() >= c.replug_at_ns;
}

void EmulatedV4l2::resetQueue(Camera& c) {
  c.streaming = false;
  c.queued.clear();
  c.done.clear();
  c.buffers.clear();  // mapped memory lives on in mappings_ until munmap
  c.owner_fd = -1;
}

int EmulatedV4l2::fileError(const OpenFile* f) const {
  if (f == nullptr) return EBADF;
  if (f->generation != f->camera->generation || !present(*f->camera)) return ENODEV;
  return 0;
}

Status EmulatedV4l2::withCamera(const std::string& path,
                                const std::function<void(Camera&)>& change) {
  {
    std::lock_guard lock(mutex_);
    Camera* c = find(path);
    if (c == nullptr) return invalidArgument("no emulated camera " + path);
    change(*c);
  }
  changed_.notify_all();
  return Status::ok();
}

Status EmulatedV4l2::injectBufferErrors(const std::string& path, int frames) {
  return withCamera(path, [&](Camera& c) { c.error_frames += frames; });
}

Status EmulatedV4l2::injectShortFrames(const std::string& path, int frames) {
  return withCamera(path, [&](Camera& c) { c.short_frames += frames; });
}

Status EmulatedV4l2::dropFrames(const std::string& path, int frames) {
  return withCamera(path, [&](Camera& c) { c.drop_frames += frames; });
}

Status EmulatedV4l2::unplug(const std::string& path, std::chrono::milliseconds duration) {
  return withCamera(path, [&](Camera& c) {
    c.replug_at_ns = sysio::monotonicNowNs() +
                     std::chrono::duration_cast<std::chrono::nanoseconds>(duration).count();
    ++c.generation;  // every fd opened before is dead for good
    resetQueue(c);
  });
}

Status EmulatedV4l2::setTimestampOffset(const std::string& path, TimeNs offset_ns) {
  return withCamera(path, [&](Camera& c) { c.config.timestamp_offset_ns = offset_ns; });
}

EmulatedV4l2Stats EmulatedV4l2::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

int EmulatedV4l2::openFds() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(files_.size());
}

int EmulatedV4l2::liveMappings() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(mappings_.size());
}

std::vector<TimeNs> EmulatedV4l2::openAttempts(const std::string& path) const {
  std::lock_guard lock(mutex_);
  const Camera* c = find(path);
  return c != nullptr ? c->open_attempts : std::vector<TimeNs>{};
}

bool EmulatedV4l2::streaming(const std::string& path) const {
  std::lock_guard lock(mutex_);
  const Camera* c = find(path);
  return c != nullptr && c->streaming;
}

std::uint32_t EmulatedV4l2::pixelFormat(const std::string& path) const {
  std::lock_guard lock(mutex_);
  const Camera* c = find(path);
  return c != nullptr ? c->pixelformat : 0;
}

void EmulatedV4l2::trigger(TimeNs time_ns) {
  {
    std::lock_guard lock(mutex_);
    const std::uint64_t frame = triggers_++;
    for (auto& c : cameras_) capture(*c, time_ns, frame);
  }
  changed_.notify_all();
}

void EmulatedV4l2::capture(Camera& c, TimeNs time_ns, std::uint64_t frame) {
  if (!present(c) || !c.streaming) return;
  if (c.drop_frames > 0 || c.queued.empty()) {
    // The sensor exposed a frame that never reaches the user: the sequence still counts it.
    if (c.drop_frames > 0) --c.drop_frames;
    ++c.sequence;
    ++stats_.frames_lost;
    return;
  }
  const int index = c.queued.front();
  c.queued.pop_front();
  Camera::Buffer& b = c.buffers[static_cast<std::size_t>(index)];

  const int w = c.config.width;
  const int h = c.config.height;
  c.gray.create(h, w, CV_8UC1);
  c.config.content(frame, c.gray);
  std::uint8_t* base = b.memory->data();
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* g = c.gray.ptr<std::uint8_t>(y);
    std::uint8_t* line = base + static_cast<std::size_t>(y) * c.bytesperline;
    if (c.pixelformat == V4L2_PIX_FMT_GREY) {
      std::memcpy(line, g, static_cast<std::size_t>(w));
    } else {
      // YUYV: Y0 U Y1 V per pixel pair; U and V belong to the pair, taken at its first pixel.
      for (int x = 0; x + 1 < w; x += 2) {
        line[2 * x + 0] = g[x];
        line[2 * x + 1] = chromaAt(x, y);
        line[2 * x + 2] = g[x + 1];
        line[2 * x + 3] = static_cast<std::uint8_t>(255 - chromaAt(x, y));
      }
    }
    // Padding bytes are garbage to a reader: fill them with something that is not the image.
    std::memset(line + static_cast<std::size_t>(w * c.bytesPerPixel()), 0xA5,
                static_cast<std::size_t>(c.config.line_padding));
  }
  b.flags = 0;
  if (c.error_frames > 0) {
    --c.error_frames;
    b.flags = V4L2_BUF_FLAG_ERROR;
  }
  b.bytesused = c.sizeimage;
  if (c.short_frames > 0) {
    --c.short_frames;
    b.bytesused = c.sizeimage / 2;  // a transfer cut short
  }
  b.sequence = c.sequence++;
  b.time_ns = time_ns + c.config.timestamp_offset_ns;
  b.state = Camera::Buffer::State::kDone;
  c.done.push_back(index);
  ++stats_.frames_made;
}

sysio::SysResult EmulatedV4l2::open(const char* path, int flags) {
  std::lock_guard lock(mutex_);
  Camera* c = find(path);
  if (c != nullptr) c->open_attempts.push_back(sysio::monotonicNowNs());
  if (c == nullptr || !present(*c)) {
    ++stats_.failed_opens;
    return {-1, ENOENT};
  }
  if ((flags & O_ACCMODE) != O_RDWR) {
    ++stats_.failed_opens;
    return {-1, EINVAL};  // capture needs read-write for QBUF/DQBUF and the shared mapping
  }
  const int fd = next_fd_++;
  files_[fd] = OpenFile{c, c->generation, (flags & O_NONBLOCK) != 0};
  ++stats_.opens;
  return {fd, 0};
}

sysio::SysResult EmulatedV4l2::close(int fd) {
  std::lock_guard lock(mutex_);
  auto it = files_.find(fd);
  if (it == files_.end()) return {-1, EBADF};
  Camera& c = *it->second.camera;
  if (it->second.generation == c.generation && c.owner_fd == fd) resetQueue(c);
  files_.erase(it);
  changed_.notify_all();
  return {0, 0};
}

sysio::SysResult EmulatedV4l2::ioctl(int fd, unsigned long request, void* arg) {
  std::unique_lock lock(mutex_);
  ++stats_.ioctls;
  auto it = files_.find(fd);
  if (it == files_.end()) return {-1, EBADF};
  if (arg == nullptr) return {-1, EFAULT};
  OpenFile& f = it->second;
  if (const int err = fileError(&f); err != 0) return {-1, err};
  Camera& c = *f.camera;
  const bool owner_ok = c.owner_fd < 0 || c.owner_fd == fd;

  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      std::memset(cap, 0, sizeof(*cap));
      copyName(cap->driver, sizeof(cap->driver), "sunvo_emulated");
      copyName(cap->card, sizeof(cap->card), "emulated " + c.config.path);
      copyName(cap->bus_info, sizeof(cap->bus_info), "platform:sunvo-emulated");
      cap->version = (6U << 16) | (1U << 8);
      cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
      cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
      return {0, 0};
    }
    case VIDIOC_G_FMT:
    case VIDIOC_S_FMT:
    case VIDIOC_TRY_FMT: {
      auto* fmt = static_cast<v4l2_format*>(arg);
      if (fmt->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return {-1, EINVAL};
      if (request == VIDIOC_S_FMT) {
        if (!c.buffers.empty()) return {-1, EBUSY};
        c.setFormat(fmt->fmt.pix.pixelformat);
      }
      std::uint32_t pixelformat = c.pixelformat;
      std::uint32_t bytesperline = c.bytesperline;
      if (request == VIDIOC_TRY_FMT) {
        Camera probe;
        probe.config = c.config;
        probe.setFormat(fmt->fmt.pix.pixelformat);
        pixelformat = probe.pixelformat;
        bytesperline = probe.bytesperline;
      }
      // The sensor has one size: a driver adjusts the request to it.
      std::memset(&fmt->fmt.pix, 0, sizeof(fmt->fmt.pix));
      fmt->fmt.pix.width = static_cast<std::uint32_t>(c.config.width);
      fmt->fmt.pix.height = static_cast<std::uint32_t>(c.config.height);
      fmt->fmt.pix.pixelformat = pixelformat;
      fmt->fmt.pix.field = V4L2_FIELD_NONE;
      fmt->fmt.pix.bytesperline = bytesperline;
      fmt->fmt.pix.sizeimage = bytesperline * static_cast<std::uint32_t>(c.config.height);
      fmt->fmt.pix.colorspace = V4L2_COLORSPACE_SRGB;
      return {0, 0};
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto* parm = static_cast<v4l2_streamparm*>(arg);
      if (parm->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return {-1, EINVAL};
      const v4l2_fract asked = parm->parm.capture.timeperframe;
      if (request == VIDIOC_S_PARM && asked.numerator != 0 && asked.denominator != 0) {
        c.timeperframe = asked;
      }
      std::memset(&parm->parm, 0, sizeof(parm->parm));
      parm->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
      parm->parm.capture.timeperframe = c.timeperframe;
      return {0, 0};
    }
    case VIDIOC_REQBUFS: {
      auto* req = static_cast<v4l2_requestbuffers*>(arg);
      if (req->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || req->memory != V4L2_MEMORY_MMAP) {
        return {-1, EINVAL};
      }
      if (!owner_ok || c.streaming) return {-1, EBUSY};
      for (const auto& b : c.buffers) {
        if (b.mapped > 0) return {-1, EBUSY};
      }
      resetQueue(c);
      if (req->count == 0) return {0, 0};
      req->count = std::clamp(req->count, kMinBuffers, kMaxBuffers);
      c.buffer_stride = (c.sizeimage + kPage - 1) / kPage * kPage;
      c.buffers.resize(req->count);
      for (auto& b : c.buffers) {
        b.memory = std::make_shared<std::vector<std::uint8_t>>(c.sizeimage);
      }
      c.owner_fd = fd;
      c.sequence = 0;
      return {0, 0};
    }
    case VIDIOC_QUERYBUF:
    case VIDIOC_QBUF:
    case VIDIOC_DQBUF: {
      auto* buf = static_cast<v4l2_buffer*>(arg);
      if (buf->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return {-1, EINVAL};
      if (!owner_ok) return {-1, EBUSY};
      if (request == VIDIOC_DQBUF) {
        if (!c.streaming) return {-1, EINVAL};
        if (c.done.empty()) {
          if (f.nonblocking) return {-1, EAGAIN};
          const std::uint64_t gen = c.generation;
          changed_.wait(lock,
                        [&] { return !c.done.empty() || !c.streaming || c.generation != gen; });
          if (c.generation != gen) return {-1, ENODEV};
          if (!c.streaming) return {-1, EINVAL};
        }
        const int index = c.done.front();
        c.done.pop_front();
        Camera::Buffer& b = c.buffers[static_cast<std::size_t>(index)];
        b.state = Camera::Buffer::State::kUser;
        std::memset(buf, 0, sizeof(*buf));
        buf->index = static_cast<std::uint32_t>(index);
        buf->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf->memory = V4L2_MEMORY_MMAP;
        buf->bytesused = b.bytesused;
        buf->flags = b.flags | V4L2_BUF_FLAG_MAPPED | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC |
                     V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
        buf->field = V4L2_FIELD_NONE;
        buf->timestamp.tv_sec = b.time_ns / kNsPerSecond;
        buf->timestamp.tv_usec = (b.time_ns % kNsPerSecond) / 1000;
        buf->sequence = b.sequence;
        buf->length = c.sizeimage;
        buf->m.offset =
            static_cast<std::uint32_t>(static_cast<std::size_t>(index) * c.buffer_stride);
        return {0, 0};
      }
      if (buf->memory != V4L2_MEMORY_MMAP || buf->index >= c.buffers.size()) return {-1, EINVAL};
      Camera::Buffer& b = c.buffers[buf->index];
      if (request == VIDIOC_QBUF) {
        if (b.state != Camera::Buffer::State::kUser) return {-1, EINVAL};
        b.state = Camera::Buffer::State::kQueued;
        c.queued.push_back(static_cast<int>(buf->index));
        buf->flags = V4L2_BUF_FLAG_QUEUED | (b.mapped > 0 ? V4L2_BUF_FLAG_MAPPED : 0U);
        return {0, 0};
      }
      buf->length = c.sizeimage;
      buf->m.offset = static_cast<std::uint32_t>(buf->index * c.buffer_stride);
      buf->bytesused = b.state == Camera::Buffer::State::kDone ? b.bytesused : 0;
      buf->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | (b.mapped > 0 ? V4L2_BUF_FLAG_MAPPED : 0U) |
                   (b.state == Camera::Buffer::State::kQueued ? V4L2_BUF_FLAG_QUEUED : 0U) |
                   (b.state == Camera::Buffer::State::kDone ? V4L2_BUF_FLAG_DONE : 0U);
      buf->field = V4L2_FIELD_NONE;
      return {0, 0};
    }
    case VIDIOC_STREAMON:
    case VIDIOC_STREAMOFF: {
      if (*static_cast<int*>(arg) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return {-1, EINVAL};
      if (!owner_ok) return {-1, EBUSY};
      if (request == VIDIOC_STREAMON) {
        if (c.buffers.empty()) return {-1, EINVAL};
        if (!c.streaming) c.sequence = 0;
        c.streaming = true;
      } else {
        // Every buffer, queued or done, goes back to the user.
        c.streaming = false;
        for (auto& b : c.buffers) b.state = Camera::Buffer::State::kUser;
        c.queued.clear();
        c.done.clear();
        changed_.notify_all();
      }
      return {0, 0};
    }
    default:
      return {-1, ENOTTY};
  }
}

sysio::MapResult EmulatedV4l2::mmap(void* /*addr*/, std::size_t length, int prot, int flags, int fd,
                                    off_t offset) {
  std::lock_guard lock(mutex_);
  auto it = files_.find(fd);
  if (it == files_.end()) return {nullptr, EBADF};
  if (const int err = fileError(&it->second); err != 0) return {nullptr, err};
  Camera& c = *it->second.camera;
  if ((flags & MAP_SHARED) == 0 || (prot & PROT_READ) == 0 || c.buffers.empty() ||
      c.buffer_stride == 0 || offset < 0 ||
      static_cast<std::size_t>(offset) % c.buffer_stride != 0) {
    return {nullptr, EINVAL};
  }
  const std::size_t index = static_cast<std::size_t>(offset) / c.buffer_stride;
  if (index >= c.buffers.size() || length == 0 || length > c.sizeimage) return {nullptr, EINVAL};
  Camera::Buffer& b = c.buffers[index];
  ++b.mapped;
  void* addr = b.memory->data();
  // One mapping per buffer and address: a second map of the same buffer is refused.
  if (mappings_.count(addr) != 0) {
    --b.mapped;
    return {nullptr, EEXIST};
  }
  mappings_[addr] = Mapping{&c, static_cast<int>(index), length, b.memory};
  return {addr, 0};
}

sysio::SysResult EmulatedV4l2::munmap(void* addr, std::size_t length) {
  std::lock_guard lock(mutex_);
  auto it = mappings_.find(addr);
  if (it == mappings_.end() || it->second.length != length) return {-1, EINVAL};
  Camera& c = *it->second.camera;
  const auto index = static_cast<std::size_t>(it->second.index);
  if (index < c.buffers.size() && c.buffers[index].memory == it->second.memory) {
    --c.buffers[index].mapped;
  }
  mappings_.erase(it);
  return {0, 0};
}

sysio::SysResult EmulatedV4l2::poll(pollfd* fds, nfds_t nfds, int timeout_ms) {
  std::unique_lock lock(mutex_);
  ++stats_.polls;
  if (timeout_ms > 0) stats_.waited_ms += static_cast<std::uint64_t>(timeout_ms);
  if (nfds == 0) {
    ++stats_.sleeps;
    lock.unlock();
    if (timeout_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));
    return {0, 0};
  }
  auto scan = [&] {
    long ready = 0;
    for (nfds_t i = 0; i < nfds; ++i) {
      pollfd& p = fds[i];
      p.revents = 0;
      auto it = files_.find(p.fd);
      if (it == files_.end()) {
        p.revents = POLLNVAL;
      } else if (fileError(&it->second) != 0) {
        p.revents = POLLERR | POLLHUP;
      } else {
        const Camera& c = *it->second.camera;
        if (!c.streaming || c.owner_fd != p.fd) {
          p.revents = POLLERR;
        } else if (!c.done.empty()) {
          p.revents = static_cast<short>(p.events & (POLLIN | POLLRDNORM));
        }
      }
      if (p.revents != 0) ++ready;
    }
    return ready;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const long ready = scan();
    if (ready > 0 || timeout_ms == 0) return {ready, 0};
    if (timeout_ms < 0) {
      changed_.wait(lock);
    } else if (changed_.wait_until(lock, deadline) == std::cv_status::timeout) {
      return {scan(), 0};
    }
  }
}

// The chroma the emulator writes into YUYV frames: varies with x and y so that a converter that
// mixes chroma into the gray image is caught.
std::uint8_t yuyvChroma(int x, int y) {
  return static_cast<std::uint8_t>((x * 7 + y * 3) & 0xff);
}

}  // namespace sunvo::emulated
