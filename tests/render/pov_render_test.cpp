// Renders tiny POV-Ray scenes and checks the camera model, stereo geometry and sun shadows
// against the analytic predictions. Needs `povray` on PATH (scripts/setup.sh installs it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/render/perez_sky.hpp"
#include "sunvo/render/pov.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::render {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

std::string testDir(const std::string& name) {
  const std::string d = std::string(SUNVO_BINARY_DIR) + "/render_test/" + name;
  std::filesystem::create_directories(d);
  return d;
}

// Renders cameras[cam] of a scene and returns the image as 8-bit gray.
cv::Mat render(const std::string& name, const Scene& scene, const std::vector<StereoCamera>& cams,
               const std::vector<Isometry3>& poses, const Lighting& light, int cam, double aa) {
  const std::string dir = testDir(name);
  std::ofstream(dir + "/scene.pov") << povFrame(cams, poses, light, "", &scene);
  RenderJob j;
  j.work_dir = dir;
  j.pov_file = "scene.pov";
  j.output_png = "out_" + std::to_string(cam) + ".png";
  j.log_file = "povray_" + std::to_string(cam) + ".log";
  j.width = cams[static_cast<std::size_t>(cam)].width;
  j.height = cams[static_cast<std::size_t>(cam)].height;
  j.cam_index = cam;
  RenderQuality q;
  q.antialias_threshold = aa;
  q.antialias_depth = 3;
  const Status st = runPovray(j, q);
  EXPECT_TRUE(st.isOk()) << st.toString();
  return cv::imread(dir + "/" + j.output_png, cv::IMREAD_GRAYSCALE);
}

// Camera 10 m above the ENU origin looking north, level: x_c = east, y_c = down, z_c = north.
Isometry3 lookingNorth(double height) {
  Isometry3 T = Isometry3::Identity();
  T.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0, 0, height);
  return T;
}

TEST(PovCamera, MarkersAppearWhereThePinholeModelPutsThem) {
  // Deliberately off-centre principal point and unequal focal lengths.
  const StereoCamera cam{180.0, 170.0, 71.3, 68.6, 0.5, 200, 120};
  const Isometry3 T_enu_c = lookingNorth(50.0);
  const std::vector<Eigen::Vector3d> p_c = {{0.0, 0.0, 6.0}, {-1.9, -1.0, 7.0}, {2.5, 1.3, 5.0}};
  Scene scene;
  scene.ground_texture = "pigment { rgb 0 } finish { ambient 0 diffuse 0 }";
  for (const auto& p : p_c) {
    scene.primitives.push_back({Primitive::Kind::kSphere,
                                T_enu_c * p,
                                {},
                                0.06,
                                "pigment { rgb 1 } finish { ambient 1 diffuse 0 }"});
  }
  Lighting L;
  L.ambient_rgb = Eigen::Vector3d::Ones();
  L.sun_enu = -Eigen::Vector3d::UnitZ();  // no sun
  L.flat_sky_rgb = Eigen::Vector3d::Zero();
  const cv::Mat img = render("projection", scene, {cam}, {T_enu_c}, L, 0, 0.05);
  ASSERT_FALSE(img.empty());
  for (const auto& p : p_c) {
    const Eigen::Vector3d uvd = cam.project(p);
    // Intensity centroid in a 9x9 window around the prediction.
    double sw = 0, su = 0, sv = 0;
    const int u0 = static_cast<int>(std::lround(uvd.x())),
              v0 = static_cast<int>(std::lround(uvd.y()));
    for (int v = v0 - 4; v <= v0 + 4; ++v)
      for (int u = u0 - 4; u <= u0 + 4; ++u) {
        const double w = img.at<unsigned char>(v, u);
        sw += w;
        su += w * u;
        sv += w * v;
      }
    ASSERT_GT(sw, 255.0) << "marker not found near the predicted pixel";
    const double du = su / sw - uvd.x(), dv = sv / sw - uvd.y();
    std::printf("marker at (%.2f, %.2f): centroid error (%.3f, %.3f) px\n", uvd.x(), uvd.y(), du,
                dv);
    EXPECT_LT(std::abs(du), 0.25);
    EXPECT_LT(std::abs(dv), 0.25);
  }
}

