// sunvo_geodesy: geodetic -> local ENU for a CSV table.
//   sunvo_geodesy [INPUT.csv | -]      (default: standard input), table on standard output.
// Exit codes: 0 ok, 2 bad input or usage, 1 output failure.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "sunvo/geodesy_cli/geodesy_csv.hpp"

namespace {

constexpr const char* kUsage =
    "usage: sunvo_geodesy [INPUT.csv | -]\n"
    "  INPUT: header 'origin_lat,origin_lon,origin_alt,lat,lon,alt' (deg, deg, m above WGS84),\n"
    "  one point per row. Writes the rows with east,north,up (m) appended to standard output.\n";

}  // namespace

int main(int argc, char** argv) {
  std::string path = "-";
  if (argc > 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  if (argc == 2) {
    path = argv[1];
    if (path == "-h" || path == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  }
  auto read_stdin = [] {
    std::ostringstream ss;
    ss << std::cin.rdbuf();
    return sunvo::files::TextFile::fromString("<stdin>", ss.str());
  };
  sunvo::Expected<sunvo::files::TextFile> in =
      path == "-" ? sunvo::Expected<sunvo::files::TextFile>(read_stdin())
                  : sunvo::files::TextFile::open(path);
  if (!in) {
    std::fprintf(stderr, "sunvo_geodesy: %s\n", in.status().message().c_str());
    return 2;
  }
  const sunvo::Status s = sunvo::geodesy_cli::convertGeodesyCsv(*in, std::cout);
  std::cout.flush();
  if (!s) {
    std::fprintf(stderr, "sunvo_geodesy: %s\n", s.message().c_str());
    return s.code() == sunvo::StatusCode::kIoError ? 1 : 2;
  }
  if (!std::cout) {
    std::fputs("sunvo_geodesy: write to standard output failed\n", stderr);
    return 1;
  }
  return 0;
}
