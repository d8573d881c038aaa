// Vertical-cue benchmark on real KITTI images: the left images of the 11 frames of
// 00_first_frames played forward and backward, the cue (estimator/vertical) with a level prior,
// once with each segment detector: the default edge chains and, as the baseline, OpenCV's LSD.
// Single-threaded (cv::setNumThreads(0)). Prints per-call CPU and wall percentiles, heap
// allocations per call after a warm-up, the valid share, and the ratio edge chains / LSD.
//
// Usage: sunvo_bench_vertical [--frames=N] [--warmup=N] [--data=DIR] [--cpu=K] [--benchmark_*]

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "sunvo/bench/bench_support.hpp"
#include "sunvo/bench/benchmark_cli.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/runtime/alloc_counter.hpp"
#include "sunvo/vertical/vertical_estimator.hpp"

namespace {

using sunvo::bench::percentile;
using sunvo::bench::pingPong;
using sunvo::bench::threadCpuMs;
using sunvo::vertical::SegmentDetector;

struct Results {
  std::vector<double> cpu_ms, wall_ms;
  std::vector<std::uint64_t> allocs;
  int valid = 0;
  bool ok = false;
};

sunvo::bench::BenchConfig g_config;
sunvo::bench::KittiFrames g_sample;
Results g_results[2];  // [0] edge chains, [1] LSD

void benchVertical(benchmark::State& state, SegmentDetector detector) {
  Results& r = g_results[detector == SegmentDetector::kLsd ? 1 : 0];
  sunvo::vertical::VerticalOptions options;
  options.detector = detector;
  sunvo::vertical::VerticalEstimator estimator;
  if (const sunvo::Status s = estimator.init(options, g_sample.camera); !s.isOk()) {
    state.SkipWithError(s.toString().c_str());
    return;
  }
  const Eigen::Vector3d level(0.0, -1.0, 0.0);
  const std::size_t n = g_sample.frames.size();
  std::size_t frame = 0;
  for (int i = 0; i < g_config.warmup; ++i, ++frame) {
    if (!estimator.estimate(g_sample.frames[pingPong(frame, n)].left, level)) {
      state.SkipWithError("estimate failed in warm-up");
      return;
    }
  }
  const auto frames = static_cast<std::size_t>(g_config.frames);
  r.cpu_ms.reserve(frames);
  r.wall_ms.reserve(frames);
  r.allocs.reserve(frames);
  bool failed = false;
  for (auto _ : state) {
    const cv::Mat& left = g_sample.frames[pingPong(frame, n)].left;
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = threadCpuMs();
    const std::uint64_t a0 = sunvo::runtime::allocationCount();
    const auto m = estimator.estimate(left, level);
    const std::uint64_t a1 = sunvo::runtime::allocationCount();
    const double cpu1 = threadCpuMs();
    const auto t1 = std::chrono::steady_clock::now();
    if (!m) {
      failed = true;
    } else if (m->valid) {
      ++r.valid;
    }
    r.allocs.push_back(a1 - a0);
    r.cpu_ms.push_back(cpu1 - cpu0);
    r.wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    ++frame;
  }
  if (failed) {
    state.SkipWithError("estimate failed");
    return;
  }
  state.counters["cpu_ms_p50"] = percentile(r.cpu_ms, 0.5);
  r.ok = true;
}

void printSummary() {
  const char* names[2] = {"edge chains (default)", "LSD (baseline)"};
  std::printf(
      "\nvertical cue, left images %dx%d (00_first_frames ping-pong), after %d warm-up "
      "calls, single thread\n",
      g_sample.camera.width, g_sample.camera.height, g_config.warmup);
  std::printf("%-24s %8s %8s %8s %8s %10s %12s %8s\n", "detector", "cpu p50", "p95", "p99", "max",
              "wall p50", "allocs/call", "valid");
  for (int d = 0; d < 2; ++d) {
    const Results& r = g_results[d];
    if (!r.ok) continue;
    std::uint64_t total = 0;
    for (auto a : r.allocs) total += a;
    std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %10.3f %12.2f %7.0f%%\n", names[d],
                percentile(r.cpu_ms, 0.5), percentile(r.cpu_ms, 0.95), percentile(r.cpu_ms, 0.99),
                percentile(r.cpu_ms, 1.0), percentile(r.wall_ms, 0.5),
                static_cast<double>(total) / static_cast<double>(r.allocs.size()),
                100.0 * r.valid / static_cast<double>(r.cpu_ms.size()));
  }
  if (g_results[0].ok && g_results[1].ok) {
    std::printf("ratio edge chains / LSD: cpu p50 %.3f, p99 %.3f\n",
                percentile(g_results[0].cpu_ms, 0.5) / percentile(g_results[1].cpu_ms, 0.5),
                percentile(g_results[0].cpu_ms, 0.99) / percentile(g_results[1].cpu_ms, 0.99));
  }
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_bench_vertical";
  cv::setNumThreads(0);
  CLI::App app{"Vertical cue: CPU time and heap allocations per call on real KITTI images.",
               kProgram};
  sunvo::bench::addBenchOptions(app, g_config);
  if (auto code = sunvo::bench::startBenchmark(app, argc, argv, kProgram, g_config, &g_sample)) {
    return *code;
  }
  sunvo::bench::registerFrames("vertical/edge_chains", g_config.frames, benchVertical,
                               SegmentDetector::kEdgeChains);
  sunvo::bench::registerFrames("vertical/lsd", g_config.frames, benchVertical,
                               SegmentDetector::kLsd);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printSummary();
  return g_results[0].ok && g_results[1].ok ? sunvo::cli::kExitOk : sunvo::cli::kExitFailure;
}
