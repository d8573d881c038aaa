// Front-end benchmark on real KITTI images: the 11 frames of 00_first_frames played forward and
// backward (0..10..0..10..), single-threaded (cv::setNumThreads(0); the front end itself makes no
// OpenCV calls that could spawn threads). Prints per-stage median/p95/p99, heap allocations per
// frame inside process() after a warm-up, and the resident set size.
//
// Usage: sunvo_bench_frontend [--frames=N] [--warmup=N] [--data=DIR] [--cpu=K] [--benchmark_*]
//   --cpu=K pins the process to CPU K (sched_setaffinity) before anything runs; --benchmark_*
//   options go to Google Benchmark; --measure-right-rows and --correct-edge-columns turn those
//   front-end options on. Options: sunvo_bench_frontend --help.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "sunvo/bench/bench_support.hpp"
#include "sunvo/bench/benchmark_cli.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/frontend/stereo_frontend.hpp"
#include "sunvo/runtime/alloc_counter.hpp"

namespace {

using sunvo::bench::percentile;
using sunvo::bench::pingPong;
using sunvo::bench::procStatusKb;
using sunvo::bench::threadCpuMs;

using Config = sunvo::bench::BenchConfig;

struct Results {
  std::vector<double> detect_ms, temporal_ms, stereo_ms, total_ms;
  std::vector<double> detect_cpu_ms, temporal_cpu_ms, stereo_cpu_ms, total_cpu_ms;
  std::vector<double> features, tracked, candidates_left;
  std::vector<std::uint64_t> allocs;
  std::uint64_t init_bytes = 0;  // heap bytes requested by StereoFrontend::init()
  long rss_warm_kb = 0;
  long rss_end_kb = 0;
  long hwm_end_kb = 0;
  bool ok = false;
};

Config g_config;
sunvo::FrontendOptions g_options;  // defaults, with the flags below
Results g_results;
sunvo::bench::KittiFrames g_sample;

void benchFrontend(benchmark::State& state) {
  sunvo::StereoFrontend fe;
  const std::uint64_t bytes0 = sunvo::runtime::allocatedBytes();
  const sunvo::Status st = fe.init(g_options, g_sample.camera);
  g_results.init_bytes = sunvo::runtime::allocatedBytes() - bytes0;
  if (!st.isOk()) {
    state.SkipWithError(st.toString().c_str());
    return;
  }
  sunvo::FrameFeatures out;
  fe.reserveOutput(out);
  const std::size_t n = g_sample.frames.size();
  std::size_t frame = 0;
  for (int i = 0; i < g_config.warmup; ++i, ++frame) {
    const std::size_t k = pingPong(frame, n);
    if (!fe.process(g_sample.frames[k].left, g_sample.frames[k].right, 0, frame, out).isOk()) {
      state.SkipWithError("process failed in warm-up");
      return;
    }
  }
  Results& r = g_results;
  const auto frames = static_cast<std::size_t>(g_config.frames);
  for (auto* v : {&r.detect_ms, &r.temporal_ms, &r.stereo_ms, &r.total_ms, &r.detect_cpu_ms,
                  &r.temporal_cpu_ms, &r.stereo_cpu_ms, &r.total_cpu_ms, &r.features, &r.tracked,
                  &r.candidates_left}) {
    v->clear();
    v->reserve(frames);
  }
  r.allocs.clear();
  r.allocs.reserve(frames);
  r.rss_warm_kb = procStatusKb("VmRSS:");
  bool failed = false;
  for (auto _ : state) {
    const std::size_t k = pingPong(frame, n);
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = threadCpuMs();
    const std::uint64_t a0 = sunvo::runtime::allocationCount();
    const sunvo::Status s =
        fe.process(g_sample.frames[k].left, g_sample.frames[k].right, 0, frame, out);
    const std::uint64_t a1 = sunvo::runtime::allocationCount();
    const double cpu1 = threadCpuMs();
    const auto t1 = std::chrono::steady_clock::now();
    if (!s.isOk()) failed = true;
    const sunvo::FrontendStats& fs = fe.lastStats();
    r.allocs.push_back(a1 - a0);
    r.total_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    r.detect_ms.push_back(static_cast<double>(fs.detect_ns) * 1e-6);
    r.temporal_ms.push_back(static_cast<double>(fs.temporal_ns) * 1e-6);
    r.stereo_ms.push_back(static_cast<double>(fs.stereo_ns) * 1e-6);
    r.total_cpu_ms.push_back(cpu1 - cpu0);
    r.detect_cpu_ms.push_back(static_cast<double>(fs.detect_cpu_ns) * 1e-6);
    r.temporal_cpu_ms.push_back(static_cast<double>(fs.temporal_cpu_ns) * 1e-6);
    r.stereo_cpu_ms.push_back(static_cast<double>(fs.stereo_cpu_ns) * 1e-6);
    r.features.push_back(static_cast<double>(out.observations.size()));
    r.tracked.push_back(static_cast<double>(fs.tracks_kept));
    r.candidates_left.push_back(static_cast<double>(fs.candidates_left));
    ++frame;
  }
  r.rss_end_kb = procStatusKb("VmRSS:");
  r.hwm_end_kb = procStatusKb("VmHWM:");
  if (failed) {
    state.SkipWithError("process failed");
    return;
  }
  std::uint64_t total_allocs = 0;
  for (auto a : r.allocs) total_allocs += a;
  state.counters["allocs_per_frame"] =
      static_cast<double>(total_allocs) / static_cast<double>(r.allocs.size());
  state.counters["features"] = percentile(r.features, 0.5);
  state.counters["tracked"] = percentile(r.tracked, 0.5);
  state.counters["cpu_ms_p50"] = percentile(r.total_cpu_ms, 0.5);
  state.counters["detect_ms_p50"] = percentile(r.detect_ms, 0.5);
  state.counters["temporal_ms_p50"] = percentile(r.temporal_ms, 0.5);
  state.counters["stereo_ms_p50"] = percentile(r.stereo_ms, 0.5);
  r.ok = true;
}

void printSummary() {
  const Results& r = g_results;
  if (!r.ok) return;
  std::printf(
      "\nfront end on %zu frames of %dx%d (00_first_frames ping-pong), after %d warm-up "
      "frames, single thread (cv::setNumThreads(0)); measure_v_right %s, correct_edge_columns %s\n",
      r.total_ms.size(), g_sample.camera.width, g_sample.camera.height, g_config.warmup,
      g_options.measure_v_right ? "on" : "off", g_options.correct_edge_columns ? "on" : "off");
  std::printf("%-32s %9s %9s %9s %9s\n", "stage [ms]", "median", "p95", "p99", "max");
  auto row = [](const char* name, const std::vector<double>& v) {
    std::printf("%-32s %9.3f %9.3f %9.3f %9.3f\n", name, percentile(v, 0.5), percentile(v, 0.95),
                percentile(v, 0.99), percentile(v, 1.0));
  };
  row("wall: detect (both images)", r.detect_ms);
  row("wall: temporal + circular", r.temporal_ms);
  row("wall: stereo match (new)", r.stereo_ms);
  row("wall: process() total", r.total_ms);
  row("cpu:  detect (both images)", r.detect_cpu_ms);
  row("cpu:  temporal + circular", r.temporal_cpu_ms);
  row("cpu:  stereo match (new)", r.stereo_cpu_ms);
  row("cpu:  process() total", r.total_cpu_ms);
  std::uint64_t total = 0;
  std::uint64_t worst = 0;
  for (auto a : r.allocs) {
    total += a;
    worst = std::max(worst, a);
  }
  std::printf("heap allocations in process(): %llu in %zu frames (%.3f per frame, max %llu)\n",
              static_cast<unsigned long long>(total), r.allocs.size(),
              static_cast<double>(total) / static_cast<double>(r.allocs.size()),
              static_cast<unsigned long long>(worst));
  std::printf(
      "RSS after warm-up %ld kB, at end %ld kB (peak %ld kB); front-end buffers "
      "allocated in init(): %.1f MB\n",
      r.rss_warm_kb, r.rss_end_kb, r.hwm_end_kb,
      static_cast<double>(r.init_bytes) / (1024.0 * 1024.0));
  std::printf(
      "features/frame median %.0f (min %.0f), circular-tracked median %.0f (min %.0f), "
      "left candidates median %.0f\n",
      percentile(r.features, 0.5), percentile(r.features, 0.0), percentile(r.tracked, 0.5),
      percentile(r.tracked, 0.0), percentile(r.candidates_left, 0.5));
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_bench_frontend";
  cv::setNumThreads(0);
  CLI::App app{"Stereo front-end time and heap allocations per frame on real KITTI frames.",
               kProgram};
  sunvo::bench::addBenchOptions(app, g_config);
  app.add_flag("--measure-right-rows", g_options.measure_v_right,
               "frontend.measure_v_right (what the self-calibration needs)");
  app.add_flag("--correct-edge-columns", g_options.correct_edge_columns,
               "frontend.correct_edge_columns (needs --measure-right-rows)");
  if (auto code = sunvo::bench::startBenchmark(app, argc, argv, kProgram, g_config, &g_sample)) {
    return *code;
  }
  sunvo::bench::registerFrames("frontend/kitti00_first_frames_pingpong", g_config.frames,
                               benchFrontend);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printSummary();
  return g_results.ok ? sunvo::cli::kExitOk : sunvo::cli::kExitFailure;
}
