#pragma once
// Shared helpers of the benchmark executables: real KITTI frames in memory (read through
// drivers/kitti's KittiStereoSource), ping-pong playback order, percentiles, CPU pinning, thread
// CPU time and the resident set size.

#include <cstddef>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/core/stereo_frame.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/kitti/stereo_source.hpp"

namespace CLI {
class App;
}

namespace sunvo::bench {

using KittiFrames = kitti::LoadedFrames;

// Options every benchmark takes: --frames=N --warmup=N --cpu=K --data=DIR.
struct BenchConfig {
  int frames = 500;  // timed frames, >= 1
  int warmup = 20;   // frames before timing, >= 0
  std::string data = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";
  int cpu = -1;  // pin to this CPU when >= 0
};
// Adds those options to a program's command line (typed and range-checked, firmware_app/cli).
void addBenchOptions(CLI::App& app, BenchConfig& config);
// Pins to config.cpu (when >= 0), fails when the allocation counter is not linked in (the
// caller passes runtime::allocCounterActive(), which only benchmark executables link), and loads
// the frames of config.data.
Expected<KittiFrames> prepareBenchmark(const BenchConfig& config, bool alloc_counter_active);

// Reads every frame of a KITTI odometry sequence folder (calib.txt, times.txt, image_0/,
// image_1/) into memory. times.txt's 0 is placed at start_time_ns (UTC ns, > 0): the odometry
// layout names no absolute time, and the benchmarks only need the frames' order.
Expected<KittiFrames> loadKittiOdometryFrames(const std::string& dir,
                                              TimeNs start_time_ns = 1'000'000'000);

// Playback index i of n >= 2 frames played forward and backward: 0,1,..,n-1,n-2,..,1,0,1,..
std::size_t pingPong(std::size_t i, std::size_t n);

// The q-quantile (q in [0, 1]) of v by the nearest-rank method (q = 1: the maximum); 0 if empty.
double percentile(std::vector<double> v, double q);

// A "Key:" line of /proc/self/status ("VmRSS:", "VmHWM:") in kB; -1 if unreadable.
long procStatusKb(const char* key);

// Bytes of heap memory in use (glibc mallinfo2: arena uordblks + mmapped hblkhd), kB. Unlike the
// RSS it does not count freed memory that the allocator keeps, so its growth means live objects.
long heapInUseKb();

// CPU time of the calling thread, ms.
double threadCpuMs();

// Pins the calling process to CPU `cpu` (sched_setaffinity).
Status pinToCpu(int cpu);

}  // namespace sunvo::bench
