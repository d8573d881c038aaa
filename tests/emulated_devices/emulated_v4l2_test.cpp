// EmulatedV4l2 follows the kernel's V4L2/videobuf2 semantics for the calls the driver makes:
// format negotiation, buffer ownership and states, streaming, poll, unplug, lost frames.

#include "sunvo/emulated/emulated_v4l2.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <chrono>
#include <thread>

namespace sunvo::emulated {
namespace {

const std::string kPath = "/dev/video3";

class EmulatedV4l2Test : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(emu_.addCamera({kPath, 64, 16, true, true, 0, 0, {}}).isOk());
    const sysio::SysResult r = emu_.open(kPath.c_str(), O_RDWR | O_NONBLOCK);
    ASSERT_TRUE(r.ok());
    fd_ = static_cast<int>(r.value);
  }
  sysio::SysResult io(unsigned long request, void* arg) { return emu_.ioctl(fd_, request, arg); }
  sysio::SysResult requestBuffers(std::uint32_t count) {
    v4l2_requestbuffers req{};
    req.count = count;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    const sysio::SysResult r = io(VIDIOC_REQBUFS, &req);
    granted_ = req.count;
    return r;
  }
  sysio::SysResult buffer(unsigned long request, std::uint32_t index, v4l2_buffer* out = nullptr) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    const sysio::SysResult r = io(request, &buf);
    if (out != nullptr) *out = buf;
    return r;
  }
  sysio::SysResult stream(unsigned long request) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    return io(request, &type);
  }

  EmulatedV4l2 emu_;
  int fd_ = -1;
  std::uint32_t granted_ = 0;
};

