// Delaunay triangulation for libviso2's outlier removal through OpenCV's
// Subdiv2D (see triangle.h); its thread-CPU time is counted (shim_stats.hpp).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <opencv2/imgproc.hpp>
#include <unordered_map>
#include <vector>

#include "shim_stats.hpp"
#include "triangle.h"

namespace {

ShimStats g_stats{"OpenCV Subdiv2D"};

std::uint64_t key(float x, float y) {
  std::uint32_t bx, by;
  std::memcpy(&bx, &x, 4);
  std::memcpy(&by, &y, 4);
  return (static_cast<std::uint64_t>(bx) << 32) | by;
}

}  // namespace

void triangulate(char*, struct triangulateio* in, struct triangulateio* out,
                 struct triangulateio*) {
  const double t0 = shimThreadCpuSeconds();
  const int n = in->numberofpoints;
  float x_min = in->pointlist[0], x_max = x_min;
  float y_min = in->pointlist[1], y_max = y_min;
  for (int i = 1; i < n; ++i) {
    const float x = in->pointlist[2 * i], y = in->pointlist[2 * i + 1];
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  cv::Subdiv2D subdiv(cv::Rect(static_cast<int>(x_min) - 2, static_cast<int>(y_min) - 2,
                               static_cast<int>(x_max - x_min) + 5,
                               static_cast<int>(y_max - y_min) + 5));
  std::unordered_map<std::uint64_t, int> index_of;
  index_of.reserve(2 * n);
  for (int i = 0; i < n; ++i) {
    const float x = in->pointlist[2 * i], y = in->pointlist[2 * i + 1];
    // A duplicate vertex keeps its first index (Triangle ignores duplicates).
    if (index_of.emplace(key(x, y), i).second) subdiv.insert(cv::Point2f(x, y));
  }
  std::vector<cv::Vec6f> triangles;
  subdiv.getTriangleList(triangles);
  std::vector<int> corners;
  corners.reserve(3 * triangles.size());
  for (const cv::Vec6f& t : triangles) {
    int idx[3];
    bool inside = true;
    for (int c = 0; c < 3 && inside; ++c) {
      const auto it = index_of.find(key(t[2 * c], t[2 * c + 1]));
      inside = it != index_of.end();
      if (inside) idx[c] = it->second;
    }
    if (!inside) continue;  // a triangle touching Subdiv2D's outer vertices
    corners.insert(corners.end(), idx, idx + 3);
  }
  out->numberoftriangles = static_cast<int>(corners.size() / 3);
  out->numberofcorners = 3;
  out->trianglelist =
      static_cast<int*>(std::malloc(std::max<size_t>(1, corners.size()) * sizeof(int)));
  if (!corners.empty())
    std::memcpy(out->trianglelist, corners.data(), corners.size() * sizeof(int));
  out->pointlist = nullptr;
  g_stats.add(n, t0);
}
