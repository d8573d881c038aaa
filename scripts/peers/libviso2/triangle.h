// Stand-in for the Triangle library (J. R. Shewchuk) that libviso2 bundles.
// Triangle is not available here, so this header declares the part of its
// C interface that libviso2's Matcher::removeOutliers uses, with libviso2's
// float coordinates, and triangle_shim.cpp computes the Delaunay triangulation
// with OpenCV's Subdiv2D. Written for the sunvo peer benchmark; not Triangle.
#ifndef LIBVISO2_TRIANGLE_SHIM_H
#define LIBVISO2_TRIANGLE_SHIM_H

struct triangulateio {
  float* pointlist;
  float* pointattributelist;
  int* pointmarkerlist;
  int numberofpoints;
  int numberofpointattributes;

  int* trianglelist;
  float* triangleattributelist;
  float* trianglearealist;
  int* neighborlist;
  int numberoftriangles;
  int numberofcorners;
  int numberoftriangleattributes;

  int* segmentlist;
  int* segmentmarkerlist;
  int numberofsegments;

  float* holelist;
  int numberofholes;

  float* regionlist;
  int numberofregions;

  int* edgelist;
  int* edgemarkerlist;
  float* normlist;
  int numberofedges;
};

// Only the switches "zQB" are supported (zero-based indices, quiet, no
// boundary markers); out->trianglelist is malloc'ed, out->pointlist is NULL.
void triangulate(char* switches, struct triangulateio* in, struct triangulateio* out,
                 struct triangulateio* vorout);

#endif
