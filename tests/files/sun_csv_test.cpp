#include "sunvo/files/sun_csv.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace sunvo::files {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("sunvo_sun_csv_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(SunCsv, ReadsTheRealSequence00File) {
  auto sun = readSunCsv(std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_sun_cam.csv");
  ASSERT_TRUE(sun) << sun.status().toString();
  ASSERT_EQ(sun->sun_c.size(), 4541u);  // one per frame of sequence 00
  EXPECT_NEAR(sun->sun_c[0].x(), 0.23639, 1e-4);
  EXPECT_NEAR(sun->sun_c[0].y(), -0.57199, 1e-4);  // camera y down: the sun is above
  EXPECT_NEAR(sun->sun_c[0].norm(), 1.0, 1e-12);
}

TEST(SunCsv, ErrorsNameFileLineAndField) {
  auto bad = readSunCsv(writeTemp("a.csv", "frame,sx,sy,sz\n0,0,0,1\n1,0,x,1\n"));
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("sunvo_sun_csv_a.csv:3: field 'sy': not a number"),
            std::string::npos)
      << bad.status().message();
  auto gap = readSunCsv(writeTemp("b.csv", "frame,sx,sy,sz\n0,0,0,1\n2,0,0,1\n"));
  ASSERT_FALSE(gap);
  EXPECT_NE(gap.status().message().find(":3: field 'frame': expected frame 1"), std::string::npos);
  auto norm = readSunCsv(writeTemp("c.csv", "frame,sx,sy,sz\n0,0,0,2\n"));
  ASSERT_FALSE(norm);
  EXPECT_NE(norm.status().message().find("not a unit vector"), std::string::npos);
  auto header = readSunCsv(writeTemp("d.csv", "f,sx,sy,sz\n0,0,0,1\n"));
  ASSERT_FALSE(header);
  EXPECT_NE(header.status().message().find(":1: header"), std::string::npos);
  auto count = readSunCsv(writeTemp("e.csv", "frame,sx,sy,sz\n0,0,1\n"));
  ASSERT_FALSE(count);
  EXPECT_NE(count.status().message().find(":2: expected 4 fields"), std::string::npos);
}

TEST(SunCsv, WhatIsWrittenReadsBack) {
  SunCsv sun;
  sun.sun_c = {Eigen::Vector3d(0.6, -0.8, 0.0), Eigen::Vector3d(0.0, -0.6, 0.8)};
  const std::string path = writeTemp("round_trip.csv", "");
  ASSERT_TRUE(writeSunCsv(path, sun).isOk());
  auto back = readSunCsv(path);
  ASSERT_TRUE(back) << back.status().toString();
  ASSERT_EQ(back->sun_c.size(), 2u);
  EXPECT_NEAR((back->sun_c[1] - sun.sun_c[1]).norm(), 0.0, 1e-9);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sunvo::files
