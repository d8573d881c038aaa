// sunvo_bench_v4l2 [--frames=N] [--width=W] [--height=H] [--cpu=K] (sunvo_bench_v4l2 --help)
// Per-frame time of V4l2StereoSource::next() (dequeue, pairing, GREY copy or YUYV conversion,
// requeue) for every layout and pixel format, through the emulated V4L2 devices; the emulated
// kernel's own work (filling the buffers in trigger()) is outside the timed region. Also counts
// heap allocations per frame after the first.

#include <time.h>

#include <chrono>
#include <cstdio>
#include <vector>

#include "sunvo/bench/bench_support.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/runtime/alloc_counter.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace {

using sunvo::TimeNs;
using sunvo::v4l2::V4l2Layout;
using sunvo::v4l2::V4l2PixelFormat;

double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double wallMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int runCase(V4l2Layout layout, V4l2PixelFormat format, int width, int height, int frames) {
  sunvo::emulated::EmulatedV4l2 emu;
  const bool sbs = layout == V4l2Layout::kSideBySide;
  if (!emu.addCamera({"/dev/video0", sbs ? 2 * width : width, height, true, true, 0, 0,
                      sunvo::emulated::patternContent(1)})
           .isOk() ||
      (!sbs && !emu.addCamera({"/dev/video1", width, height, true, true, 0, 0,
                               sunvo::emulated::patternContent(2)})
                    .isOk())) {
    std::fprintf(stderr, "cannot add emulated cameras\n");
    return 1;
  }
  sunvo::v4l2::V4l2Options o;
  o.layout = layout;
  o.pixel_format = format;
  o.width = width;
  o.height = height;
  auto source = sunvo::v4l2::V4l2StereoSource::open(o, emu);
  if (!source.hasValue()) {
    std::fprintf(stderr, "%s\n", source.status().toString().c_str());
    return 1;
  }
  sunvo::StereoFrame frame;
  std::vector<double> cpu_ms;
  std::vector<double> wall_ms;
  cpu_ms.reserve(static_cast<std::size_t>(frames));
  wall_ms.reserve(static_cast<std::size_t>(frames));
  std::uint64_t allocations = 0;
  constexpr TimeNs kPeriod = 100'000'000;
  for (int k = 0; k <= frames; ++k) {
    emu.trigger(k * kPeriod);
    const std::uint64_t allocs_before = sunvo::runtime::allocationCount();
    const double c0 = threadCpuMs();
    const double w0 = wallMs();
    const sunvo::Status s = (*source)->next(frame);
    const double w1 = wallMs();
    const double c1 = threadCpuMs();
    const std::uint64_t allocs = sunvo::runtime::allocationCount() - allocs_before;
    if (!s.isOk()) {
      std::fprintf(stderr, "frame %d: %s\n", k, s.toString().c_str());
      return 1;
    }
    if (k == 0) continue;  // the first frame allocates the output images
    allocations += allocs;
    cpu_ms.push_back(c1 - c0);
    wall_ms.push_back(w1 - w0);
  }
  std::printf("| %s | %s | %dx%d | %.3f | %.3f | %.3f | %.3f | %llu |\n",
              sbs ? "side-by-side" : "two devices",
              format == V4l2PixelFormat::kGrey ? "GREY" : "YUYV", width, height,
              sunvo::metrics::percentile(cpu_ms, 0.5), sunvo::metrics::percentile(cpu_ms, 0.99),
              sunvo::metrics::percentile(wall_ms, 0.5), sunvo::metrics::percentile(wall_ms, 0.99),
              static_cast<unsigned long long>(allocations));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_bench_v4l2";
  int frames = 500;
  int width = 1242;
  int height = 375;
  int cpu = -1;
  CLI::App app{
      "V4l2StereoSource::next() time and heap allocations per frame through the emulated "
      "V4L2 devices, for every layout and pixel format.",
      kProgram};
  app.add_option("--frames", frames, "timed frames per case")->check(CLI::Range(1, 100000000));
  app.add_option("--width", width, "image width per eye, px")->check(CLI::Range(16, 16384));
  app.add_option("--height", height, "image height, px")->check(CLI::Range(16, 16384));
  app.add_option("--cpu", cpu, "pin the process to this CPU (-1: no pinning)")
      ->check(CLI::Range(-1, 4095));
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (!sunvo::runtime::allocCounterActive()) {
    return sunvo::cli::fail(kProgram, "allocation counter not active");
  }
  if (cpu >= 0) {
    const sunvo::Status s = sunvo::bench::pinToCpu(cpu);
    if (!s.isOk()) std::fprintf(stderr, "%s: warning: %s\n", kProgram, s.toString().c_str());
  }
  std::printf(
      "V4l2StereoSource::next() per frame, %d frames per case (after one warm-up frame), "
      "emulated devices\n\n",
      frames);
  std::printf(
      "| layout | format | per eye | CPU median ms | CPU p99 ms | wall median ms | "
      "wall p99 ms | allocations in all frames |\n|---|---|---|---|---|---|---|---|\n");
  int rc = 0;
  for (V4l2Layout layout : {V4l2Layout::kTwoDevices, V4l2Layout::kSideBySide}) {
    for (V4l2PixelFormat format : {V4l2PixelFormat::kGrey, V4l2PixelFormat::kYuyv}) {
      rc |= runCase(layout, format, width, height, frames);
    }
  }
  return rc;
}
