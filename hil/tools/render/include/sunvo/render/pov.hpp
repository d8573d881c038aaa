#pragma once
// POV-Ray scene text and the povray process pool.
// Axes: the scene lives in local ENU; POV-Ray (left-handed, y up) gets the point <e, u, n>.
// The swap of two axes is a reflection, applied to every point and every camera vector alike,
// so the rendered image is exactly the one of the ENU scene (rays are linear in the vectors).

#include <functional>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"
#include "sunvo/render/scene.hpp"

namespace sunvo::render {

// "<e,u,n>" for an ENU point or vector.
std::string povVector(const Eigen::Vector3d& v_enu);

// Exact pinhole camera block for camera c with pose T_enu_c (camera: x right, y down,
// z forward) and intrinsics fu fv cu cv over a width x height image.
// Derivation: POV-Ray shoots, for screen coordinates (sx, sy) in [-1/2, 1/2] (sx to the right,
// sy up), the ray direction + sx right + sy up. Pixel column i (0-based, its centre at
// u = i in the pinhole convention u = fu X/Z + cu) has sx = (i + 1/2)/W - 1/2, so
// u = (sx + 1/2) W - 1/2 and the pinhole ray (X/Z, Y/Z, 1) = ((u - cu)/fu, (v - cv)/fv, 1) is
//   sx * (W/fu, 0, 0) + ((W-1)/2 - cu)/fu x-offset,
//   with v = (1/2 - sy) H - 1/2:  sy * (0, -H/fv, 0) + ((H-1)/2 - cv)/fv y-offset.
// Hence right = C (W/fu, 0, 0), up = C (0, -H/fv, 0),
// direction = C (((W-1)/2 - cu)/fu, ((H-1)/2 - cv)/fv, 1) with C = R_enu_c; the principal
// point offset is exact, no crop needed (POV-Ray does not require perpendicular vectors).
std::string povCamera(const StereoCamera& cam, const Isometry3& T_enu_c);

struct Lighting {
  Eigen::Vector3d sun_enu = Eigen::Vector3d::UnitZ();            // unit vector toward the sun
  Eigen::Vector3d sun_rgb = Eigen::Vector3d::Ones();             // light colour (linear, scaled)
  Eigen::Vector3d ambient_rgb = Eigen::Vector3d::Constant(0.2);  // ambient_light (linear)
  std::string sky_image;  // HDR file for the sky_sphere (map_type 1); empty: flat sky colour
  Eigen::Vector3d flat_sky_rgb = Eigen::Vector3d(0.5, 0.6, 0.8);
  std::string materials;  // POV text written before the scene: a styled frame's textures, fog
};

// The scene part (declarations, ground plane and primitives) as POV-Ray text.
std::string povSceneBody(const Scene& scene);
// Primitives alone as POV-Ray text (a frame's moving objects, after the static scene).
std::string povPrimitives(const std::vector<Primitive>& primitives);

// A complete frame: global settings, lighting and sky, `#include "include_file"` when
// include_file is non-empty (else the scene body inline), and one camera per pose selected by
// the declared variable CAM (povray Declare=CAM=k), default 0.
std::string povFrame(const std::vector<StereoCamera>& cams, const std::vector<Isometry3>& T_enu_c,
                     const Lighting& light, const std::string& include_file,
                     const Scene* inline_scene);

struct RenderQuality {
  double antialias_threshold = 0.3;  // +A threshold; 0 = no antialiasing. [0, 1]
  int antialias_depth = 2;           // +R, [1, 9]
  int quality = 9;                   // +Q, [0, 11]
  Status validate() const;
};

struct RenderJob {
  std::string work_dir;  // cwd of povray; paths below are relative to it
  std::string pov_file;
  std::string output_png;
  int width = 0, height = 0;
  int cam_index = 0;     // Declare=CAM=...
  std::string log_file;  // povray's stdout/stderr
};

// Runs the jobs with at most max_parallel povray children (each single-threaded, +WT1).
// on_done(index, status) is called in the caller's thread as each job ends. Returns the first
// failure (after all jobs have ended), or ok.
Status runPovrayJobs(const std::vector<RenderJob>& jobs, const RenderQuality& quality,
                     int max_parallel,
                     const std::function<void(std::size_t, const Status&)>& on_done);

// Convenience: render one job synchronously.
Status runPovray(const RenderJob& job, const RenderQuality& quality);

}  // namespace sunvo::render
