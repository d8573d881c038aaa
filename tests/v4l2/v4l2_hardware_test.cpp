// V4l2StereoSource on a real /dev/video0 through the real syscalls; skipped when there is none
// (CI machines have no cameras). The device is treated as one side-by-side camera at its current
// size if it delivers GREY or YUYV.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/stat.h>

#include "sunvo/sysio/sysio.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace sunvo::v4l2 {
namespace {

TEST(V4l2Hardware, StreamsFromVideo0WhenPresent) {
  const char* path = "/dev/video0";
  struct stat st {};
  if (::stat(path, &st) != 0 || !S_ISCHR(st.st_mode)) GTEST_SKIP() << "no " << path;
  sysio::SysIo& io = sysio::linuxSysIo();
  const sysio::SysResult fd = io.open(path, O_RDWR | O_NONBLOCK);
  if (!fd.ok()) GTEST_SKIP() << path << " cannot be opened (errno " << fd.err << ")";
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  const sysio::SysResult g = sysio::ioctlRetry(io, static_cast<int>(fd.value), VIDIOC_G_FMT, &fmt);
  (void)io.close(static_cast<int>(fd.value));
  if (!g.ok()) GTEST_SKIP() << path << " is no capture device (VIDIOC_G_FMT errno " << g.err << ")";
  const std::uint32_t pf = fmt.fmt.pix.pixelformat;
  if ((pf != V4L2_PIX_FMT_GREY && pf != V4L2_PIX_FMT_YUYV) || fmt.fmt.pix.width % 4 != 0) {
    GTEST_SKIP() << path << " delivers neither GREY nor YUYV at a width divisible by 4";
  }

  V4l2Options o;
  o.layout = V4l2Layout::kSideBySide;
  o.left_device = path;
  o.pixel_format = pf == V4L2_PIX_FMT_GREY ? V4l2PixelFormat::kGrey : V4l2PixelFormat::kYuyv;
  o.width = static_cast<int>(fmt.fmt.pix.width / 2);
  o.height = static_cast<int>(fmt.fmt.pix.height);
  o.fps = 10.0;
  o.dequeue_timeout_ms = 2000;
  auto source = V4l2StereoSource::open(o, io);
  ASSERT_TRUE(source.hasValue()) << source.status().toString();
  StereoFrame frame;
  int delivered = 0;
  for (int i = 0; i < 10; ++i) {
    const Status s = (*source)->next(frame);
    if (s.isOk()) ++delivered;
  }
  if (delivered == 0) GTEST_SKIP() << path << " streams no frames (an external trigger?)";
  EXPECT_EQ(frame.left.cols, o.width);
  EXPECT_EQ(frame.left.rows, o.height);
  EXPECT_EQ((*source)->counters().frames, static_cast<std::uint64_t>(delivered));
}

}  // namespace
}  // namespace sunvo::v4l2
