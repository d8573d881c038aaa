#include "sunvo/rover/pose_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>

namespace sunvo::rover {

Expected<std::unique_ptr<TumPoseLog>> TumPoseLog::open(const std::string& path,
                                                       std::size_t buffer_bytes,
                                                       const std::string& header) {
  if (buffer_bytes < kMaxLineBytes) {
    return invalidArgument("pose log buffer: " + std::to_string(buffer_bytes) +
                           " bytes, needs at least " + std::to_string(kMaxLineBytes));
  }
  if (header.find('\n') != std::string::npos || header.size() + 3 > buffer_bytes) {
    return invalidArgument("pose log header: one line shorter than the buffer");
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return ioError(path + ": cannot open for appending: " + std::strerror(errno));
  std::unique_ptr<TumPoseLog> log(new TumPoseLog(path, fd, buffer_bytes));
  const int n = std::snprintf(log->buffer_.data(), log->buffer_.size(), "# %s\n", header.c_str());
  log->used_ = static_cast<std::size_t>(n);
  return log;
}

TumPoseLog::TumPoseLog(std::string path, int fd, std::size_t buffer_bytes)
    : path_(std::move(path)), fd_(fd), buffer_(buffer_bytes) {}

TumPoseLog::~TumPoseLog() {
  (void)flush();  // nobody to report to; the telemetry thread flushes (and counts errors) first
  ::close(fd_);
}

Status TumPoseLog::flush() {
  std::size_t done = 0;
  Status status = Status::ok();
  while (done < used_) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, used_ - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      status = ioError(path_ + ": write failed: " + (n < 0 ? std::strerror(errno) : "no progress"));
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  // What was written leaves the buffer; what failed stays for the next try.
  std::memmove(buffer_.data(), buffer_.data() + done, used_ - done);
  used_ -= done;
  return status;
}

Status TumPoseLog::append(const PoseRecord& pose) {
  Status status = Status::ok();
  if (buffer_.size() - used_ < kMaxLineBytes) status = flush();
  if (buffer_.size() - used_ < kMaxLineBytes) return status;  // still full: this pose is lost
  if (pose.utc_ns < 0) {
    return invalidArgument(path_ + ": pose " + std::to_string(pose.sequence) + " before 1970");
  }
  // Seconds and nanoseconds as integers: a double holds UTC seconds to about 0.2 us only.
  const std::int64_t s = pose.utc_ns / 1'000'000'000;
  const std::int64_t ns = pose.utc_ns % 1'000'000'000;
  const int n = std::snprintf(buffer_.data() + used_, kMaxLineBytes,
                              "%" PRId64 ".%09" PRId64 " %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", s,
                              ns, pose.p_w[0], pose.p_w[1], pose.p_w[2], pose.q_w_c[0],
                              pose.q_w_c[1], pose.q_w_c[2], pose.q_w_c[3]);
  if (n < 0 || static_cast<std::size_t>(n) >= kMaxLineBytes) {
    return invalidArgument(path_ + ": pose " + std::to_string(pose.sequence) +
                           " does not fit a line (position out of range)");
  }
  used_ += static_cast<std::size_t>(n);
  lines_.fetch_add(1, std::memory_order_relaxed);
  return status;
}

}  // namespace sunvo::rover
