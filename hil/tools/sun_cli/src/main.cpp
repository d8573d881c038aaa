// sunvo_sun: batch sun positions (NREL SPA) for a CSV of UTC times and places.
//   sunvo_sun [-i IN.csv] [-o OUT.csv] [--delta-t S] [--delta-ut1 S] [--vector-zenith
//             unrefracted|refracted] [--timing]
// Reads stdin / writes stdout unless -i / -o are given. Exit status: 0 ok, 2 bad usage or bad
// input (the message names file, line and field), 1 when the output cannot be written.

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>

#include "sunvo/files/text_file.hpp"
#include "sunvo/sun_cli/sun_csv.hpp"

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitIoError = 1;

void usage() {
  std::cerr << "usage: sunvo_sun [-i IN.csv] [-o OUT.csv] [--delta-t S] [--delta-ut1 S]\n"
               "                 [--vector-zenith unrefracted|refracted] [--timing]\n"
               "  in:  utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c\n"
               "  out: the same + zenith_deg,zenith_refracted_deg,azimuth_deg,east,north,up\n"
               "  utc_iso: YYYY-MM-DD[T| ]HH:MM:SS[.fff] with Z, +hh:mm/-hh:mm or nothing (= UTC)\n"
               "  --delta-t S     TT-UT1 in s (default: built-in table 1990-2025)\n"
               "  --delta-ut1 S   UT1-UTC in s (default 0)\n"
               "  --timing        print the time per SPA call to stderr\n";
}

bool parseNumber(const char* text, double& out) {
  char* end = nullptr;
  errno = 0;
  out = std::strtod(text, &end);
  return errno == 0 && end != text && *end == '\0';
}

}  // namespace

int main(int argc, char** argv) {
  std::string in_path;
  std::string out_path;
  bool timing = false;
  sunvo::sun_cli::SunCsvOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (arg == "-h" || arg == "--help") {
      usage();
      return 0;
    } else if (arg == "-i" || arg == "--input") {
      const char* v = value();
      if (!v) return usage(), kExitBadInput;
      in_path = v;
    } else if (arg == "-o" || arg == "--output") {
      const char* v = value();
      if (!v) return usage(), kExitBadInput;
      out_path = v;
    } else if (arg == "--delta-t" || arg == "--delta-ut1") {
      const char* v = value();
      double x = 0.0;
      if (!v || !parseNumber(v, x)) {
        std::cerr << "sunvo_sun: " << arg << " needs a number of seconds\n";
        return kExitBadInput;
      }
      if (arg == "--delta-t") {
        options.spa.delta_t_s = x;
      } else {
        options.spa.delta_ut1_s = x;
      }
    } else if (arg == "--vector-zenith") {
      const char* v = value();
      const std::string_view which = v ? v : "";
      if (which == "unrefracted") {
        options.spa.vector_zenith = sunvo::sun::SunVectorZenith::kUnrefracted;
      } else if (which == "refracted") {
        options.spa.vector_zenith = sunvo::sun::SunVectorZenith::kRefracted;
      } else {
        std::cerr << "sunvo_sun: --vector-zenith takes 'unrefracted' or 'refracted'\n";
        return kExitBadInput;
      }
    } else if (arg == "--timing") {
      timing = true;
    } else {
      std::cerr << "sunvo_sun: unknown argument '" << arg << "'\n";
      usage();
      return kExitBadInput;
    }
  }
  if (const sunvo::Status s = options.validate(); !s.isOk()) {
    std::cerr << "sunvo_sun: " << s.message() << "\n";
    return kExitBadInput;
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
  if (!input) {
    std::cerr << "sunvo_sun: " << input.status().message() << "\n";
    return kExitBadInput;
  }

  std::string out;
  auto stats = sunvo::sun_cli::convertSunCsv(*input, options, out);
  if (!stats) {
    std::cerr << "sunvo_sun: " << stats.status().message() << "\n";
    return kExitBadInput;
  }

  if (out_path.empty() || out_path == "-") {
    std::cout << out << std::flush;
    if (!std::cout) {
      std::cerr << "sunvo_sun: writing stdout failed\n";
      return kExitIoError;
    }
  } else {
    std::ofstream file(out_path, std::ios::binary);
    file << out;
    file.close();
    if (!file) {
      std::cerr << "sunvo_sun: cannot write '" << out_path << "': " << std::strerror(errno) << "\n";
      return kExitIoError;
    }
  }
  if (timing) {
    const double us = stats->rows > 0 ? static_cast<double>(stats->spa_ns) * 1e-3 /
                                            static_cast<double>(stats->rows)
                                      : 0.0;
    std::fprintf(stderr, "sunvo_sun: %lld rows, %.3f us per SPA call\n",
                 static_cast<long long>(stats->rows), us);
  }
  return 0;
}
