#pragma once
// A synthetic outdoor frame with a known sun for the sunvision tests: a KITTI-like level camera
// 1.65 m above a flat ground; above the horizon a Perez clear sky (this library's own model,
// bluish, sRGB-encoded) or a dark textured wall; on the ground the cast shadows of vertical
// poles: ground point p is shadowed by the pole at b when p - b runs along the horizontal
// anti-sun direction within the shadow length h tan(zenith) and within the pole radius of it.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>

#include "../support/synthetic_stereo.hpp"
#include "sunvo/core/camera.hpp"
#include "sunvo/sunvision/sky_model.hpp"

namespace sunvo::sunvision::testing {

// The shared KITTI-like rectified camera of the tests (1242 x 375).
using sunvo::testing::kittiCamera;

inline unsigned char toSrgb8(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<unsigned char>(std::lround(255.0 * s));
}

// Sun (azimuth from the optical axis toward the right, zenith from up) in the level camera.
inline Eigen::Vector3d sunInLevelCamera(double azimuth_deg, double zenith_deg) {
  const double a = azimuth_deg * std::numbers::pi / 180.0,
               z = zenith_deg * std::numbers::pi / 180.0;
  return {std::sin(z) * std::sin(a), -std::cos(z), std::sin(z) * std::cos(a)};
}

inline cv::Mat renderScene(const StereoCamera& cam, const Eigen::Vector3d& sun_c, bool with_sky,
                           bool with_poles) {
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const double height = 1.65, pole_h = 4.0, pole_r = 0.2;
  const PerezParameters p = clearSkyLuminanceParameters(2.5);
  const Eigen::Vector3d s = sun_c.normalized();
  Eigen::Vector3d away = -(s - s.dot(up) * up);  // horizontal direction shadows point to
  const double shadow_len = std::min(pole_h * away.norm() / std::max(s.dot(up), 1e-3), 40.0);
  away.normalize();
  // Pole feet on the ground (camera frame: x right, z forward, y = +height).
  const double poles[][2] = {{-3.0, 6.0}, {3.0, 9.0},   {-4.0, 12.0}, {2.5, 15.0},
                             {4.0, 7.0},  {-2.0, 10.0}, {1.0, 18.0}};
  cv::Mat img(cam.height, cam.width, CV_8UC3);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d d =
          Eigen::Vector3d((u - cam.cu) / cam.fu, (v - cam.cv) / cam.fv, 1.0).normalized();
      const double du = d.dot(up);
      cv::Vec3b& px = img.at<cv::Vec3b>(v, u);
      if (du > 0.0) {
        if (with_sky) {
          const double gamma = std::acos(std::clamp(d.dot(s), -1.0, 1.0));
          const double L = 0.15 * perezGradation(p, du) * perezScattering(p, gamma);
          px = cv::Vec3b(toSrgb8(L), toSrgb8(0.85 * L), toSrgb8(0.7 * L));
        } else {
          const unsigned char g = static_cast<unsigned char>(40 + ((u / 9 + v / 7) % 2) * 25);
          px = cv::Vec3b(g, g, g);
        }
        continue;
      }
      const Eigen::Vector3d ground = d * (height / -du);
      bool shadow = false;
      if (with_poles) {
        for (const auto& b : poles) {
          const Eigen::Vector3d rel = ground - Eigen::Vector3d(b[0], height, b[1]);
          const double t = rel.dot(away);
          if (t < 0.0 || t > shadow_len) continue;
          if ((rel - t * away - rel.dot(up) * up).norm() < pole_r) shadow = true;
        }
      }
      // Sunlit asphalt vs the same lit by the bluish sky only.
      px = shadow ? cv::Vec3b(toSrgb8(0.07), toSrgb8(0.055), toSrgb8(0.045))
                  : cv::Vec3b(toSrgb8(0.2), toSrgb8(0.2), toSrgb8(0.2));
    }
  }
  return img;
}

}  // namespace sunvo::sunvision::testing
