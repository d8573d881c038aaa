// sunvo_geodesy: geodetic -> local ENU for a CSV table.
//   sunvo_geodesy [INPUT.csv | -]      (default: standard input), table on standard output.
// Exit codes (firmware_app/cli): 0 ok, 2 a bad command line, 1 an unreadable or malformed input
// (the message names file, line and field) or an output failure.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "sunvo/cli/cli.hpp"
#include "sunvo/geodesy_cli/geodesy_csv.hpp"

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_geodesy";
  std::string path = "-";
  CLI::App app{
      "Geodetic -> local East-North-Up for a CSV table. Input header "
      "'origin_lat,origin_lon,origin_alt,lat,lon,alt' (deg, deg, m above WGS84), one point per "
      "row; writes the rows with east,north,up (m) appended to standard output.",
      kProgram};
  app.add_option("input", path, "the CSV table; - or none: standard input");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  auto read_stdin = [] {
    std::ostringstream ss;
    ss << std::cin.rdbuf();
    return sunvo::files::TextFile::fromString("<stdin>", ss.str());
  };
  sunvo::Expected<sunvo::files::TextFile> in =
      path == "-" ? sunvo::Expected<sunvo::files::TextFile>(read_stdin())
                  : sunvo::files::TextFile::open(path);
  if (!in) return sunvo::cli::fail(kProgram, in.status().message());
  const sunvo::Status s = sunvo::geodesy_cli::convertGeodesyCsv(*in, std::cout);
  std::cout.flush();
  if (!s) return sunvo::cli::fail(kProgram, s.message());
  if (!std::cout) return sunvo::cli::fail(kProgram, "write to standard output failed");
  return sunvo::cli::kExitOk;
}