TEST(PovCamera, StereoDisparityMatchesBaselineTimesFocalOverDepth) {
  const StereoCamera cam{120.0, 120.0, 95.0, 52.0, 0.5, 200, 100};
  const double Z = 4.0;  // expected disparity = 120 * 0.5 / 4 = 15 px
  const Isometry3 T0 = lookingNorth(50.0);
  Isometry3 T_c0_c1 = Isometry3::Identity();
  T_c0_c1.translation() = Eigen::Vector3d(cam.baseline_m, 0, 0);
  const Isometry3 T1 = T0 * T_c0_c1;
  Scene scene;
  scene.ground_texture = "pigment { rgb 0 }";
  // A fronto-parallel textured plate at depth Z (thin box spanning x,y in the camera frame).
  const Eigen::Vector3d a = T0 * Eigen::Vector3d(-8, -4, Z),
                        b = T0 * Eigen::Vector3d(8, 4, Z + 0.01);
  scene.primitives.push_back(
      {Primitive::Kind::kBox, a.cwiseMin(b), a.cwiseMax(b), 0.0,
       "pigment { granite scale 0.4 color_map { [0 rgb 0.05] [1 rgb 0.95] } } "
       "finish { ambient 1 diffuse 0 }"});
  Lighting L;
  L.ambient_rgb = Eigen::Vector3d::Ones();
  L.sun_enu = -Eigen::Vector3d::UnitZ();
  const cv::Mat left = render("disparity", scene, {cam, cam}, {T0, T1}, L, 0, 0.1);
  const cv::Mat right = render("disparity", scene, {cam, cam}, {T0, T1}, L, 1, 0.1);
  ASSERT_FALSE(left.empty());
  ASSERT_FALSE(right.empty());
  // NCC block matching (11x11) along the row, parabola sub-pixel refinement.
  std::vector<double> disp;
  const int r = 5;
  for (int v = 15; v < cam.height - 15; v += 10) {
    for (int u = 45; u < cam.width - 15; u += 10) {
      cv::Mat tl;
      left(cv::Rect(u - r, v - r, 2 * r + 1, 2 * r + 1)).convertTo(tl, CV_32F);
      std::vector<double> score;
      for (int d = 0; d <= 30; ++d) {
        cv::Mat tr;
        right(cv::Rect(u - d - r, v - r, 2 * r + 1, 2 * r + 1)).convertTo(tr, CV_32F);
        cv::Mat res;
        cv::matchTemplate(tr, tl, res, cv::TM_CCOEFF_NORMED);
        score.push_back(res.at<float>(0, 0));
      }
      const int best =
          static_cast<int>(std::max_element(score.begin(), score.end()) - score.begin());
      if (best == 0 || best == 30 || score[static_cast<std::size_t>(best)] < 0.8) continue;
      const double sm = score[static_cast<std::size_t>(best - 1)],
                   s0 = score[static_cast<std::size_t>(best)],
                   sp = score[static_cast<std::size_t>(best + 1)];
      disp.push_back(best + 0.5 * (sm - sp) / (sm - 2 * s0 + sp));
    }
  }
  ASSERT_GT(disp.size(), 30u);
  std::sort(disp.begin(), disp.end());
  const double expected = cam.fu * cam.baseline_m / Z;
  const double median = disp[disp.size() / 2];
  std::printf("disparity: median %.3f px over %zu patches, expected %.3f px, range [%.3f, %.3f]\n",
              median, disp.size(), expected, disp.front(), disp.back());
  EXPECT_NEAR(median, expected, 0.5);
  std::size_t within = 0;
  for (double d : disp) within += std::abs(d - expected) < 0.5 ? 1 : 0;
  EXPECT_GT(static_cast<double>(within) / static_cast<double>(disp.size()), 0.9);
}

