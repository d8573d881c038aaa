#pragma once
// Synthetic stereo scenes for the motion, backend and vo tests: random 3-D landmarks around a known
// camera trajectory, projected through a KITTI-like rectified stereo camera with pixel noise and
// optional outliers. Deterministic for a seed.

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"

namespace sunvo::testing {

inline StereoCamera kittiCamera() {
  StereoCamera c;
  c.fu = 707.0912;
  c.fv = 707.0912;
  c.cu = 601.8873;
  c.cv = 183.1104;
  c.baseline_m = 0.53715;
  c.width = 1242;
  c.height = 375;
  return c;
}

// A small rotation about the camera y axis (yaw, deg) and forward motion (m): T_k_km1.
inline Isometry3 forwardMotion(double forward_m, double yaw_deg, double pitch_deg = 0.0) {
  Isometry3 T_km1_k = Isometry3::Identity();
  T_km1_k.linear() = expSO3(Eigen::Vector3d(pitch_deg * M_PI / 180.0, yaw_deg * M_PI / 180.0, 0.0));
  T_km1_k.translation() = Eigen::Vector3d(0.02 * forward_m, 0.01 * forward_m, forward_m);
  return T_km1_k.inverse();
}

struct SceneOptions {
  int num_landmarks = 3000;
  double pixel_noise_px = 1.0;    // std of Gaussian noise on uL, vL, uR
  double outlier_fraction = 0.0;  // fraction of observations per frame replaced by garbage
  int max_per_frame = 150;        // observations kept per frame (the nearest-id first)
  double max_depth_m = 60.0;
  std::uint64_t seed = 1;
};

// Landmarks in world = camera-0 frame, spread along a corridor of `length_m` ahead of the camera.
inline std::vector<Eigen::Vector3d> makeLandmarks(const SceneOptions& o, double length_m) {
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> ux(-25.0, 25.0), uy(-4.0, 2.0), uz(2.0, length_m + 60.0);
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(static_cast<std::size_t>(o.num_landmarks));
  for (int i = 0; i < o.num_landmarks; ++i) pts.emplace_back(ux(rng), uy(rng), uz(rng));
  return pts;
}

// Observations of frame k at pose T_k_w (world -> camera k). Outliers keep their landmark id but
// get random image positions (so they are matched by id, like a wrong KLT track).
inline FrameFeatures observe(const StereoCamera& cam, const std::vector<Eigen::Vector3d>& pts_w,
                             const Isometry3& T_k_w, std::uint64_t k, const SceneOptions& o) {
  std::mt19937_64 rng(o.seed * 1000003ULL + k);
  std::normal_distribution<double> noise(0.0, o.pixel_noise_px);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  FrameFeatures f;
  f.sequence = k;
  f.time_ns = static_cast<TimeNs>(k) * 100'000'000;
  for (std::size_t i = 0; i < pts_w.size(); ++i) {
    const Eigen::Vector3d p = T_k_w * pts_w[i];
    if (p.z() < 1.0 || p.z() > o.max_depth_m) continue;
    const Eigen::Vector3d y = cam.project(p);
    if (y.x() < 0 || y.x() >= cam.width || y.y() < 0 || y.y() >= cam.height) continue;
    if (y.x() - y.z() < 0) continue;
    StereoObservation ob;
    ob.landmark_id = static_cast<std::int64_t>(i);
    ob.u_left = y.x() + noise(rng);
    ob.v_left = y.y() + noise(rng);
    ob.u_right = y.x() - y.z() + noise(rng);
    ob.v_right = ob.v_left;
    f.observations.push_back(ob);
    if (static_cast<int>(f.observations.size()) >= o.max_per_frame) break;
  }
  for (auto& ob : f.observations) {
    if (unit(rng) < o.outlier_fraction) {
      ob.u_left = unit(rng) * (cam.width - 1);
      ob.v_left = unit(rng) * (cam.height - 1);
      ob.u_right = ob.u_left - 1.0 - unit(rng) * 60.0;
      ob.v_right = ob.v_left;
    }
  }
  return f;
}

// Poses T_w_k of a trajectory of n frames with constant motion T_k_km1.
inline std::vector<Isometry3> trajectory(int n, const Isometry3& T_k_km1) {
  std::vector<Isometry3> T_w_k(static_cast<std::size_t>(n), Isometry3::Identity());
  for (int k = 1; k < n; ++k) {
    T_w_k[static_cast<std::size_t>(k)] = T_w_k[static_cast<std::size_t>(k - 1)] * T_k_km1.inverse();
  }
  return T_w_k;
}

inline double rotationErrorDeg(const Isometry3& A, const Isometry3& B) {
  return rotationAngle(A.linear().transpose() * B.linear()) * 180.0 / M_PI;
}

}  // namespace sunvo::testing
