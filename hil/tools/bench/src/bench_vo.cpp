// Full image VO benchmark on real KITTI images: StereoImageOdometry (front end + 3-point RANSAC +
// two-frame window) on the 11 frames of 00_first_frames played forward and backward (0..10..0..),
// single-threaded (cv::setNumThreads(0); the pipeline starts no threads). Prints per-stage wall
// time median/p95/p99/max, heap allocations per frame per stage in steady state, the resident set
// size after warm-up and at the end, and measured/target ratios (targets: 20 ms median, 35 ms p99
// per frame).
//
// Three runs over the same frames: "full" (the default pipeline, window solved by the
// fixed-memory Schur LM), "full_ceres" (the same with window.solver = ceres, the baseline of the
// ratio rows) and "ransac_only" (vo.use_window = false). The front end is deterministic and RANSAC
// is seeded per frame, so the back end of the second run makes the same association + RANSAC calls:
// its allocations are RANSAC's, and the window's are the full run's back-end allocations minus
// those.
//
// A third run times the back end alone (vo::StereoTrackOdometry, track mode) on the real feature
// tracks of KITTI 2011_09_30_drive_0020 (1000 frames, SURF+KLT tracks, ~65 observations per frame).
//
// With --peer NAME, a peer VO library built outside the tree (libviso2; sunvo/bench/peer.hpp)
// then runs in the same process over the same frames, warm-up and timed count, on the same pinned
// CPU, twice: alone after sunvo's runs, and interleaved frame by frame with a fresh sunvo
// pipeline (sunvo frame k, peer frame k, ...: both see the same load on the shared core). Its
// per-frame wall and thread CPU times are printed with the ratios sunvo/peer of each.
//
// Usage: sunvo_bench_vo [--frames=N] [--warmup=N] [--data=DIR] [--tracks=DIR|--tracks=]
//                       [--cpu=K] [--peer=libviso2] [--benchmark_*]
//   --cpu=K pins the process to CPU K (sched_setaffinity) before anything runs;
//   --tracks= (empty) skips the track-mode run; --benchmark_* options go to Google Benchmark.
//   Options: sunvo_bench_vo --help.

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
#include "sunvo/bench/peer.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/dataset/track_folder.hpp"
#include "sunvo/files/tracks_io.hpp"
#include "sunvo/pipeline/stereo_image_odometry.hpp"
#include "sunvo/runtime/alloc_counter.hpp"