TEST_F(EmulatedV4l2Test, FormatIsAdjustedToWhatTheSensorGives) {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = 640;
  fmt.fmt.pix.height = 480;
  fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  ASSERT_TRUE(io(VIDIOC_S_FMT, &fmt).ok());
  EXPECT_EQ(fmt.fmt.pix.width, 64u);
  EXPECT_EQ(fmt.fmt.pix.height, 16u);
  EXPECT_EQ(fmt.fmt.pix.pixelformat, V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(fmt.fmt.pix.bytesperline, 128u);
  EXPECT_EQ(fmt.fmt.pix.sizeimage, 128u * 16u);
  fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_MJPEG;  // not offered: the default comes back
  ASSERT_TRUE(io(VIDIOC_S_FMT, &fmt).ok());
  EXPECT_EQ(fmt.fmt.pix.pixelformat, V4L2_PIX_FMT_GREY);
  fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  EXPECT_EQ(io(VIDIOC_S_FMT, &fmt).err, EINVAL);
  v4l2_capability cap{};
  ASSERT_TRUE(io(VIDIOC_QUERYCAP, &cap).ok());
  EXPECT_NE(cap.device_caps & V4L2_CAP_STREAMING, 0u);
  int dummy = 0;
  EXPECT_EQ(io(VIDIOC_ENUMINPUT, &dummy).err, ENOTTY);
}

TEST_F(EmulatedV4l2Test, BufferRequestsFollowVideobuf2) {
  ASSERT_TRUE(requestBuffers(1).ok());
  EXPECT_EQ(granted_, 2u);  // clamped up to the minimum
  ASSERT_TRUE(requestBuffers(100).ok());
  EXPECT_EQ(granted_, 32u);
  v4l2_requestbuffers user{};
  user.count = 4;
  user.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  user.memory = V4L2_MEMORY_USERPTR;
  EXPECT_EQ(io(VIDIOC_REQBUFS, &user).err, EINVAL);
  ASSERT_TRUE(requestBuffers(4).ok());
  // Another file of the same device does not own the queue.
  const sysio::SysResult other = emu_.open(kPath.c_str(), O_RDWR);
  ASSERT_TRUE(other.ok());
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  EXPECT_EQ(emu_.ioctl(static_cast<int>(other.value), VIDIOC_QBUF, &buf).err, EBUSY);
  EXPECT_TRUE(emu_.close(static_cast<int>(other.value)).ok());
  // The format cannot change under allocated buffers; mapped buffers cannot be freed.
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(io(VIDIOC_S_FMT, &fmt).err, EBUSY);
  v4l2_buffer q{};
  ASSERT_TRUE(buffer(VIDIOC_QUERYBUF, 1, &q).ok());
  EXPECT_EQ(buffer(VIDIOC_QUERYBUF, 4).err, EINVAL);
  const sysio::MapResult m =
      emu_.mmap(nullptr, q.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, q.m.offset);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(emu_.mmap(nullptr, q.length, PROT_READ, MAP_SHARED, fd_, q.m.offset + 1).err, EINVAL);
  EXPECT_EQ(requestBuffers(0).err, EBUSY);
  EXPECT_TRUE(emu_.munmap(m.addr, q.length).ok());
  EXPECT_EQ(emu_.munmap(m.addr, q.length).err, EINVAL);
  EXPECT_TRUE(requestBuffers(0).ok());
}

TEST_F(EmulatedV4l2Test, QueueStreamDequeueAndPoll) {
  ASSERT_TRUE(requestBuffers(2).ok());
  pollfd p{fd_, POLLIN, 0};
  ASSERT_TRUE(emu_.poll(&p, 1, 0).ok());
  EXPECT_EQ(p.revents, POLLERR);  // not streaming
  EXPECT_EQ(buffer(VIDIOC_DQBUF, 0).err, EINVAL);
  EXPECT_EQ(stream(VIDIOC_STREAMON).ok(), true);
  ASSERT_TRUE(buffer(VIDIOC_QBUF, 0).ok());
  EXPECT_EQ(buffer(VIDIOC_QBUF, 0).err, EINVAL);  // already queued
  EXPECT_EQ(buffer(VIDIOC_DQBUF, 0).err, EAGAIN);
  EXPECT_EQ(emu_.poll(&p, 1, 0).value, 0);

  emu_.trigger(5'000'123'456);
  ASSERT_EQ(emu_.poll(&p, 1, 0).value, 1);
  EXPECT_EQ(p.revents, POLLIN);
  v4l2_buffer b{};
  ASSERT_TRUE(buffer(VIDIOC_DQBUF, 0, &b).ok());
  EXPECT_EQ(b.index, 0u);
  EXPECT_EQ(b.sequence, 0u);
  EXPECT_EQ(b.bytesused, 64u * 16u);
  EXPECT_EQ(b.timestamp.tv_sec, 5);
  EXPECT_EQ(b.timestamp.tv_usec, 123);
  EXPECT_NE(b.flags & V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC, 0u);

  // No buffer queued: the sensor's frame is lost but counted by the sequence.
  emu_.trigger(5'100'000'000);
  ASSERT_TRUE(buffer(VIDIOC_QBUF, 0).ok());
  ASSERT_TRUE(emu_.injectBufferErrors(kPath, 1).isOk());
  emu_.trigger(5'200'000'000);
  ASSERT_TRUE(buffer(VIDIOC_DQBUF, 0, &b).ok());
  EXPECT_EQ(b.sequence, 2u);
  EXPECT_NE(b.flags & V4L2_BUF_FLAG_ERROR, 0u);
  EXPECT_EQ(emu_.stats().frames_lost, 1u);

  // STREAMOFF hands every buffer back: both can be queued again.
  ASSERT_TRUE(buffer(VIDIOC_QBUF, 0).ok());
  ASSERT_TRUE(stream(VIDIOC_STREAMOFF).ok());
  EXPECT_TRUE(buffer(VIDIOC_QBUF, 0).ok());
  EXPECT_TRUE(buffer(VIDIOC_QBUF, 1).ok());
}

TEST_F(EmulatedV4l2Test, PollWaitsForATriggerFromAnotherThread) {
  ASSERT_TRUE(requestBuffers(2).ok());
  ASSERT_TRUE(buffer(VIDIOC_QBUF, 0).ok());
  ASSERT_TRUE(stream(VIDIOC_STREAMON).ok());
  std::thread camera([this] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    emu_.trigger(1);
  });
  pollfd p{fd_, POLLIN, 0};
  const sysio::SysResult r = emu_.poll(&p, 1, 2000);
  camera.join();
  EXPECT_EQ(r.value, 1);
  EXPECT_EQ(p.revents, POLLIN);
}

TEST_F(EmulatedV4l2Test, UnpluggedDeviceFailsUntilItReturns) {
  ASSERT_TRUE(requestBuffers(2).ok());
  ASSERT_TRUE(stream(VIDIOC_STREAMON).ok());
  ASSERT_TRUE(emu_.unplug(kPath, std::chrono::milliseconds(40)).isOk());
  pollfd p{fd_, POLLIN, 0};
  ASSERT_EQ(emu_.poll(&p, 1, 0).value, 1);
  EXPECT_EQ(p.revents, POLLERR | POLLHUP);
  EXPECT_EQ(buffer(VIDIOC_QBUF, 0).err, ENODEV);
  EXPECT_EQ(emu_.open(kPath.c_str(), O_RDWR).err, ENOENT);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  // Back: the old file stays dead, a new one works.
  EXPECT_EQ(buffer(VIDIOC_QBUF, 0).err, ENODEV);
  const sysio::SysResult again = emu_.open(kPath.c_str(), O_RDWR);
  ASSERT_TRUE(again.ok());
  v4l2_capability cap{};
  EXPECT_TRUE(emu_.ioctl(static_cast<int>(again.value), VIDIOC_QUERYCAP, &cap).ok());
  EXPECT_TRUE(emu_.close(static_cast<int>(again.value)).ok());
  EXPECT_TRUE(emu_.close(fd_).ok());
  EXPECT_EQ(emu_.close(fd_).err, EBADF);
  EXPECT_EQ(emu_.openAttempts(kPath).size(), 3u);
}

}  // namespace
}  // namespace sunvo::emulated
