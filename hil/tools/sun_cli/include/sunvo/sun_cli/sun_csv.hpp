#pragma once
// The batch sun-position CSV of the `sunvo_sun` tool, as a library so that it can be tested:
//   in:  utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c
//   out: the same columns (as read) + zenith_deg,zenith_refracted_deg,azimuth_deg,east,north,up
// zenith_deg is the unrefracted topocentric zenith, zenith_refracted_deg the refracted one,
// azimuth_deg is from north clockwise, and east,north,up the unit ENU sun vector (built from the
// zenith chosen by SpaOptions::vector_zenith, unrefracted by default).

#include <cstdint>
#include <string>
#include <string_view>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/sun/spa.hpp"

namespace sunvo::sun_cli {

// Parses an ISO-8601-like UTC time: "YYYY-MM-DD[T| ]HH:MM:SS[.f{1,9}]" followed by "Z", by a
// "+hh:mm" / "-hh:mm" / "+hhmm" / "+hh" offset of the written local time ahead of UTC, or by
// nothing (then it is taken as UTC). Returns UTC ns; errors are kParseError naming the text.
Expected<TimeNs> parseUtcIso(std::string_view text);

struct SunCsvOptions {
  // Model settings shared by every row; the per-row columns (latitude, longitude, height,
  // pressure, temperature) replace the corresponding fields.
  sun::SpaOptions spa;
  // Output precision of the angle columns, decimal places. Valid [0, 12].
  int angle_decimals = 6;
  // Output precision of the vector columns, decimal places. Valid [0, 15].
  int vector_decimals = 9;

  Status validate() const;
};

struct SunCsvStats {
  std::int64_t rows = 0;    // data rows converted
  std::int64_t spa_ns = 0;  // monotonic time spent inside computeSolarPosition, ns
};

// Converts the whole input; appends the output CSV (header first) to `out`. The first error
// names the input's path, line and field ("in.csv:3: field 'lat_deg': ..."); nothing is
// appended to `out` for the rows from that line on. Blank lines are skipped.
Expected<SunCsvStats> convertSunCsv(files::TextFile& in, const SunCsvOptions& options,
                                    std::string& out);

}  // namespace sunvo::sun_cli