namespace {

using sunvo::bench::percentile;

constexpr double kTargetMedianMs = 20.0;
constexpr double kTargetP99Ms = 35.0;

struct Config : sunvo::bench::BenchConfig {
  std::string tracks = std::string(SUNVO_DATA_DIR) + "/kitti_tracks/2011_09_30_drive_0020";
  std::string peer;  // empty: no peer run
};

struct Run {
  const char* name = "";
  std::vector<double> detect_ms, match_ms, frontend_ms, ransac_ms, window_ms, odometry_ms, total_ms,
      outer_ms, cpu_ms;
  std::vector<double> detect_cpu_ms, match_cpu_ms, frontend_cpu_ms, odometry_cpu_ms;
  std::vector<double> ceres_ms;  // Ceres' own total_time of the window solve
  std::vector<double> alloc_frontend, alloc_odometry;
  std::vector<double> features, tracked, inliers, landmarks, iterations;
  int lost = 0;
  int tracking = 0;
  int recovered = 0;
  long rss_warm_kb = 0;
  long rss_end_kb = 0;
  long heap_warm_kb = 0;  // heap in use (mallinfo2)
  long heap_end_kb = 0;
  std::vector<long> heap_trace_kb;  // heap in use every 100 frames (track mode)
  bool ok = false;
};

Config g_config;
sunvo::bench::KittiFrames g_data;
Run g_full;
Run g_full_ceres;
Run g_ransac_only;
Run g_tracks;
sunvo::files::TrackSequence g_track_seq;

void runPipeline(benchmark::State& state, bool use_window, sunvo::backend::WindowSolver solver,
                 Run& r) {
  sunvo::pipeline::PipelineOptions opt;
  opt.vo.use_window = use_window;
  opt.vo.window.solver = solver;
  sunvo::pipeline::StereoImageOdometry vo;
  const sunvo::Status st = vo.init(opt, g_data.camera);
  if (!st.isOk()) {
    state.SkipWithError(st.toString().c_str());
    return;
  }
  vo.setStageCounter(&sunvo::runtime::allocationCount);
  const std::size_t n = g_data.frames.size();
  // Playback copies share the image buffers (cv::Mat headers); only sequence and time change so
  // that the back end sees a monotonic 10 Hz stream.
  sunvo::StereoFrame frame;
  std::size_t i = 0;
  auto feed = [&](std::size_t index) -> sunvo::Expected<sunvo::pipeline::FrameResult> {
    const sunvo::StereoFrame& src = g_data.frames[sunvo::bench::pingPong(index, n)];
    frame.left = src.left;
    frame.right = src.right;
    frame.sequence = index;
    frame.trigger_time_ns = 1'000'000'000 + static_cast<sunvo::TimeNs>(index) * 100'000'000;
    return vo.process(frame);
  };
  for (int w = 0; w < g_config.warmup; ++w, ++i) {
    if (!feed(i).hasValue()) {
      state.SkipWithError("process failed in warm-up");
      return;
    }
  }
  const auto frames = static_cast<std::size_t>(g_config.frames);
  for (auto* v : {&r.detect_ms,       &r.match_ms,        &r.frontend_ms,    &r.ransac_ms,
                  &r.window_ms,       &r.odometry_ms,     &r.total_ms,       &r.outer_ms,
                  &r.cpu_ms,          &r.ceres_ms,        &r.detect_cpu_ms,  &r.match_cpu_ms,
                  &r.frontend_cpu_ms, &r.odometry_cpu_ms, &r.alloc_frontend, &r.alloc_odometry,
                  &r.features,        &r.tracked,         &r.inliers,        &r.landmarks,
                  &r.iterations}) {
    v->clear();
    v->reserve(frames);
  }
  r.rss_warm_kb = sunvo::bench::procStatusKb("VmRSS:");
  r.heap_warm_kb = sunvo::bench::heapInUseKb();
  bool failed = false;
  for (auto _ : state) {
    const double cpu0 = sunvo::bench::threadCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    auto res = feed(i);
    const auto t1 = std::chrono::steady_clock::now();
    const double cpu1 = sunvo::bench::threadCpuMs();
    ++i;
    if (!res.hasValue()) {
      failed = true;
      continue;
    }
    const sunvo::pipeline::FrameResult& f = *res;
    r.detect_ms.push_back(f.times.detect_ms);
    r.match_ms.push_back(f.times.matchMs());
    r.frontend_ms.push_back(f.times.frontend_ms);
    r.ransac_ms.push_back(f.times.ransac_ms);
    r.window_ms.push_back(f.times.window_ms);
    r.odometry_ms.push_back(f.times.odometry_ms);
    r.total_ms.push_back(f.times.total_ms);
    r.outer_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    r.cpu_ms.push_back(cpu1 - cpu0);
    r.alloc_frontend.push_back(static_cast<double>(f.frontend_counter_delta));
    r.alloc_odometry.push_back(static_cast<double>(f.odometry_counter_delta));
    r.features.push_back(f.num_features);
    r.tracked.push_back(f.frontend.tracks_kept);
    r.inliers.push_back(f.vo.ransac_inliers);
    r.ceres_ms.push_back(f.vo.solver_time_s * 1e3);
    r.detect_cpu_ms.push_back(f.times.detect_cpu_ms);
    r.match_cpu_ms.push_back(f.times.match_cpu_ms);
    r.frontend_cpu_ms.push_back(f.times.frontend_cpu_ms);
    r.odometry_cpu_ms.push_back(f.times.odometry_cpu_ms);
    r.landmarks.push_back(f.vo.window_landmarks);
    r.iterations.push_back(f.vo.solver_iterations);
    switch (f.vo.status) {
      case sunvo::vo::TrackingStatus::kLost:
        ++r.lost;
        break;
      case sunvo::vo::TrackingStatus::kRecovered:
        ++r.recovered;
        break;
      case sunvo::vo::TrackingStatus::kTracking:
        ++r.tracking;
        break;
      case sunvo::vo::TrackingStatus::kInitializing:
        break;
    }
  }
  r.rss_end_kb = sunvo::bench::procStatusKb("VmRSS:");
  r.heap_end_kb = sunvo::bench::heapInUseKb();
  if (failed) {
    state.SkipWithError("process failed");
    return;
  }
  state.counters["total_ms_p50"] = percentile(r.total_ms, 0.5);
  state.counters["total_ms_p99"] = percentile(r.total_ms, 0.99);
  state.counters["lost"] = r.lost;
  r.ok = true;
}

// The back end alone on recorded real tracks: every frame of the sequence once, in order.
void benchTracks(benchmark::State& state) {
  Run& r = g_tracks;
  sunvo::vo::StereoTrackOdometry vo;
  const sunvo::Status st =
      vo.init(sunvo::vo::VoOptions{}, g_track_seq.camera, sunvo::Isometry3::Identity());
  if (!st.isOk()) {
    state.SkipWithError(st.toString().c_str());
    return;
  }
  for (auto* v : {&r.ransac_ms, &r.window_ms, &r.ceres_ms, &r.odometry_ms, &r.cpu_ms,
                  &r.alloc_odometry, &r.inliers, &r.landmarks, &r.iterations}) {
    v->clear();
    v->reserve(g_track_seq.frames.size());
  }
  r.heap_trace_kb.reserve(g_track_seq.frames.size() / 100 + 1);
  r.rss_warm_kb = sunvo::bench::procStatusKb("VmRSS:");
  r.heap_warm_kb = sunvo::bench::heapInUseKb();
  std::size_t k = 0;
  bool failed = false;
  for (auto _ : state) {
    const std::uint64_t a0 = sunvo::runtime::allocationCount();
    const double cpu0 = sunvo::bench::threadCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    auto res = vo.process(g_track_seq.frames[k]);
    const auto t1 = std::chrono::steady_clock::now();
    const double cpu1 = sunvo::bench::threadCpuMs();
    const std::uint64_t a1 = sunvo::runtime::allocationCount();
    ++k;
    if (!res.hasValue()) {
      failed = true;
      continue;
    }
    if (k % 100 == 0) r.heap_trace_kb.push_back(sunvo::bench::heapInUseKb());
    if (k == 1) continue;  // frame 0 only initialises
    r.ransac_ms.push_back(res->ransac_ms);
    r.window_ms.push_back(res->window_ms);
    r.ceres_ms.push_back(res->solver_time_s * 1e3);
    r.odometry_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    r.cpu_ms.push_back(cpu1 - cpu0);
    r.alloc_odometry.push_back(static_cast<double>(a1 - a0));
    r.inliers.push_back(res->ransac_inliers);
    r.landmarks.push_back(res->window_landmarks);
    r.iterations.push_back(res->solver_iterations);
    if (res->status == sunvo::vo::TrackingStatus::kLost) ++r.lost;
    if (res->status == sunvo::vo::TrackingStatus::kRecovered) ++r.recovered;
    if (res->status == sunvo::vo::TrackingStatus::kTracking) ++r.tracking;
  }
  r.rss_end_kb = sunvo::bench::procStatusKb("VmRSS:");
  r.heap_end_kb = sunvo::bench::heapInUseKb();
  if (failed) {
    state.SkipWithError("process failed");
    return;
  }
  r.ok = true;
}

void benchFull(benchmark::State& state) {
  runPipeline(state, true, sunvo::backend::WindowSolver::kSchurLm, g_full);
}
void benchFullCeres(benchmark::State& state) {
  runPipeline(state, true, sunvo::backend::WindowSolver::kCeres, g_full_ceres);
}
void benchRansacOnly(benchmark::State& state) {
  runPipeline(state, false, sunvo::backend::WindowSolver::kSchurLm, g_ransac_only);
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

void row(const char* name, const std::vector<double>& v) {
  std::printf("%-36s %9.3f %9.3f %9.3f %9.3f %9.3f\n", name, percentile(v, 0.5),
              percentile(v, 0.95), percentile(v, 0.99), percentile(v, 1.0), mean(v));
}

void printRun(const Run& r) {
  std::printf(
      "\n[%s] %zu frames of %dx%d (00_first_frames ping-pong) after %d warm-up frames, "
      "one thread\n",
      r.name, r.total_ms.size(), g_data.camera.width, g_data.camera.height, g_config.warmup);
  std::printf("%-36s %9s %9s %9s %9s %9s\n", "wall time per frame [ms]", "median", "p95", "p99",
              "max", "mean");
  row("front end: detect (both images)", r.detect_ms);
  row("front end: match (temporal+stereo)", r.match_ms);
  row("front end: process() total", r.frontend_ms);
  row("back end: association + RANSAC", r.ransac_ms);
  row("back end: window (gather + solve)", r.window_ms);
  row("  of which the solver (own timer)", r.ceres_ms);
  row("back end: process() total", r.odometry_ms);
  row("pipeline: process() total", r.total_ms);
  row("pipeline: outer wall (incl. call)", r.outer_ms);
  std::printf("%-36s %9s %9s %9s %9s %9s\n", "thread CPU time per frame [ms]", "median", "p95",
              "p99", "max", "mean");
  row("front end: detect (both images)", r.detect_cpu_ms);
  row("front end: match (temporal+stereo)", r.match_cpu_ms);
  row("front end: process() total", r.frontend_cpu_ms);
  row("back end: process() total", r.odometry_cpu_ms);
  row("pipeline: process() total", r.cpu_ms);
  std::printf("%-36s %9s %9s %9s %9s %9s\n", "heap allocations per frame", "median", "p95", "p99",
              "max", "mean");
  row("front end", r.alloc_frontend);
  row("back end (association+RANSAC+window)", r.alloc_odometry);
  std::printf(
      "status: %d tracking, %d recovered, %d lost; features/frame median %.0f, "
      "circular-tracked median %.0f, RANSAC inliers median %.0f (min %.0f)\n",
      r.tracking, r.recovered, r.lost, percentile(r.features, 0.5), percentile(r.tracked, 0.5),
      percentile(r.inliers, 0.5), percentile(r.inliers, 0.0));
  std::printf("window landmarks median %.0f (max %.0f), solver iterations median %.0f (max %.0f)\n",
              percentile(r.landmarks, 0.5), percentile(r.landmarks, 1.0),
              percentile(r.iterations, 0.5), percentile(r.iterations, 1.0));
  std::printf(
      "RSS after warm-up %ld kB, at end %ld kB (change %+ld kB); heap in use %ld kB, "
      "%ld kB (change %+ld kB)\n",
      r.rss_warm_kb, r.rss_end_kb, r.rss_end_kb - r.rss_warm_kb, r.heap_warm_kb, r.heap_end_kb,
      r.heap_end_kb - r.heap_warm_kb);
}

void printTracks(const Run& r) {
  std::printf("\n[back end only, track mode] %zu frames of %s (frame 0 excluded)\n",
              r.odometry_ms.size(), g_config.tracks.c_str());
  std::printf("%-36s %9s %9s %9s %9s %9s\n", "wall time per frame [ms]", "median", "p95", "p99",
              "max", "mean");
  row("association + RANSAC", r.ransac_ms);
  row("window (gather + solve)", r.window_ms);
  row("  of which the solver (own timer)", r.ceres_ms);
  row("StereoTrackOdometry::process() total", r.odometry_ms);
  row("thread CPU time", r.cpu_ms);
  row("heap allocations per frame", r.alloc_odometry);
  std::printf(
      "status: %d tracking, %d recovered, %d lost; RANSAC inliers median %.0f, window "
      "landmarks median %.0f, solver iterations median %.0f\n",
      r.tracking, r.recovered, r.lost, percentile(r.inliers, 0.5), percentile(r.landmarks, 0.5),
      percentile(r.iterations, 0.5));
  std::printf(
      "RSS before %ld kB, after %ld kB (change %+ld kB); heap in use %ld kB, %ld kB "
      "(change %+ld kB)\n",
      r.rss_warm_kb, r.rss_end_kb, r.rss_end_kb - r.rss_warm_kb, r.heap_warm_kb, r.heap_end_kb,
      r.heap_end_kb - r.heap_warm_kb);
  std::printf("heap in use every 100 frames [kB]:");
  for (long h : r.heap_trace_kb) std::printf(" %ld", h);
  std::printf("\n");
}

void printSummary() {
  if (!g_full.ok) return;
  printRun(g_full);
  if (g_ransac_only.ok) {
    printRun(g_ransac_only);
    std::printf("\nper-stage heap allocations per frame (mean over the timed frames)\n");
    const double fe = mean(g_full.alloc_frontend);
    const double ransac = mean(g_ransac_only.alloc_odometry);
    const double backend = mean(g_full.alloc_odometry);
    std::printf("  front end                 %10.2f (max %.0f)\n", fe,
                percentile(g_full.alloc_frontend, 1.0));
    std::printf("  association + RANSAC      %10.2f (max %.0f)   [ransac_only run]\n", ransac,
                percentile(g_ransac_only.alloc_odometry, 1.0));
    std::printf("  window                    %10.2f             [full - ransac_only]\n",
                backend - ransac);
  }
  if (g_full_ceres.ok) {
    printRun(g_full_ceres);
    const auto ratio = [](const char* what, const std::vector<double>& a,
                          const std::vector<double>& b) {
      std::printf("  %-34s median %8.3f / %8.3f = %.3f   p99 %8.3f / %8.3f = %.3f\n", what,
                  percentile(a, 0.5), percentile(b, 0.5), percentile(a, 0.5) / percentile(b, 0.5),
                  percentile(a, 0.99), percentile(b, 0.99),
                  percentile(a, 0.99) / percentile(b, 0.99));
    };
    std::printf("\nschur_lm (full) against the ceres baseline (full_ceres), same frames:\n");
    ratio("window wall time [ms]", g_full.window_ms, g_full_ceres.window_ms);
    ratio("back end thread CPU [ms]", g_full.odometry_cpu_ms, g_full_ceres.odometry_cpu_ms);
    ratio("pipeline thread CPU [ms]", g_full.cpu_ms, g_full_ceres.cpu_ms);
    ratio("pipeline wall time [ms]", g_full.total_ms, g_full_ceres.total_ms);
    std::printf("  %-34s mean %10.2f / %10.2f\n", "back-end heap allocations per frame",
                mean(g_full.alloc_odometry), mean(g_full_ceres.alloc_odometry));
  }
  if (g_tracks.ok) printTracks(g_tracks);
  const double p50 = percentile(g_full.total_ms, 0.5);
  const double p99 = percentile(g_full.total_ms, 0.99);
  std::printf(
      "\ntargets (full pipeline, wall time per frame): median %.2f ms / %.0f ms = %.2f, "
      "p99 %.2f ms / %.0f ms = %.2f\n",
      p50, kTargetMedianMs, p50 / kTargetMedianMs, p99, kTargetP99Ms, p99 / kTargetP99Ms);
  const double c50 = percentile(g_full.cpu_ms, 0.5);
  const double c99 = percentile(g_full.cpu_ms, 0.99);
  std::printf(
      "same in thread CPU time (what other processes on the core do not inflate): median "
      "%.2f ms / %.0f ms = %.2f, p99 %.2f ms / %.0f ms = %.2f\n",
      c50, kTargetMedianMs, c50 / kTargetMedianMs, c99, kTargetP99Ms, c99 / kTargetP99Ms);
}

// sunvo's full pipeline and a peer, frame by frame alternately (same frames, same load).
struct Interleaved {
  std::vector<double> sunvo_wall_ms, sunvo_cpu_ms;
  sunvo::bench::PeerRun peer;
};

sunvo::Expected<Interleaved> runInterleaved(const std::string& name) {
  auto peer = sunvo::bench::makePeer(name, g_data.camera);
  if (!peer) return peer.status();
  sunvo::pipeline::StereoImageOdometry vo;
  SUNVO_RETURN_IF_ERROR(vo.init(sunvo::pipeline::PipelineOptions{}, g_data.camera));
  const std::size_t n = g_data.frames.size();
  sunvo::StereoFrame frame;
  auto feed = [&](std::size_t index) {
    const sunvo::StereoFrame& src = g_data.frames[sunvo::bench::pingPong(index, n)];
    frame.left = src.left;
    frame.right = src.right;
    frame.sequence = index;
    frame.trigger_time_ns = 1'000'000'000 + static_cast<sunvo::TimeNs>(index) * 100'000'000;
    return vo.process(frame).hasValue();
  };
  Interleaved r;
  r.peer.name = name;
  std::size_t i = 0;
  for (int w = 0; w < g_config.warmup; ++w, ++i) {
    if (!feed(i)) return sunvo::Status(sunvo::StatusCode::kInternal, "process failed in warm-up");
    const sunvo::StereoFrame& src = g_data.frames[sunvo::bench::pingPong(i, n)];
    (void)(*peer)->process(src.left, src.right);
  }
  for (int k = 0; k < g_config.frames; ++k, ++i) {
    const double cpu0 = sunvo::bench::threadCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = feed(i);
    const auto t1 = std::chrono::steady_clock::now();
    const double cpu1 = sunvo::bench::threadCpuMs();
    if (!ok) return sunvo::Status(sunvo::StatusCode::kInternal, "process failed");
    r.sunvo_wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    r.sunvo_cpu_ms.push_back(cpu1 - cpu0);
    sunvo::bench::timePeerFrame(**peer, g_data, i, r.peer);
  }
  return r;
}

// The peer's times next to sunvo's (same frames, same process, same CPU).
void printPeer(const char* how, const sunvo::bench::PeerRun& p,
               const std::vector<double>& sunvo_wall_ms, const std::vector<double>& sunvo_cpu_ms) {
  std::printf(
      "\n[peer %s, %s] %zu frames of %dx%d (00_first_frames ping-pong) after %d warm-up frames, "
      "same process and CPU\n",
      p.name.c_str(), how, p.wall_ms.size(), g_data.camera.width, g_data.camera.height,
      g_config.warmup);
  std::printf("%-36s %9s %9s %9s %9s %9s\n", "per frame [ms]", "median", "p95", "p99", "max",
              "mean");
  row("peer wall time", p.wall_ms);
  row("peer thread CPU time", p.cpu_ms);
  row("sunvo pipeline wall (outer)", sunvo_wall_ms);
  row("sunvo pipeline thread CPU", sunvo_cpu_ms);
  std::printf(
      "peer: %d failed frames; matches median %.0f, inliers median %.0f (min %.0f), "
      "|t| per frame median %.3f m\n",
      p.failures, percentile(p.matches, 0.5), percentile(p.inliers, 0.5),
      percentile(p.inliers, 0.0), percentile(p.translation_m, 0.5));
  auto ratio = [](const std::vector<double>& a, const std::vector<double>& b, double q) {
    return percentile(a, q) / percentile(b, q);
  };
  std::printf("ratio sunvo/%s (%s): wall median %.2f, p99 %.2f; thread CPU median %.2f, p99 %.2f\n",
              p.name.c_str(), how, ratio(sunvo_wall_ms, p.wall_ms, 0.5),
              ratio(sunvo_wall_ms, p.wall_ms, 0.99), ratio(sunvo_cpu_ms, p.cpu_ms, 0.5),
              ratio(sunvo_cpu_ms, p.cpu_ms, 0.99));
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_bench_vo";
  cv::setNumThreads(0);
  CLI::App app{
      "Image VO (front end, RANSAC, window) time and heap allocations per frame on real "
      "KITTI frames, and the back end alone on recorded feature tracks.",
      kProgram};
  sunvo::bench::addBenchOptions(app, g_config);
  app.add_option("--tracks", g_config.tracks,
                 "feature-track folder of the back-end-only run (--tracks= skips it)")
      ->expected(0, 1);
  app.add_option("--peer", g_config.peer,
                 "after sunvo's runs, time this peer VO library on the same frames (libviso2; "
                 "needs a build configured with -DSUNVO_LIBVISO2_DIR)")
      ->check(CLI::Validator(
          [](std::string& name) {
            for (const std::string& p : sunvo::bench::availablePeers()) {
              if (p == name) return std::string();
            }
            return sunvo::bench::peerUnavailableMessage(name);
          },
          "PEER", "built-in peer"));
  if (auto code = sunvo::bench::startBenchmark(app, argc, argv, kProgram, g_config, &g_data)) {
    return *code;
  }
  g_full.name = "full";
  g_full_ceres.name = "full_ceres";
  g_ransac_only.name = "ransac_only";
  sunvo::bench::registerFrames("vo/full/kitti00_first_frames_pingpong", g_config.frames, benchFull);
  sunvo::bench::registerFrames("vo/full_ceres/kitti00_first_frames_pingpong", g_config.frames,
                               benchFullCeres);
  sunvo::bench::registerFrames("vo/ransac_only/kitti00_first_frames_pingpong", g_config.frames,
                               benchRansacOnly);
  if (!g_config.tracks.empty()) {
    auto seq = sunvo::dataset::readTrackFolder(g_config.tracks, sunvo::files::TrackReadOptions{});
    if (!seq) return sunvo::cli::fail(kProgram, seq.status());
    g_track_seq = std::move(*seq);
    g_tracks.name = "tracks";
    sunvo::bench::registerFrames("vo/backend_only/kitti_tracks_0020",
                                 static_cast<int>(g_track_seq.frames.size()), benchTracks);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printSummary();
  if (!g_config.peer.empty()) {
    auto peer = sunvo::bench::runPeer(g_config.peer, g_data, g_config);
    if (!peer) return sunvo::cli::fail(kProgram, peer.status());
    auto both = runInterleaved(g_config.peer);
    if (!both) return sunvo::cli::fail(kProgram, both.status());
    if (g_full.ok) {
      printPeer("alone, after sunvo's runs", *peer, g_full.outer_ms, g_full.cpu_ms);
      printPeer("interleaved frame by frame with sunvo", both->peer, both->sunvo_wall_ms,
                both->sunvo_cpu_ms);
    }
  }
  return g_full.ok ? sunvo::cli::kExitOk : sunvo::cli::kExitFailure;
}
