#include "sunvo/runtime/latency_profiler.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <fstream>

#include "sunvo/metrics/metrics.hpp"

namespace sunvo::runtime {
namespace {

std::size_t roundUpPow2(std::size_t n) {
  std::size_t c = 2;
  while (c < n) c <<= 1;
  return c;
}

TimeNs stampOf(const FrameStamps& f, Stamp s) {
  return f.t[static_cast<std::size_t>(s)];
}

}  // namespace

const std::vector<StageSpan>& stageSpans() {
  static const std::vector<StageSpan> spans = {
      {"grab", Stamp::kTrigger, Stamp::kGrabEnd, 1},
      {"queue", Stamp::kGrabEnd, Stamp::kEstimatorStart, 2},
      {"frontend", Stamp::kEstimatorStart, Stamp::kFrontendEnd, 2},
      {"ransac", Stamp::kFrontendEnd, Stamp::kRansacEnd, 2},
      {"window", Stamp::kRansacEnd, Stamp::kWindowEnd, 2},
      {"sun", Stamp::kSunStart, Stamp::kSunEnd, 3},
      {"publish", Stamp::kWindowEnd, Stamp::kLastByte, 4},
      {"trigger_to_serial", Stamp::kTrigger, Stamp::kLastByte, 0},
  };
  return spans;
}

LatencyProfiler::LatencyProfiler(std::size_t ring_frames)
    : capacity_(roundUpPow2(ring_frames)), records_(std::make_unique<Record[]>(capacity_)) {}

void LatencyProfiler::begin(std::uint64_t sequence, TimeNs utc_ns, TimeNs trigger_mono_ns) {
  Record& r = at(sequence);
  r.tag.store(0, std::memory_order_relaxed);  // invalid while it is being cleared
  for (auto& t : r.t) t.store(0, std::memory_order_relaxed);
  r.budget_ms.store(0.0F, std::memory_order_relaxed);
  r.utc_ns.store(utc_ns, std::memory_order_relaxed);
  r.t[static_cast<std::size_t>(Stamp::kTrigger)].store(trigger_mono_ns, std::memory_order_relaxed);
  r.tag.store(sequence + 1, std::memory_order_release);
}

void LatencyProfiler::stamp(std::uint64_t sequence, Stamp s, TimeNs mono_ns) {
  Record& r = at(sequence);
  if (r.tag.load(std::memory_order_acquire) != sequence + 1) return;
  r.t[static_cast<std::size_t>(s)].store(mono_ns, std::memory_order_release);
}

void LatencyProfiler::setSolverBudget(std::uint64_t sequence, double ms) {
  Record& r = at(sequence);
  if (r.tag.load(std::memory_order_acquire) != sequence + 1) return;
  r.budget_ms.store(static_cast<float>(ms), std::memory_order_relaxed);
}

std::vector<FrameStamps> LatencyProfiler::snapshot() const {
  std::vector<FrameStamps> out;
  out.reserve(capacity_);
  for (std::size_t i = 0; i < capacity_; ++i) {
    const Record& r = records_[i];
    const std::uint64_t tag = r.tag.load(std::memory_order_acquire);
    if (tag == 0) continue;
    FrameStamps f;
    f.sequence = tag - 1;
    f.utc_ns = r.utc_ns.load(std::memory_order_relaxed);
    f.solver_budget_ms = r.budget_ms.load(std::memory_order_relaxed);
    for (std::size_t k = 0; k < f.t.size(); ++k) f.t[k] = r.t[k].load(std::memory_order_acquire);
    // Reused by a newer frame while it was read, or not complete yet: left out.
    if (r.tag.load(std::memory_order_acquire) != tag) continue;
    if (stampOf(f, Stamp::kTrigger) == 0 || stampOf(f, Stamp::kLastByte) == 0) continue;
    out.push_back(f);
  }
  std::sort(out.begin(), out.end(),
            [](const FrameStamps& a, const FrameStamps& b) { return a.sequence < b.sequence; });
  return out;
}

std::vector<StageSummary> LatencyProfiler::summarize(const std::vector<FrameStamps>& frames) {
  std::vector<StageSummary> out;
  for (const StageSpan& span : stageSpans()) {
    std::vector<double> ms;
    ms.reserve(frames.size());
    for (const FrameStamps& f : frames) {
      const TimeNs a = stampOf(f, span.from), b = stampOf(f, span.to);
      if (a != 0 && b != 0 && b >= a) ms.push_back(static_cast<double>(b - a) * 1e-6);
    }
    StageSummary s;
    s.name = span.name;
    s.count = ms.size();
    if (!ms.empty()) {
      s.p50_ms = metrics::percentile(ms, 0.50);
      s.p95_ms = metrics::percentile(ms, 0.95);
      s.p99_ms = metrics::percentile(ms, 0.99);
      s.max_ms = *std::max_element(ms.begin(), ms.end());
    }
    out.push_back(s);
  }
  return out;
}

std::string LatencyProfiler::formatSummary(const std::vector<StageSummary>& summary) {
  std::string out = "stage                  n      p50 ms   p95 ms   p99 ms   max ms\n";
  char line[160];
  for (const StageSummary& s : summary) {
    std::snprintf(line, sizeof(line), "%-18s %6zu %9.2f %8.2f %8.2f %8.2f\n", s.name.c_str(),
                  s.count, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms);
    out += line;
  }
  return out;
}

Status LatencyProfiler::writeCsv(const std::string& path, const std::vector<FrameStamps>& frames) {
  std::ofstream out(path);
  if (!out) return ioError(path + ": cannot open for writing");
  out << "sequence,utc_ns,trigger_ns,grab_end_ns,estimator_start_ns,frontend_end_ns,ransac_end_ns,"
         "window_end_ns,sun_start_ns,sun_end_ns,publish_start_ns,last_byte_ns,solver_budget_ms,"
         "trigger_to_serial_ms\n";
  for (const FrameStamps& f : frames) {
    out << f.sequence << ',' << f.utc_ns;
    for (TimeNs t : f.t) out << ',' << t;
    char tail[64];
    std::snprintf(
        tail, sizeof(tail), ",%.3f,%.4f\n", static_cast<double>(f.solver_budget_ms),
        static_cast<double>(stampOf(f, Stamp::kLastByte) - stampOf(f, Stamp::kTrigger)) * 1e-6);
    out << tail;
  }
  out.flush();
  if (!out) return ioError(path + ": write failed");
  return Status::ok();
}

Status LatencyProfiler::writeChromeTrace(const std::string& path,
                                         const std::vector<FrameStamps>& frames) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return ioError(path + ": cannot open for writing");
  const TimeNs t0 = frames.empty() ? 0 : stampOf(frames.front(), Stamp::kTrigger);
  std::fprintf(f, "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n");
  const char* names[] = {"", "capture", "estimator", "sun", "telemetry"};
  for (int tid = 1; tid <= 4; ++tid) {
    std::fprintf(f,
                 "%s{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":%d,"
                 "\"args\":{\"name\":\"%s\"}}",
                 tid == 1 ? "" : ",\n", tid, names[tid]);
  }
  for (const FrameStamps& fr : frames) {
    for (const StageSpan& span : stageSpans()) {
      if (span.tid == 0) continue;
      const TimeNs a = stampOf(fr, span.from), b = stampOf(fr, span.to);
      if (a == 0 || b == 0 || b < a) continue;
      std::fprintf(f,
                   "%s{\"name\":\"%s\",\"cat\":\"frame\",\"ph\":\"X\",\"pid\":1,\"tid\":%d,"
                   "\"ts\":%.3f,\"dur\":%.3f,\"args\":{\"sequence\":%" PRIu64 "}}",
                   ",\n", span.name, span.tid, static_cast<double>(a - t0) * 1e-3,
                   static_cast<double>(b - a) * 1e-3, fr.sequence);
    }
  }
  std::fprintf(f, "\n]}\n");
  const bool ok = std::ferror(f) == 0;
  if (std::fclose(f) != 0 || !ok) return ioError(path + ": write failed");
  return Status::ok();
}

}  // namespace sunvo::runtime
