// Delaunay triangulation for libviso2's outlier removal through CGAL's
// Delaunay_triangulation_2 (see triangle.h), a stand-in for Shewchuk's Triangle
// of about its speed (both O(n log n) with exact predicates); its thread-CPU
// time is counted (shim_stats.hpp). sunvo's code; peer builds only.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <utility>
#include <vector>

#include "shim_stats.hpp"
#include "triangle.h"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

ShimStats g_stats{"CGAL Delaunay_triangulation_2"};

}  // namespace

void triangulate(char*, struct triangulateio* in, struct triangulateio* out,
                 struct triangulateio*) {
  const double t0 = shimThreadCpuSeconds();
  const int n = in->numberofpoints;
  std::vector<std::pair<Kernel::Point_2, int>> points;
  points.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    points.emplace_back(Kernel::Point_2(in->pointlist[2 * i], in->pointlist[2 * i + 1]), i);
  }
  // Range insertion sorts spatially first; a duplicate point is inserted once (as Triangle).
  Delaunay dt(points.begin(), points.end());
  std::vector<int> corners;
  corners.reserve(6 * static_cast<std::size_t>(n));
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    for (int c = 0; c < 3; ++c) corners.push_back(f->vertex(c)->info());
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
