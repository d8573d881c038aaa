#pragma once
// Thread-CPU accounting of a Delaunay stand-in for libviso2's Triangle (triangle_shim*.cpp),
// printed to stderr at exit (LIBVISO2_SHIM_QUIET set: silent), so a benchmark can state how much
// of libviso2's time the stand-in took. sunvo's code; peer builds only.
#include <cstdio>
#include <cstdlib>
#include <ctime>

inline double shimThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct ShimStats {
  const char* method;  // e.g. "OpenCV Subdiv2D"
  long calls = 0;
  long points = 0;
  double cpu_s = 0.0;
  // One triangulation of n points that started at thread-CPU time t0 (shimThreadCpuSeconds()).
  void add(int n, double t0) {
    ++calls;
    points += n;
    cpu_s += shimThreadCpuSeconds() - t0;
  }
  ~ShimStats() {
    if (calls > 0 && std::getenv("LIBVISO2_SHIM_QUIET") == nullptr)
      std::fprintf(stderr,
                   "libviso2 triangle shim (%s): %ld calls, %.1f points per call, "
                   "%.1f ms thread-CPU total, %.3f ms per call\n",
                   method, calls, static_cast<double>(points) / calls, 1e3 * cpu_s,
                   1e3 * cpu_s / calls);
  }
};
