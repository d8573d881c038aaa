#include "sunvo/sun_cli/sun_csv.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace sunvo::sun_cli {
namespace {

constexpr const char* kHeader = "utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c\n";

TEST(SunCsv, ParsesUtcIsoForms) {
  const TimeNs t = civilToUtcNs(2011, 9, 30, 12, 8, 26, 500000000);
  for (const char* text :
       {"2011-09-30T12:08:26.5Z", "2011-09-30 12:08:26.5Z", "2011-09-30T12:08:26.500000000Z",
        "2011-09-30T12:08:26.5", "2011-09-30T14:08:26.5+02:00", "2011-09-30T14:08:26.5+0200",
        "2011-09-30T14:08:26.5+02", "2011-09-30T05:38:26.5-06:30", "  2011-09-30T12:08:26.5Z "}) {
    auto p = parseUtcIso(text);
    ASSERT_TRUE(p) << text << ": " << p.status().toString();
    EXPECT_EQ(*p, t) << text;
  }
  // Offset crossing midnight and a date change.
  auto p = parseUtcIso("2003-10-17T20:30:30-07:00");
  ASSERT_TRUE(p);
  EXPECT_EQ(*p, civilToUtcNs(2003, 10, 18, 3, 30, 30, 0));
}

TEST(SunCsv, RejectsBadUtcIso) {
  for (const char* text :
       {"", "2011-09-30", "2011-09-30T12:08Z", "2011-09-30T12:08:26.5+7",
        "2011-09-30T12:08:26.5+19:00", "2011-09-30T12:08:26.5+02:60", "2011-09-30T12:08:26.5ZZ",
        "2011-09-30T12:08:26.5 UTC", "2011-02-30T12:08:26Z", "2011-09-30T12:08:26,5Z"}) {
    auto p = parseUtcIso(text);
    EXPECT_FALSE(p) << text;
    if (!p) {
      EXPECT_EQ(p.status().code(), StatusCode::kParseError) << text;
    }
  }
}

// The SPA report example as a CSV row, in local time with its offset: the refracted zenith and
// azimuth must come out as the report's 50.11162 / 194.34024 deg (to 1e-5 with Delta T 67 s).
TEST(SunCsv, ConvertsReportExampleRow) {
  auto in = files::TextFile::fromString(
      "in.csv", std::string(kHeader) +
                    "2003-10-17T12:30:30-07:00,39.742476,-105.1786,1830.14,820,11\n\n"
                    "2003-10-17 19:30:30Z, 39.742476, -105.1786, 1830.14, 820, 11\r\n");
  SunCsvOptions o;
  o.spa.delta_t_s = 67.0;
  std::string out;
  auto stats = convertSunCsv(in, o, out);
  ASSERT_TRUE(stats) << stats.status().toString();
  EXPECT_EQ(stats->rows, 2);
  std::istringstream lines(out);
  std::string line;
  ASSERT_TRUE(std::getline(lines, line));
  EXPECT_EQ(line,
            "utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c,zenith_deg,zenith_refracted_deg,"
            "azimuth_deg,east,north,up");
  for (int row = 0; row < 2; ++row) {
    ASSERT_TRUE(std::getline(lines, line));
    const auto f = files::splitFields(line, ',');
    ASSERT_EQ(f.size(), 12u) << line;
    EXPECT_EQ(f[1], "39.742476");
    const double zen = std::stod(std::string(f[6]));
    const double zen_refr = std::stod(std::string(f[7]));
    const double az = std::stod(std::string(f[8]));
    const double e = std::stod(std::string(f[9]));
    const double n = std::stod(std::string(f[10]));
    const double u = std::stod(std::string(f[11]));
    EXPECT_NEAR(zen_refr, 50.11162, 1e-5);
    EXPECT_NEAR(az, 194.34024, 1e-5);
    EXPECT_NEAR(90.0 - zen, 39.872046, 1e-5);
    EXPECT_NEAR(e * e + n * n + u * u, 1.0, 1e-8);
    EXPECT_NEAR(u, std::cos(zen * std::numbers::pi / 180.0),
                1e-8);  // unrefracted zenith by default
  }
  EXPECT_FALSE(std::getline(lines, line));
}

TEST(SunCsv, ErrorsNameLineAndField) {
  struct Case {
    std::string body;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"2003-10-17T19:30:30Z,91,0,0,1000,10\n", "in.csv:2: field 'lat_deg'"},
      {"2003-10-17T19:30:30Z,0,200,0,1000,10\n", "in.csv:2: field 'lon_deg'"},
      {"2003-10-17T19:30:30Z,0,0,abc,1000,10\n", "in.csv:2: field 'alt_m': not a number"},
      {"2003-10-17T19:30:30Z,0,0,0,-5,10\n", "in.csv:2: field 'pressure_mbar'"},
      {"2003-10-17T19:30:30Z,0,0,0,1000,\n", "in.csv:2: field 'temp_c'"},
      {"2003-10-17T19:30:30Q,0,0,0,1000,10\n", "in.csv:2: field 'utc_iso'"},
      {"2003-10-17T19:30:30Z,0,0,0,1000,10\n2003-10-17T19:30:30Z,0,0,0,1000\n",
       "in.csv:3: expected 6 comma-separated fields, got 5"},
  };
  for (const Case& c : cases) {
    auto in = files::TextFile::fromString("in.csv", kHeader + c.body);
    std::string out;
    auto stats = convertSunCsv(in, SunCsvOptions{}, out);
    ASSERT_FALSE(stats) << c.body;
    EXPECT_EQ(stats.status().code(), StatusCode::kParseError) << stats.status().toString();
    EXPECT_NE(stats.status().message().find(c.expected), std::string::npos)
        << stats.status().message() << " (expected '" << c.expected << "')";
    EXPECT_TRUE(out.empty());
  }
  auto bad_header = files::TextFile::fromString("in.csv", "utc,lat_deg\n");
  std::string out;
  auto stats = convertSunCsv(bad_header, SunCsvOptions{}, out);
  ASSERT_FALSE(stats);
  EXPECT_NE(stats.status().message().find("in.csv:1: bad header"), std::string::npos);
  auto empty = files::TextFile::fromString("in.csv", "");
  EXPECT_FALSE(convertSunCsv(empty, SunCsvOptions{}, out));
}

