#pragma once
// The rover's pose log (telemetry.pose_log): every pose the telemetry thread publishes, one TUM
// line each,
//   t tx ty tz qx qy qz qw
// t the frame's UTC time in s (exact to the ns), (tx, ty, tz) the camera position in the world
// (ENU, m), (qx, qy, qz, qw) C_w_c as a unit quaternion: what sunvo_eval and evo read, to evaluate
// a field run afterwards. The file is opened once at start-up and appended to; each start first
// writes one '#' comment line (readers of TUM files skip them).
//
// Real time: open() allocates the line buffer once. append() formats into it (snprintf into a
// fixed buffer, no allocation) and calls write(2) only when the buffer cannot take another line;
// flush() writes what is buffered (the telemetry thread calls it about once a second, so a crash
// loses at most that much); the destructor flushes and closes.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/rover/pose_link.hpp"

namespace sunvo::rover {

class TumPoseLog {
 public:
  // Longest line append() writes, bytes (a time of 20 digits, 7 numbers of at most 24 chars).
  static constexpr std::size_t kMaxLineBytes = 256;

  // Opens `path` for appending (created 0644 if missing) and buffers `header` as a comment line.
  // buffer_bytes: the line buffer, >= kMaxLineBytes. Errors name the path.
  static Expected<std::unique_ptr<TumPoseLog>> open(const std::string& path,
                                                    std::size_t buffer_bytes,
                                                    const std::string& header);
  ~TumPoseLog();
  TumPoseLog(const TumPoseLog&) = delete;
  TumPoseLog& operator=(const TumPoseLog&) = delete;

  // Adds the pose's line; an error names the path and the errno of a failed write (the line is
  // kept in the buffer only if it fits).
  Status append(const PoseRecord& pose);
  // Writes everything buffered.
  Status flush();

  const std::string& path() const { return path_; }
  // Pose lines appended (any thread may read it).
  std::uint64_t lines() const { return lines_.load(std::memory_order_relaxed); }

 private:
  TumPoseLog(std::string path, int fd, std::size_t buffer_bytes);

  std::string path_;
  int fd_ = -1;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::atomic<std::uint64_t> lines_{0};
};

}  // namespace sunvo::rover
