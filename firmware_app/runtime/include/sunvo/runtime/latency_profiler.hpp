#pragma once
// Per-frame stage timestamps of the running program in a fixed ring (allocated at start-up), and
// their reports: a CSV, a Chrome trace (JSON "traceEvents", complete events "ph":"X" with ts and
// dur in µs, one tid per thread; chrome://tracing and Perfetto open it) and p50/p95/p99/max per
// stage.
//
// Each frame has one record, indexed by sequence modulo the ring size. The capture thread opens
// it with begin() (trigger time); every other thread writes its own stamps with stamp(), which
// is ignored when the record was already reused by a newer frame. Fields are relaxed atomics:
// stamping is wait-free and allocation-free, and a report taken while frames are in flight reads
// consistent values (incomplete frames are left out). Reports allocate; they run on the main
// thread at exit or on SIGUSR1.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::runtime {

// Monotonic ns stamps of one frame, in the order they happen.
enum class Stamp : int {
  kTrigger = 0,     // exposure trigger (capture thread: trigger event)
  kGrabEnd,         // images in the pool slot (capture)
  kEstimatorStart,  // dequeued by the estimator
  kFrontendEnd,     // front end done (estimator)
  kRansacEnd,       // association + RANSAC done (estimator)
  kWindowEnd,       // Ceres window done (estimator)
  kSunStart,        // sun thread: ephemeris + measurement (every n-th frame only)
  kSunEnd,
  kPublishStart,  // telemetry thread dequeued the pose
  kLastByte,      // the last byte of the pose's ODOMETRY frame written to the port
  kCount
};

// Named spans the reports show, each between two stamps, on one thread.
struct StageSpan {
  const char* name;
  Stamp from;
  Stamp to;
  int tid;  // 1 capture, 2 estimator, 3 sun, 4 telemetry, 0 = end to end (not a trace event)
};
const std::vector<StageSpan>& stageSpans();

struct StageSummary {
  std::string name;
  std::size_t count = 0;
  double p50_ms = 0.0, p95_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
};

struct FrameStamps {
  std::uint64_t sequence = 0;
  TimeNs utc_ns = 0;
  float solver_budget_ms = 0.0F;  // the window's time budget for this frame
  std::array<TimeNs, static_cast<int>(Stamp::kCount)> t{};  // 0 = not stamped
};

class LatencyProfiler {
 public:
  // ring_frames: a power of two >= 2 (rounded up).
  explicit LatencyProfiler(std::size_t ring_frames);

  void begin(std::uint64_t sequence, TimeNs utc_ns, TimeNs trigger_mono_ns);
  void stamp(std::uint64_t sequence, Stamp s, TimeNs mono_ns);
  void setSolverBudget(std::uint64_t sequence, double ms);

  // Complete frames (trigger and last byte stamped) currently in the ring, by sequence.
  std::vector<FrameStamps> snapshot() const;

  static std::vector<StageSummary> summarize(const std::vector<FrameStamps>& frames);
  // "stage  n  p50  p95  p99  max" lines, ms.
  static std::string formatSummary(const std::vector<StageSummary>& summary);
  static Status writeCsv(const std::string& path, const std::vector<FrameStamps>& frames);
  // ts relative to the first trigger in the list.
  static Status writeChromeTrace(const std::string& path, const std::vector<FrameStamps>& frames);

  std::size_t capacity() const { return capacity_; }

 private:
  struct Record {
    std::atomic<std::uint64_t> tag{0};  // sequence + 1 of the frame in this record, 0 = empty
    std::atomic<TimeNs> utc_ns{0};
    std::atomic<float> budget_ms{0.0F};
    std::array<std::atomic<TimeNs>, static_cast<int>(Stamp::kCount)> t{};
  };
  Record& at(std::uint64_t sequence) { return records_[sequence & (capacity_ - 1)]; }

  std::size_t capacity_;
  std::unique_ptr<Record[]> records_;
};

}  // namespace sunvo::runtime