TEST(SunCsv, OptionsValidateNamesKey) {
  SunCsvOptions o;
  o.angle_decimals = 20;
  EXPECT_NE(o.validate().message().find("angle_decimals"), std::string::npos);
  o = SunCsvOptions{};
  o.spa.delta_ut1_s = 2.0;
  EXPECT_NE(o.validate().message().find("delta_ut1_s"), std::string::npos);
}

// The program itself: exit 0 and a CSV file on good input, exit 1 and a line/field message on
// bad input, exit 2 on a bad command line.
int runTool(const std::string& args, const std::string& err_path) {
  const std::string tool = std::string(SUNVO_TOOL_EMULATOR) + SUNVO_BINARY_DIR + "/bin/sunvo_sun";
  const int rc = std::system((tool + " " + args + " 2>'" + err_path + "'").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SunCsv, ToolExitCodes) {
  const std::filesystem::path dir =
      std::filesystem::path(SUNVO_BINARY_DIR) / "tests" / "sun_cli" / "tool_io";
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "good.csv").string();
  const std::string bad = (dir / "bad.csv").string();
  const std::string out = (dir / "out.csv").string();
  const std::string err = (dir / "err.txt").string();
  std::ofstream(good) << kHeader << "2011-09-30T12:08:26.5Z,49.011,8.416,115,1013.25,15\n";
  std::ofstream(bad) << kHeader << "2011-09-30T12:08:26.5Z,49.011,8.416,115,1013.25,15\n"
                     << "2011-09-30T12:08:26.5Z,49.011,east,115,1013.25,15\n";
  std::filesystem::remove(out);
  EXPECT_EQ(runTool("-i '" + good + "' -o '" + out + "'", err), 0) << slurp(err);
  const std::string text = slurp(out);
  EXPECT_NE(text.find("2011-09-30T12:08:26.5Z,49.011,8.416,115,1013.25,15,"), std::string::npos)
      << text;
  EXPECT_EQ(runTool("-i '" + bad + "' -o '" + out + "'", err), 1);
  EXPECT_NE(slurp(err).find("bad.csv:3: field 'lon_deg'"), std::string::npos) << slurp(err);
  EXPECT_EQ(runTool("--delta-t nope < '" + good + "'", err), 2);
  EXPECT_EQ(runTool("--bogus", err), 2);
}

}  // namespace
}  // namespace sunvo::sun_cli
