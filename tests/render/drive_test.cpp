// renderDrive's grid heading (place.grid_heading_deg): the city, the route and the POV-Ray scene
// turn together on the ground, the sun is turned into the grid for the lighting, and every file
// written stays in ENU.
#include "sunvo/render/drive.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace sunvo::render {
namespace {

constexpr double kPi = 3.141592653589793;

std::string scenarioYaml(double heading_deg, int traffic_cars = 0) {
  char b[1024];
  std::snprintf(b, sizeof b,
                "name: grid_heading\n"
                "drive_number: 7\n"
                "place: {latitude_deg: 41.9, longitude_deg: 12.5, altitude_m: 20.0, "
                "grid_heading_deg: %.1f}\n"
                "start_utc: \"2026-07-14 07:40:00\"\n"
                "frames: 2\n"
                "seed: 11\n"
                "sky: {image_width: 64}\n"
                "city: {blocks_x: 3, blocks_y: 3}\n"
                "route: {rate_hz: 1}\n"
                "camera: {fu: 80.0, fv: 80.0, cu: 67.5, cv: 19.8, baseline_m: 0.537, width: 138, "
                "height: 42}\n"
                "render: {antialias_threshold: 0.0, quality: 4}\n"
                "traffic: {cars: %d}\n",
                heading_deg, traffic_cars);
  return b;
}

std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// Rows of numbers of a CSV (header skipped) or of a KITTI pose file.
std::vector<std::vector<double>> readRows(const std::string& path, bool header) {
  std::ifstream f(path);
  std::string line;
  if (header) std::getline(f, line);
  std::vector<std::vector<double>> rows;
  while (std::getline(f, line)) {
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream in(line);
    std::vector<double> row;
    for (double v; in >> v;) row.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

// The sun direction of the frame's POV-Ray parallel light (location - point_at), back from
// POV-Ray's <x, z, y> order into the scene's (x, y, z).
Eigen::Vector3d povSun(const std::string& pov_file) {
  const std::string text = readText(pov_file);
  const auto at = text.find("light_source { <");
  const auto to = text.find("point_at <", at);
  Eigen::Vector3d loc, aim;
  if (at == std::string::npos || to == std::string::npos ||
      std::sscanf(text.c_str() + at, "light_source { <%lf,%lf,%lf>", &loc.x(), &loc.z(),
                  &loc.y()) != 3 ||
      std::sscanf(text.c_str() + to, "point_at <%lf,%lf,%lf>", &aim.x(), &aim.z(), &aim.y()) != 3) {
    ADD_FAILURE() << pov_file << ": no parallel sun light";
    return Eigen::Vector3d::Zero();
  }
  return (loc - aim).normalized();
}

// Renders into test_render_cache/<test>_<heading>_<cars>: each test its own folders (ctest -j).
std::string renderWithHeading(const std::string& test, double heading_deg, int traffic_cars) {
  auto s = parseScenario(scenarioYaml(heading_deg, traffic_cars), "grid_heading");
  EXPECT_TRUE(s) << s.status().toString();
  if (!s) return {};
  const auto out = std::filesystem::path(SUNVO_BINARY_DIR) / "test_render_cache" /
                   (test + "_" + std::to_string(static_cast<int>(heading_deg)) + "_" +
                    std::to_string(traffic_cars));
  std::filesystem::remove_all(out);
  auto drive = renderDrive(*s, out.string(), 2, {});
  EXPECT_TRUE(drive) << drive.status().toString();
  return drive ? *drive : std::string();
}

TEST(Drive, GridHeadingTurnsTheCityOnTheGroundAndKeepsTheFilesInEnu) {
  const double heading_deg = 90.0;
  const std::string d0 = renderWithHeading("grid_heading", 0.0, 0),
                    d1 = renderWithHeading("grid_heading", heading_deg, 0);
  ASSERT_FALSE(d0.empty());
  ASSERT_FALSE(d1.empty());
  const Eigen::Matrix3d R_enu_g =
      Eigen::AngleAxisd(heading_deg * kPi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();

  // Same place and times: the same sun in ENU; the same route in the grid: the same motion (to
  // rounding: on aarch64 the turned route's relative poses differ by about 1e-22, FMA contraction).
  EXPECT_EQ(readText(d0 + "/gt/sun_enu.csv"), readText(d1 + "/gt/sun_enu.csv"));
  const auto rel0 = readRows(d0 + "/gt/poses_cam0.txt", false);
  const auto rel1 = readRows(d1 + "/gt/poses_cam0.txt", false);
  ASSERT_EQ(rel0.size(), rel1.size());
  for (std::size_t k = 0; k < rel0.size(); ++k) {
    ASSERT_EQ(rel0[k].size(), rel1[k].size());
    for (std::size_t i = 0; i < rel0[k].size(); ++i) EXPECT_NEAR(rel0[k][i], rel1[k][i], 1e-12);
  }
  const auto sun_enu = readRows(d0 + "/gt/sun_enu.csv", true);
  const auto pose0 = readRows(d0 + "/gt/poses_cam0_enu.txt", false);
  const auto pose1 = readRows(d1 + "/gt/poses_cam0_enu.txt", false);
  const auto sun_c0 = readRows(d0 + "/gt/sun_cam0.csv", true);
  const auto sun_c1 = readRows(d1 + "/gt/sun_cam0.csv", true);
  const auto body0 = readRows(d0 + "/gt/body_enu.csv", true);
  const auto body1 = readRows(d1 + "/gt/body_enu.csv", true);
  ASSERT_EQ(pose0.size(), 2u);
  ASSERT_EQ(pose1.size(), 2u);
  ASSERT_EQ(sun_enu.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    ASSERT_EQ(pose0[k].size(), 12u);
    ASSERT_EQ(pose1[k].size(), 12u);
    Eigen::Matrix3d R0, R1;
    Eigen::Vector3d t0, t1;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        R0(i, j) = pose0[k][4 * i + j];
        R1(i, j) = pose1[k][4 * i + j];
      }
      t0(i) = pose0[k][4 * i + 3];
      t1(i) = pose1[k][4 * i + 3];
    }
    // The camera's pose in ENU turns with the grid.
    EXPECT_TRUE((R_enu_g * R0).isApprox(R1, 1e-6)) << k;
    EXPECT_TRUE((R_enu_g * t0).isApprox(t1, 1e-6)) << k;
    // The sun in the camera is the ENU sun seen from the turned camera: it moved.
    const Eigen::Vector3d s_enu(sun_enu[k][3], sun_enu[k][4], sun_enu[k][5]);
    const Eigen::Vector3d s_c0(sun_c0[k][1], sun_c0[k][2], sun_c0[k][3]);
    const Eigen::Vector3d s_c1(sun_c1[k][1], sun_c1[k][2], sun_c1[k][3]);
    EXPECT_LT((R0.transpose() * s_enu - s_c0).norm(), 1e-5) << k;
    EXPECT_LT((R1.transpose() * s_enu - s_c1).norm(), 1e-5) << k;
    EXPECT_GT((s_c1 - s_c0).norm(), 0.1) << k;
    // The POV-Ray scene is the grid: its sun is the ENU sun turned back by the heading.
    char pov[32];
    std::snprintf(pov, sizeof pov, "/pov/frame_%06zu.pov", k);
    EXPECT_LT((povSun(d0 + pov) - s_enu).norm(), 1e-6) << k;
    EXPECT_LT((povSun(d1 + pov) - R_enu_g.transpose() * s_enu).norm(), 1e-6) << k;
    // Body states: position and velocity turned, yaw (column 7) plus the heading.
    ASSERT_EQ(body1[k].size(), 11u);
    const Eigen::Vector3d p0(body0[k][2], body0[k][3], body0[k][4]);
    const Eigen::Vector3d p1(body1[k][2], body1[k][3], body1[k][4]);
    const Eigen::Vector3d v0(body0[k][8], body0[k][9], body0[k][10]);
    const Eigen::Vector3d v1(body1[k][8], body1[k][9], body1[k][10]);
    EXPECT_LT((R_enu_g * p0 - p1).norm(), 1e-3) << k;
    EXPECT_LT((R_enu_g * v0 - v1).norm(), 1e-3) << k;
    EXPECT_NEAR(body1[k][7] - body0[k][7], heading_deg * kPi / 180.0, 1e-6) << k;
  }
  // The camera images differ: the sun falls on the streets from another side.
  for (const char* image : {"/image_02/data/0000000000.png", "/image_00/data/0000000001.png"}) {
    EXPECT_NE(readText(d0 + image), readText(d1 + image)) << image;
  }
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Moving cars (traffic.hpp) are drawn into each frame's scene, move between frames and change
// nothing but the images.
TEST(Drive, TrafficAddsMovingCarsToEveryFrameAndNothingElse) {
  const std::string d0 = renderWithHeading("traffic", 0.0, 0),
                    d1 = renderWithHeading("traffic", 0.0, 60);
  ASSERT_FALSE(d0.empty());
  ASSERT_FALSE(d1.empty());
  for (const char* gt : {"/gt/poses_cam0_enu.txt", "/gt/sun_cam0.csv", "/gt/body_enu.csv"}) {
    EXPECT_EQ(readText(d0 + gt), readText(d1 + gt)) << gt;
  }
  const std::string a0 = readText(d0 + "/pov/frame_000000.pov");
  const std::string f0 = readText(d1 + "/pov/frame_000000.pov");
  const std::string f1 = readText(d1 + "/pov/frame_000001.pov");
  EXPECT_EQ(count(a0, "box {"), 0u);  // the static city is in city.inc
  const std::size_t boxes = count(f0, "box {");
  EXPECT_EQ(boxes % 3, 0u);  // body, cabin, tyres per car
  EXPECT_GT(boxes, 3u * 30);
  EXPECT_LE(boxes, 3u * 60);
  // The same cars one frame (1 s) later are elsewhere.
  EXPECT_NE(f0.substr(f0.find("box {")), f1.substr(f1.find("box {")));
  EXPECT_NE(readText(d0 + "/image_02/data/0000000001.png"),
            readText(d1 + "/image_02/data/0000000001.png"));
}

TEST(Drive, GridHeadingIsRangeChecked) {
  auto s = parseScenario(scenarioYaml(190.0), "grid_heading");
  ASSERT_FALSE(s);
  EXPECT_NE(s.status().message().find("place.grid_heading_deg"), std::string::npos)
      << s.status().toString();
}

// A render stopped part-way is continued: the frames whose four images exist are kept, the rest
// is rendered, and the images equal those of the render made in one go. A folder rendered from
// another scenario is not resumed (the manifest names it); a fresh render leaves no image of an
// earlier one behind.
TEST(Drive, AResumedRenderKeepsTheFramesDoneAndRendersTheRest) {
  auto s = parseScenario(scenarioYaml(0.0), "resume");
  ASSERT_TRUE(s) << s.status().toString();
  s->frames = 3;
  const auto out = std::filesystem::path(SUNVO_BINARY_DIR) / "test_render_cache" / "resume";
  std::filesystem::remove_all(out);
  auto drive = renderDrive(*s, out.string(), 2, {});
  ASSERT_TRUE(drive) << drive.status().toString();
  const auto image = [&](int c, int k) {
    char b[64];
    std::snprintf(b, sizeof b, "/image_0%d/data/%010d.png", c, k);
    return *drive + b;
  };
  std::vector<std::string> first;
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 4; ++c) first.push_back(readText(image(c, k)));
  for (const std::string& bytes : first) ASSERT_GT(bytes.size(), 100u);

  // Frame 1 lost one image (a run killed between its renders); frame 2's scene changed.
  std::filesystem::remove(image(2, 1));
  {
    std::ofstream pov(*drive + "/pov/frame_000002.pov", std::ios::app);
    pov << "// edited\n";
  }
  DriveProgress last;
  auto again = renderDrive(
      *s, out.string(), 2, [&](const DriveProgress& p) { last = p; }, true);
  ASSERT_TRUE(again) << again.status().toString();
  EXPECT_EQ(last.kept_frames, 1u);  // frame 0
  EXPECT_EQ(last.total, 4u);        // frames 1 and 2, two cameras each
  EXPECT_EQ(last.done, 4u);
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(readText(image(c, k)), first[static_cast<std::size_t>(4 * k + c)])
          << "frame " << k << " camera " << c;
  for (const auto& e : std::filesystem::recursive_directory_iterator(*drive))
    EXPECT_NE(e.path().extension(), ".part") << e.path();

  // Another scenario's folder is not resumed.
  Scenario other = *s;
  other.source_text += "# another scenario\n";
  auto refused = renderDrive(other, out.string(), 2, {}, true);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.status().message().find("render_manifest.txt"), std::string::npos)
      << refused.status().toString();

  // A fresh render of fewer frames leaves none of the longer render's images behind.
  s->frames = 2;
  ASSERT_TRUE(renderDrive(*s, out.string(), 2, {}));
  EXPECT_TRUE(std::filesystem::exists(image(0, 1)));
  EXPECT_FALSE(std::filesystem::exists(image(0, 2)));

  // Resuming where nothing was rendered renders the whole drive.
  std::filesystem::remove_all(out);
  s->frames = 1;
  DriveProgress fresh;
  auto whole = renderDrive(
      *s, out.string(), 2, [&](const DriveProgress& p) { fresh = p; }, true);
  ASSERT_TRUE(whole) << whole.status().toString();
  EXPECT_EQ(fresh.kept_frames, 0u);
  EXPECT_EQ(fresh.done, 2u);
  EXPECT_EQ(readText(image(0, 0)), first[0]);
}

}  // namespace
}  // namespace sunvo::render