TEST(PovSun, PoleShadowPointsAwayFromTheEphemerisAzimuth) {
  // Sun from the SPA for Karlsruhe, 2026-06-21 08:30 UTC; a 3 m pole (0.3 m radius) seen from
  // 20 m above (20 px per ground metre).
  sun::SpaOptions spa;
  spa.latitude_deg = 49.0114;
  spa.longitude_deg = 8.4044;
  spa.elevation_m = 115.0;
  auto sp = sun::computeSolarPosition(civilToUtcNs(2026, 6, 21, 8, 30, 0, 0), spa);
  ASSERT_TRUE(sp);
  const StereoCamera cam{400.0, 400.0, 99.5, 99.5, 0.5, 200, 200};
  Isometry3 T = Isometry3::Identity();
  T.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // x_c = east, y_c = south, z_c = down
  T.translation() = Eigen::Vector3d(0, 0, 20);
  Scene scene;
  scene.ground_texture = "pigment { rgb 0.8 }";
  const double h = 3.0;
  scene.primitives.push_back(
      {Primitive::Kind::kCylinder, {0, 0, 0}, {0, 0, h}, 0.3, "pigment { rgb 0.8 }"});
  Lighting L;
  L.sun_enu = sp->sun_enu;
  L.sun_rgb = Eigen::Vector3d::Ones();
  L.ambient_rgb = Eigen::Vector3d::Constant(0.1);
  const cv::Mat img = render("shadow", scene, {cam}, {T}, L, 0, 0.0);
  ASSERT_FALSE(img.empty());
  // Shadow pixels: dark ground; direction from the pole base (image centre) to their centroid
  // weighted by distance, and the farthest shadow pixel for the length.
  const Eigen::Vector3d base = cam.project(T.inverse() * Eigen::Vector3d(0, 0, 0));
  double se = 0, sn = 0, far = 0;
  int n = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      if (img.at<unsigned char>(v, u) > 128) continue;
      const double e = (u - base.x()) / cam.fu * 20.0, nn = -(v - base.y()) / cam.fv * 20.0;
      if (std::hypot(e, nn) < 0.5) continue;  // the pole itself
      se += e;
      sn += nn;
      far = std::max(far, std::hypot(e, nn));
      ++n;
    }
  ASSERT_GT(n, 50);
  const double shadow_az = std::fmod(std::atan2(se, sn) / kDeg + 360.0, 360.0);
  const double expected = std::fmod(sp->azimuth_deg + 180.0, 360.0);
  double diff = std::abs(shadow_az - expected);
  diff = std::min(diff, 360.0 - diff);
  // The far end of the shadow of a cylinder of radius r lies h tan(z) + r from the axis.
  const double expected_len = h * std::tan(sp->zenith_deg * kDeg) + 0.3;
  std::printf(
      "sun azimuth %.2f deg, zenith %.2f deg: shadow azimuth %.2f (expected %.2f), length "
      "%.2f m (expected %.2f)\n",
      sp->azimuth_deg, sp->zenith_deg, shadow_az, expected, far, expected_len);
  EXPECT_LT(diff, 2.0);
  EXPECT_NEAR(far, expected_len, 0.05 * expected_len);
}

TEST(PovSky, SkySphereImageIsBrightTowardTheSun) {
  // Sun due east at 20 deg elevation; a camera looking east at the horizon must see a brighter
  // sky than the same camera looking west (checks the HDR spherical map's orientation).
  const Eigen::Vector3d sun(std::cos(20 * kDeg), 0.0, std::sin(20 * kDeg));
  const std::string dir = testDir("sky");
  const StereoCamera cam{40.0, 40.0, 39.5, 19.5, 0.5, 80, 40};
  Isometry3 east = Isometry3::Identity();  // x_c = south, y_c = down, z_c = east
  east.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  east.translation() = Eigen::Vector3d(0, 0, 50);
  Isometry3 west = Isometry3::Identity();  // x_c = north, y_c = down, z_c = west
  west.linear() << 0, 0, -1, 1, 0, 0, 0, -1, 0;
  west.translation() = Eigen::Vector3d(0, 0, 50);
  // Tilt both up by 25 deg so the view is all sky (ground hidden by the downward limit).
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(25 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix();
  east.linear() = east.linear() * tilt;
  west.linear() = west.linear() * tilt;
  Scene scene;
  scene.ground_texture = "pigment { rgb 0 }";
  Lighting L;
  L.sun_enu = -Eigen::Vector3d::UnitZ();
  L.sky_image = "sky.hdr";
  const PerezSky sky(sun, SkyOptions{3.0});
  ASSERT_TRUE(cv::imwrite(dir + "/sky.hdr",
                          sky.equirectangular(256, 128, 1.0 / 20000.0, Eigen::Vector3d::Zero())));
  const cv::Mat ie = render("sky", scene, {cam, cam}, {east, west}, L, 0, 0.0);
  const cv::Mat iw = render("sky", scene, {cam, cam}, {east, west}, L, 1, 0.0);
  ASSERT_FALSE(ie.empty());
  ASSERT_FALSE(iw.empty());
  const double me = cv::mean(ie)[0], mw = cv::mean(iw)[0];
  std::printf("mean sky gray looking east (sun side) %.1f, west %.1f\n", me, mw);
  EXPECT_GT(me, 1.3 * mw);
}

}  // namespace
}  // namespace sunvo::render
