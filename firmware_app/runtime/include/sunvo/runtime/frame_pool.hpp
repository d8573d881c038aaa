#pragma once
// The stereo frames of the running program, allocated once at start-up. Queues carry a slot's
// index, never the images.
//
// Ownership: one thread (capture) takes free slots with acquire() and hands them on; the thread
// that is done with a slot (estimator) gives it back with release(), through a lock-free return
// ring that can hold every slot (it never drops). The capture thread puts a slot it got back from
// a drop-oldest queue straight back with recycle(). No allocation after create().

#include <cstdint>
#include <memory>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/runtime/spsc_queue.hpp"

namespace sunvo::runtime {

struct FramePoolOptions {
  int width = 1242;    // px, [16, 8192]: image width
  int height = 375;    // px, [16, 8192]: image height
  int pool_depth = 8;  // slots, [2, 256]: frames alive at once (queued + in use)
  bool color = false;  // also a CV_8UC3 left/right colour pair per slot (set by the program)
  Status validate() const;
  template <class Self, class V>
  static void fields(Self& s, V& v) {
    v("width", s.width);
    v("height", s.height);
    v("pool_depth", s.pool_depth);
  }
};

// Data about one frame besides its images.
struct FrameMeta {
  std::uint64_t sequence = 0;     // trigger sequence (monotonically increasing)
  std::int64_t source_index = 0;  // frame index in the recording / the camera's own counter
  TimeNs trigger_utc_ns = 0;      // UTC ns of the exposure trigger
  TimeNs trigger_mono_ns = 0;     // monotonic ns of the trigger
  TimeNs grab_mono_ns = 0;        // monotonic ns when the images were in the slot
};

struct FrameSlot {
  StereoFrame frame;  // Mats allocated at create(), reused for every frame
  FrameMeta meta;
};

class FramePool {
 public:
  static Expected<std::unique_ptr<FramePool>> create(const FramePoolOptions& options);

  // Capture thread: a free slot, or false when every slot is queued or in use.
  bool acquire(std::uint32_t* index);
  // Capture thread: a slot it owns again (e.g. dropped from a drop-oldest queue).
  void recycle(std::uint32_t index);
  // Consumer thread: gives a slot back to the capture thread.
  void release(std::uint32_t index);

  FrameSlot& slot(std::uint32_t index) { return slots_[index]; }
  std::size_t depth() const { return slots_.size(); }
  std::size_t freeCount() const { return free_count_ + returns_.size(); }
  const FramePoolOptions& options() const { return options_; }

 private:
  explicit FramePool(const FramePoolOptions& options);

  FramePoolOptions options_;
  std::vector<FrameSlot> slots_;
  std::vector<std::uint32_t> free_;  // capture thread's stack, capacity depth
  std::size_t free_count_ = 0;
  SpscQueue<std::uint32_t> returns_;
};

}  // namespace sunvo::runtime
