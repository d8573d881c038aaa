#include "sunvo/sun_cli/sun_csv.hpp"

#include <array>
#include <chrono>
#include <cstdio>

namespace sunvo::sun_cli {
namespace {

constexpr std::array<std::string_view, 6> kInputColumns{"utc_iso", "lat_deg",       "lon_deg",
                                                        "alt_m",   "pressure_mbar", "temp_c"};
constexpr std::string_view kOutputExtra =
    "zenith_deg,zenith_refracted_deg,azimuth_deg,east,north,up";

bool twoDigits(std::string_view s, int& out) {
  if (s.size() != 2 || s[0] < '0' || s[0] > '9' || s[1] < '0' || s[1] > '9') return false;
  out = (s[0] - '0') * 10 + (s[1] - '0');
  return true;
}

void appendFixed(std::string& out, double v, int decimals) {
  std::array<char, 64> buf{};
  std::snprintf(buf.data(), buf.size(), "%.*f", decimals, v);
  out += buf.data();
}

}  // namespace

Expected<TimeNs> parseUtcIso(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  const std::string shown(text);
  // The civil part is at least "YYYY-MM-DDTHH:MM:SS" (19 characters); a zone suffix starts at
  // the first 'Z', '+' or '-' after it.
  std::int64_t offset_s = 0;
  std::string_view civil = text;
  if (text.size() > 19) {
    const std::size_t zone = text.find_first_of("Z+-", 19);
    if (zone != std::string_view::npos) {
      civil = text.substr(0, zone);
      const std::string_view suffix = text.substr(zone);
      if (suffix == "Z") {
        offset_s = 0;
      } else if (suffix.front() == '+' || suffix.front() == '-') {
        // +hh, +hhmm or +hh:mm; the written time is that far ahead of UTC.
        const std::string_view body = suffix.substr(1);
        int hh = 0, mm = 0;
        bool ok = false;
        if (body.size() == 2) ok = twoDigits(body, hh);
        if (body.size() == 4)
          ok = twoDigits(body.substr(0, 2), hh) && twoDigits(body.substr(2), mm);
        if (body.size() == 5) {
          ok = body[2] == ':' && twoDigits(body.substr(0, 2), hh) && twoDigits(body.substr(3), mm);
        }
        if (!ok || hh > 18 || mm > 59) {
          return parseError("time '" + shown + "': bad UTC offset '" + std::string(suffix) +
                            "' (expected Z, +hh:mm, +hhmm or +hh)");
        }
        offset_s = (suffix.front() == '-' ? -1 : 1) * (hh * 3600 + mm * 60);
      } else {
        return parseError("time '" + shown + "': unexpected text after the time");
      }
    }
  }
  return parseCivilTime(civil, offset_s);
}

Status SunCsvOptions::validate() const {
  SUNVO_RETURN_IF_ERROR(spa.validate());
  if (angle_decimals < 0 || angle_decimals > 12) {
    return invalidArgument("SunCsvOptions.angle_decimals = " + std::to_string(angle_decimals) +
                           " is outside [0, 12]");
  }
  if (vector_decimals < 0 || vector_decimals > 15) {
    return invalidArgument("SunCsvOptions.vector_decimals = " + std::to_string(vector_decimals) +
                           " is outside [0, 15]");
  }
  return Status::ok();
}

Expected<SunCsvStats> convertSunCsv(files::TextFile& in, const SunCsvOptions& options,
                                    std::string& out) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SunCsvStats stats;
  std::string_view line;
  // Header: exactly the six input columns, in order.
  bool have_header = false;
  while (in.nextLine(line)) {
    if (files::isBlank(line)) continue;
    const auto fields = files::splitFields(line, ',');
    bool ok = fields.size() == kInputColumns.size();
    for (std::size_t i = 0; ok && i < fields.size(); ++i) ok = fields[i] == kInputColumns[i];
    if (!ok) {
      return in.lineError("bad header '" + std::string(line) +
                          "' (expected utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c)");
    }
    have_header = true;
    break;
  }
  if (!have_header) return parseError(in.path() + ": empty input, expected a CSV header");
  std::string result;
  result += "utc_iso,lat_deg,lon_deg,alt_m,pressure_mbar,temp_c,";
  result += kOutputExtra;
  result += '\n';

  while (in.nextLine(line)) {
    if (files::isBlank(line)) continue;
    const auto f = files::splitFields(line, ',');
    if (f.size() != kInputColumns.size()) {
      return in.lineError("expected " + std::to_string(kInputColumns.size()) +
                          " comma-separated fields, got " + std::to_string(f.size()));
    }
    auto t = parseUtcIso(f[0]);
    if (!t) return in.error(kInputColumns[0], t.status().message());

    // Each numeric column is range-checked by SpaOptions::validate() on an otherwise default
    // options struct, so that the error names the CSV column rather than the options key.
    sun::SpaOptions spa = options.spa;
    double* targets[] = {&spa.latitude_deg, &spa.longitude_deg, &spa.elevation_m,
                         &spa.pressure_mbar, &spa.temperature_c};
    for (std::size_t c = 1; c < kInputColumns.size(); ++c) {
      auto v = in.parseDouble(f[c], kInputColumns[c]);
      if (!v) return v.status();
      sun::SpaOptions single = options.spa;
      double* single_targets[] = {&single.latitude_deg, &single.longitude_deg, &single.elevation_m,
                                  &single.pressure_mbar, &single.temperature_c};
      *single_targets[c - 1] = *v;
      const Status s = single.validate();
      if (!s.isOk()) return in.error(kInputColumns[c], s.message());
      *targets[c - 1] = *v;
    }

    const auto start = std::chrono::steady_clock::now();
    auto pos = sun::computeSolarPosition(*t, spa);
    stats.spa_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now() - start)
                        .count();
    if (!pos) return in.lineError(pos.status().message());

    for (std::size_t c = 0; c < f.size(); ++c) {
      result.append(f[c]);
      result += ',';
    }
    appendFixed(result, pos->zenith_deg, options.angle_decimals);
    result += ',';
    appendFixed(result, pos->zenith_refracted_deg, options.angle_decimals);
    result += ',';
    appendFixed(result, pos->azimuth_deg, options.angle_decimals);
    for (int k = 0; k < 3; ++k) {
      result += ',';
      appendFixed(result, pos->sun_enu[k], options.vector_decimals);
    }
    result += '\n';
    ++stats.rows;
  }
  out += result;
  return stats;
}

}  // namespace sunvo::sun_cli
