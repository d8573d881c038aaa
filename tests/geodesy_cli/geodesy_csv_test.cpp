#include "sunvo/geodesy_cli/geodesy_csv.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <GeographicLib/Geodesic.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sunvo::geodesy_cli {
namespace {

Status convert(const std::string& text, std::string& out) {
  files::TextFile in = files::TextFile::fromString("in.csv", text);
  std::ostringstream os;
  Status s = convertGeodesyCsv(in, os);
  out = os.str();
  return s;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream is(s);
  std::string l;
  while (std::getline(is, l)) out.push_back(l);
  return out;
}

TEST(GeodesyCsv, AppendsEastNorthUp) {
  std::string out;
  const Status s = convert(
      "origin_lat,origin_lon,origin_alt,lat,lon,alt\n"
      "49.0,8.4,0,49.001,8.4,0\n"
      "\n"
      "49.0, 8.4, 0, 49.0, 8.4, 12.5\n",
      out);
  ASSERT_TRUE(s) << s.toString();
  const auto l = lines(out);
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0], "origin_lat,origin_lon,origin_alt,lat,lon,alt,east,north,up");
  double s12 = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(49.0, 8.4, 49.001, 8.4, s12);
  double e = 0, n = 0, u = 0;
  ASSERT_EQ(std::sscanf(l[1].c_str(), "49.0,8.4,0,49.001,8.4,0,%lf,%lf,%lf", &e, &n, &u), 3);
  EXPECT_NEAR(e, 0.0, 1e-6);
  EXPECT_NEAR(n / s12, 1.0, 1e-6);
  EXPECT_NEAR(u, -0.00097, 1e-4);
  EXPECT_EQ(l[2], "49.0,8.4,0,49.0,8.4,12.5,0.000000,0.000000,12.500000");
}

TEST(GeodesyCsv, ErrorsNameLineAndField) {
  std::string out;
  const std::string header = "origin_lat,origin_lon,origin_alt,lat,lon,alt\n";
  Status s = convert(header + "49,8,0,49,8,0\n49,8,0,49.x,8,0\n", out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "in.csv:3: field 'lat': not a number: '49.x'");
  s = convert(header + "49,8,0,49,8\n", out);
  EXPECT_EQ(s.message(), "in.csv:2: expected 6 fields, found 5");
  s = convert(header + "95,8,0,49,8,0\n", out);
  EXPECT_EQ(s.message(), "in.csv:2: field 'origin_lat': outside [-90, 90] deg");
  s = convert(header + "49,8,0,49,8,1e9\n", out);
  EXPECT_EQ(s.message(), "in.csv:2: field 'alt': beyond 1e7 m");
  s = convert("origin_lat,origin_lon,origin_alt,lat,lon,height\n", out);
  EXPECT_EQ(s.message(), "in.csv:1: field 'alt': header column 6 is 'height'");
  s = convert("lat,lon\n", out);
  EXPECT_EQ(s.code(), StatusCode::kParseError);
  s = convert("", out);
  EXPECT_EQ(s.code(), StatusCode::kParseError);
}

// The executable: exit 0 on good input, 1 on bad input, 2 on a bad command line, errors on
// stderr.
TEST(GeodesyCli, ExitCodes) {
  const std::string exe = std::string(SUNVO_BINARY_DIR) + "/bin/sunvo_geodesy";
  ASSERT_TRUE(std::filesystem::exists(exe)) << exe;
  const auto dir =
      std::filesystem::temp_directory_path() / ("sunvo_geodesy_cli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "good.csv").string(), bad = (dir / "bad.csv").string();
  const std::string out = (dir / "out.csv").string(), err = (dir / "err.txt").string();
  std::ofstream(good) << "origin_lat,origin_lon,origin_alt,lat,lon,alt\n49,8,0,49,8.001,0\n";
  std::ofstream(bad) << "origin_lat,origin_lon,origin_alt,lat,lon,alt\n49,8,0,49,east,0\n";
  auto run = [&](const std::string& args) {
    const int rc =
        std::system((SUNVO_TOOL_EMULATOR + exe + " " + args + " > " + out + " 2> " + err).c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(run(good), 0);
  EXPECT_NE(slurp(out).find("49,8,0,49,8.001,0,73."), std::string::npos) << slurp(out);
  EXPECT_EQ(run("< " + good), 0);  // standard input
  EXPECT_EQ(run(bad), 1);
  EXPECT_NE(slurp(err).find(bad + ":2: field 'lon': not a number: 'east'"), std::string::npos)
      << slurp(err);
  EXPECT_EQ(run((dir / "absent.csv").string()), 1);
  EXPECT_EQ(run("a b"), 2);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sunvo::geodesy_cli
