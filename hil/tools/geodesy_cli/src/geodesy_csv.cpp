#include "sunvo/geodesy_cli/geodesy_csv.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include "sunvo/geodesy/local_enu.hpp"

namespace sunvo::geodesy_cli {
namespace {

constexpr std::array<std::string_view, 6> kColumns{"origin_lat", "origin_lon", "origin_alt",
                                                   "lat",        "lon",        "alt"};

}  // namespace

Status convertGeodesyCsv(files::TextFile& in, std::ostream& out) {
  std::string_view line;
  bool have_header = false;
  while (in.nextLine(line)) {
    if (files::isBlank(line)) continue;
    const auto fields = files::splitFields(line, ',');
    if (!have_header) {
      have_header = true;
      if (fields.size() != kColumns.size()) {
        return in.lineError("header: expected 6 columns " +
                            std::string("origin_lat,origin_lon,origin_alt,lat,lon,alt, found ") +
                            std::to_string(fields.size()));
      }
      for (std::size_t i = 0; i < kColumns.size(); ++i) {
        if (fields[i] != kColumns[i]) {
          return in.error(kColumns[i], "header column " + std::to_string(i + 1) + " is '" +
                                           std::string(fields[i]) + "'");
        }
      }
      out << "origin_lat,origin_lon,origin_alt,lat,lon,alt,east,north,up\n";
      continue;
    }
    if (fields.size() != kColumns.size()) {
      return in.lineError("expected 6 fields, found " + std::to_string(fields.size()));
    }
    std::array<double, 6> v{};
    for (std::size_t i = 0; i < kColumns.size(); ++i) {
      auto d = in.parseDouble(fields[i], kColumns[i]);
      if (!d) return d.status();
      v[i] = *d;
    }
    const geodesy::GeodeticPoint origin{v[0], v[1], v[2]};
    const geodesy::GeodeticPoint point{v[3], v[4], v[5]};
    // Range errors from geodesy name "lat_deg"/"lon_deg"/"alt_m"; report the CSV column instead.
    for (int which = 0; which < 2; ++which) {
      const geodesy::GeodeticPoint& p = which == 0 ? origin : point;
      const std::size_t base = which == 0 ? 0 : 3;
      if (!(p.lat_deg >= -90.0 && p.lat_deg <= 90.0)) {
        return in.error(kColumns[base], "outside [-90, 90] deg");
      }
      if (!(std::abs(p.alt_m) <= 1e7)) return in.error(kColumns[base + 2], "beyond 1e7 m");
    }
    auto frame = geodesy::LocalEnuFrame::create(origin);
    if (!frame) return in.lineError(frame.status().message());
    auto enu = frame->toEnu(point);
    if (!enu) return in.lineError(enu.status().message());
    for (std::size_t i = 0; i < fields.size(); ++i) out << fields[i] << ',';
    std::array<char, 96> buf{};
    // Values that round to zero print as "0.000000", never "-0.000000".
    auto tidy = [](double m) { return std::abs(m) < 5e-7 ? 0.0 : m; };
    std::snprintf(buf.data(), buf.size(), "%.6f,%.6f,%.6f\n", tidy(enu->x()), tidy(enu->y()),
                  tidy(enu->z()));
    out << buf.data();
  }
  if (!have_header) return parseError(in.path() + ": empty input (no header line)");
  if (!out) return ioError("write failed");
  return Status::ok();
}

}  // namespace sunvo::geodesy_cli
