#include "sunvo/bench/bench_support.hpp"

#include <malloc.h>
#include <sched.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <utility>

#include "sunvo/kitti/stereo_source.hpp"

namespace sunvo::bench {

Expected<KittiFrames> loadKittiOdometryFrames(const std::string& dir, TimeNs start_time_ns) {
  kitti::KittiSourceOptions o;
  o.root = dir;
  o.layout = kitti::KittiLayout::kOdometry;
  o.odometry_start_time_ns = start_time_ns;
  auto out = kitti::loadAllFrames(o);
  if (!out) return out.status();
  if (out->frames.size() < 2) return invalidArgument(dir + ": fewer than 2 frames");
  return out;
}

void addBenchOptions(CLI::App& app, BenchConfig& config) {
  app.add_option("--frames", config.frames, "timed frames")->check(CLI::Range(1, 100000000));
  app.add_option("--warmup", config.warmup, "frames before timing")
      ->check(CLI::Range(0, 100000000));
  app.add_option("--data", config.data, "KITTI odometry sequence folder (calib.txt, image_0/1)");
  app.add_option("--cpu", config.cpu, "pin the process to this CPU (-1: no pinning)")
      ->check(CLI::Range(-1, 4095));
}

Expected<KittiFrames> prepareBenchmark(const BenchConfig& config, bool alloc_counter_active) {
  if (config.cpu >= 0) {
    SUNVO_RETURN_IF_ERROR(pinToCpu(config.cpu));
    std::printf("pinned to CPU %d\n", config.cpu);
  }
  if (!alloc_counter_active) {
    return failedPrecondition("allocation counter is not active in this binary");
  }
  return loadKittiOdometryFrames(config.data);
}

std::size_t pingPong(std::size_t i, std::size_t n) {
  if (n < 2) return 0;
  const std::size_t period = 2 * (n - 1);
  const std::size_t k = i % period;
  return k < n ? k : period - k;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

long procStatusKb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::size_t n = std::strlen(key);
  while (std::getline(f, line)) {
    if (line.compare(0, n, key) == 0) return std::strtol(line.c_str() + n, nullptr, 10);
  }
  return -1;
}

long heapInUseKb() {
  const struct mallinfo2 mi = mallinfo2();
  return static_cast<long>((mi.uordblks + mi.hblkhd) / 1024);
}

double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

Status pinToCpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof(set), &set) != 0) {
    return invalidArgument("cannot pin to CPU " + std::to_string(cpu) + ": " +
                           std::strerror(errno));
  }
  return Status::ok();
}

}  // namespace sunvo::bench
