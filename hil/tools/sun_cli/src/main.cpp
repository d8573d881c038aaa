// sunvo_sun: batch sun positions (NREL SPA) for a CSV of UTC times and places.
//   sunvo_sun [-i IN.csv] [-o OUT.csv] [--delta-t S] [--delta-ut1 S] [--vector-zenith
//             unrefracted|refracted] [--timing]
// Reads stdin / writes stdout unless -i / -o are given. Exit status (firmware_app/cli): 0 ok,
// 2 a bad command line or option value, 1 a bad input (the message names file, line and field) or
// an output that cannot be written.

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "sunvo/cli/cli.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/sun_cli/sun_csv.hpp"

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_sun";
  std::string in_path;
  std::string out_path;
  bool timing = false;
  double delta_t_s = 0.0;
  std::string vector_zenith = "unrefracted";
  sunvo::sun_cli::SunCsvOptions options;
  CLI::App app{
      "Batch sun positions (NREL SPA) for a CSV of UTC times and places.\n"
      "  in:  utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c\n"
      "  out: the same + zenith_deg,zenith_refracted_deg,azimuth_deg,east,north,up\n"
      "  utc_iso: YYYY-MM-DD[T| ]HH:MM:SS[.fff] with Z, +hh:mm/-hh:mm or nothing (= UTC)",
      kProgram};
  app.add_option("-i,--input", in_path, "input CSV (default or -: standard input)");
  app.add_option("-o,--output", out_path, "output CSV (default or -: standard output)");
  app.add_option("--delta-t", delta_t_s, "TT-UT1, s (default: built-in table 1990-2025)");
  app.add_option("--delta-ut1", options.spa.delta_ut1_s, "UT1-UTC, s");
  app.add_option("--vector-zenith", vector_zenith, "zenith of the ENU sun vector")
      ->check(CLI::IsMember({"unrefracted", "refracted"}));
  app.add_flag("--timing", timing, "print the time per SPA call to stderr");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  if (app.count("--delta-t") > 0) options.spa.delta_t_s = delta_t_s;
  options.spa.vector_zenith = vector_zenith == "refracted"
                                  ? sunvo::sun::SunVectorZenith::kRefracted
                                  : sunvo::sun::SunVectorZenith::kUnrefracted;
  if (const sunvo::Status s = options.validate(); !s.isOk()) {
    std::cerr << kProgram << ": " << s.message() << "\n";
    return sunvo::cli::kExitUsage;
  }

  sunvo::Expected<sunvo::files::TextFile> input = [&]() -> sunvo::Expected<sunvo::files::TextFile> {
    if (!in_path.empty() && in_path != "-") return sunvo::files::TextFile::open(in_path);
    std::string content;
    std::array<char, 65536> buf{};
    std::size_t n = 0;
    while ((n = std::fread(buf.data(), 1, buf.size(), stdin)) > 0) content.append(buf.data(), n);
    if (std::ferror(stdin)) return sunvo::ioError("<stdin>: read failed");
    return sunvo::files::TextFile::fromString("<stdin>", std::move(content));
  }();
  if (!input) return sunvo::cli::fail(kProgram, input.status().message());

  std::string out;
  auto stats = sunvo::sun_cli::convertSunCsv(*input, options, out);
  if (!stats) return sunvo::cli::fail(kProgram, stats.status().message());

  if (out_path.empty() || out_path == "-") {
    std::cout << out << std::flush;
    if (!std::cout) return sunvo::cli::fail(kProgram, "writing stdout failed");
  } else {
    std::ofstream file(out_path, std::ios::binary);
    file << out;
    file.close();
    if (!file) {
      return sunvo::cli::fail(kProgram, "cannot write '" + out_path + "': " + std::strerror(errno));
    }
  }
  if (timing) {
    const double us = stats->rows > 0 ? static_cast<double>(stats->spa_ns) * 1e-3 /
                                            static_cast<double>(stats->rows)
                                      : 0.0;
    std::fprintf(stderr, "sunvo_sun: %lld rows, %.3f us per SPA call\n",
                 static_cast<long long>(stats->rows), us);
  }
  return sunvo::cli::kExitOk;
}
