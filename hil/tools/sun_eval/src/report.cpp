#include "report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "sunvo/report/json_writer.hpp"

namespace sunvo::suneval {
namespace {

std::string percent(double share) {
  return std::isfinite(share) ? formatNumber(100.0 * share, 0) + " %" : "–";
}

std::string degrees(double v) {
  return std::isfinite(v) ? formatNumber(v) + "°" : "–";
}

std::string signedDegrees(double v) {
  if (!std::isfinite(v)) return "–";
  std::string out = v > 0.0 ? "+" : "";
  out += formatNumber(v);
  out += "°";
  return out;
}

// "share (n/d)" so a share over few frames reads as what it is.
std::string countedPercent(double share, int n, int d) {
  if (d == 0) return "–";
  return percent(share) + " (" + std::to_string(n) + "/" + std::to_string(d) + ")";
}

std::string csvNumber(double v) {
  if (!std::isfinite(v)) return "";
  char b[32];
  std::snprintf(b, sizeof(b), "%.6g", v);
  return b;
}

void cueJson(report::JsonWriter& w, const char* name, const CueSummary& c) {
  w.key(name)
      .beginObject()
      .key("frames")
      .value(c.frames)
      .key("informative")
      .value(c.informative)
      .key("informative_share")
      .value(c.informative_share)
      .key("abs_error_deg_median")
      .value(c.median_deg)
      .key("abs_error_deg_p90")
      .value(c.p90_deg)
      .key("gross")
      .value(c.gross)
      .key("gross_share")
      .value(c.gross_share)
      .endObject();
}

}  // namespace

std::string formatNumber(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char b[32];
  std::snprintf(b, sizeof(b), "%.*f", digits, v);
  return b;
}

std::string markdownReport(const std::vector<SetResult>& results, const ReportMeta& meta) {
  std::ostringstream md;
  md << "# Image sun estimators: errors against the true sun\n\n"
     << "Azimuth errors (camera-frame azimuth atan2(x, z), estimate minus truth, wrapped) over the "
        "valid estimates; bias = their signed median (+ = the estimates lie clockwise of the "
        "true sun seen from above); gross = |azimuth error| > 45 deg, over the valid estimates; "
        "gross flagged = share of all gross estimates (valid or not) that the estimator flagged "
        "invalid; < 2σ = share of the valid estimates with |azimuth error| < 2 sigma (95 % when "
        "sigma is calibrated); kept = accepted by the default sun gate against the true-pose "
        "prediction, over all frames; CPU = process CPU time per call. VO prior attitude error "
     << formatNumber(meta.prior_error_deg) << " deg per axis (1 sigma), seed " << meta.seed
     << "; OpenCV threads " << meta.threads << ". Cameras:";
  std::string last_set;
  for (const SetResult& r : results) {
    if (r.set == last_set) continue;
    md << (last_set.empty() ? " " : ", ") << r.set << " "
       << (r.camera == "color" ? "colour (camera 2)" : "gray (camera 0)");
    last_set = r.set;
  }
  md << ".\n\n"
     << "| estimator | set | frames | valid | az. median | az. p90 | bias | gross | "
        "gross flagged | < 2σ | zen. median | kept by gate | CPU ms/call median | p90 |\n"
     << "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
        "| ---: |\n";
  for (const SetResult& r : results) {
    const EstimatorSummary& s = r.summary;
    md << "| " << r.estimator << " | " << r.set << " | " << s.frames << " | "
       << percent(s.valid_share) << " | " << degrees(s.azimuth_median_deg) << " | "
       << degrees(s.azimuth_p90_deg) << " | " << signedDegrees(s.azimuth_bias_deg) << " | "
       << percent(s.gross_share) << " | "
       << countedPercent(s.gross_flagged, s.gross_invalid, s.gross_any) << " | "
       << percent(s.within_2sigma_share) << " | " << degrees(s.zenith_median_deg) << " | "
       << percent(s.kept_share) << " | " << formatNumber(s.cpu_ms_median) << " | "
       << formatNumber(s.cpu_ms_p90) << " |\n";
  }
  bool any_cues = false;
  for (const SetResult& r : results) any_cues = any_cues || r.cues.has_value();
  if (!any_cues) return md.str();
  md << "\nLalonde's cues alone (horizon-frame azimuth of each cue's best cell against the true "
        "sun's; the shadow cue's error is axial, in [0, 90] deg, since a shadow line fixes the "
        "sun's azimuth only up to 180 deg; over the frames where the cue was informative):\n\n"
     << "| estimator | set | cue | informative | median | p90 | gross |\n"
     << "| --- | --- | --- | ---: | ---: | ---: | ---: |\n";
  for (const SetResult& r : results) {
    if (!r.cues) continue;
    for (const auto& [name, c] : {std::pair<const char*, const CueSummary*>{"sky", &r.cues->sky},
                                  {"shadow", &r.cues->shadow}}) {
      md << "| " << r.estimator << " | " << r.set << " | " << name << " | "
         << countedPercent(c->informative_share, c->informative, c->frames) << " | "
         << degrees(c->median_deg) << " | " << degrees(c->p90_deg) << " | "
         << percent(c->gross_share) << " |\n";
    }
  }
  return md.str();
}

std::string jsonReport(const std::vector<SetResult>& results, const ReportMeta& meta) {
  report::JsonWriter w;
  w.beginObject().key("prior_error_deg").value(meta.prior_error_deg);
  w.key("seed").value(static_cast<std::uint64_t>(meta.seed)).key("threads").value(meta.threads);
  w.key("gross_threshold_deg").value(kGrossAzimuthDeg);
  w.key("results").beginArray();
  for (const SetResult& r : results) {
    const EstimatorSummary& s = r.summary;
    w.beginObject().key("estimator").value(r.estimator).key("dataset").value(r.set);
    w.key("camera").value(r.camera);
    w.key("frames").value(s.frames).key("valid").value(s.valid);
    w.key("valid_share").value(s.valid_share);
    w.key("azimuth_abs_error_deg_median").value(s.azimuth_median_deg);
    w.key("azimuth_abs_error_deg_p90").value(s.azimuth_p90_deg);
    w.key("azimuth_signed_error_deg_median").value(s.azimuth_bias_deg);
    w.key("zenith_abs_error_deg_median").value(s.zenith_median_deg);
    w.key("zenith_abs_error_deg_p90").value(s.zenith_p90_deg);
    w.key("gross_errors").value(s.gross).key("gross_share").value(s.gross_share);
    w.key("gross_any").value(s.gross_any).key("gross_invalid").value(s.gross_invalid);
    w.key("gross_flagged_invalid_share").value(s.gross_flagged);
    w.key("sigma_checked").value(s.sigma_checked).key("within_2sigma").value(s.within_2sigma);
    w.key("within_2sigma_share").value(s.within_2sigma_share);
    w.key("kept_by_gate").value(s.kept).key("kept_share").value(s.kept_share);
    w.key("cpu_ms_median").value(s.cpu_ms_median).key("cpu_ms_p90").value(s.cpu_ms_p90);
    w.key("wall_ms_median").value(s.wall_ms_median).key("wall_ms_p90").value(s.wall_ms_p90);
    if (r.cues) {
      w.key("cues").beginObject();
      cueJson(w, "sky", r.cues->sky);
      cueJson(w, "shadow", r.cues->shadow);
      w.endObject();
    }
    // Every frame's errors (null where undefined), valid or not, with its validity.
    w.key("valid_frames").beginArray();
    for (const FrameResult& f : r.frames) w.value(f.valid);
    w.endArray().key("azimuth_errors_deg").beginArray();
    for (const FrameResult& f : r.frames) w.value(f.azimuth_error_deg);
    w.endArray().key("zenith_errors_deg").beginArray();
    for (const FrameResult& f : r.frames) w.value(f.zenith_error_deg);
    w.endArray().key("azimuth_sigma_deg").beginArray();
    for (const FrameResult& f : r.frames) w.value(f.azimuth_sigma_deg);
    w.endArray().endObject();
  }
  w.endArray().endObject();
  return w.str() + "\n";
}

std::string csvReport(const std::vector<SetResult>& results) {
  std::ostringstream csv;
  csv << "estimator,set,frames,valid_share,azimuth_median_deg,azimuth_p90_deg,azimuth_bias_deg,"
         "gross_share,gross_flagged_invalid_share,within_2sigma_share,zenith_median_deg,"
         "kept_share,cpu_ms_median,cpu_ms_p90,sky_informative_share,sky_median_deg,"
         "sky_gross_share,shadow_informative_share,shadow_median_deg,shadow_gross_share,camera\n";
  for (const SetResult& r : results) {
    const EstimatorSummary& s = r.summary;
    csv << r.estimator << ',' << r.set << ',' << s.frames;
    for (double v : {s.valid_share, s.azimuth_median_deg, s.azimuth_p90_deg, s.azimuth_bias_deg,
                     s.gross_share, s.gross_flagged, s.within_2sigma_share, s.zenith_median_deg,
                     s.kept_share, s.cpu_ms_median, s.cpu_ms_p90}) {
      csv << ',' << csvNumber(v);
    }
    for (const CueSummary* c :
         {r.cues ? &r.cues->sky : nullptr, r.cues ? &r.cues->shadow : nullptr}) {
      csv << ',' << (c ? csvNumber(c->informative_share) : "") << ','
          << (c ? csvNumber(c->median_deg) : "") << ',' << (c ? csvNumber(c->gross_share) : "");
    }
    csv << ',' << r.camera << '\n';
  }
  return csv.str();
}

}  // namespace sunvo::suneval
