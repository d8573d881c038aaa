#include "sunvo/report/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "sunvo/report/json_writer.hpp"

namespace sunvo::report {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s == "-0.00" || s == "-0.0" || s == "-0") s.erase(0, 1);  // no negative zero in tables
  return s;
}

using Getter = std::function<double(const metrics::Evaluation&)>;

struct Row {
  std::string label;
  Getter get;
  int decimals = 2;
};

// One markdown table: a header of estimate names and one line per row. When bold_best is true
// the smallest printed value of each row is bold.
std::string markdownTable(const ReportInput& input, const std::string& corner,
                          const std::vector<Row>& rows, bool bold_best) {
  std::string out = "| " + corner + " |";
  for (const auto& e : input.estimates) out += " " + e.name + " |";
  out += "\n|---|";
  for (std::size_t i = 0; i < input.estimates.size(); ++i) out += "---:|";
  out += "\n";
  for (const Row& row : rows) {
    std::vector<std::string> cells;
    double best = INFINITY;
    for (const auto& e : input.estimates) {
      const double v = row.get(e.evaluation);
      cells.push_back(fixed(v, row.decimals));
      if (std::isfinite(v)) best = std::min(best, v);
    }
    // Rounding is monotonic, so the smallest value prints the smallest text; every cell that
    // prints the same text is tied for best as far as the reader can see.
    const std::string best_text = std::isfinite(best) ? fixed(best, row.decimals) : "";
    out += "| " + row.label + " |";
    for (const std::string& c : cells) {
      const bool bold = bold_best && !best_text.empty() && c == best_text;
      out += " " + (bold ? "**" + c + "**" : c) + " |";
    }
    out += "\n";
  }
  return out;
}

void writeStats(JsonWriter& w, const metrics::ErrorStats& s, double factor) {
  w.beginObject();
  w.key("rmse").value(s.rmse * factor);
  w.key("mean").value(s.mean * factor);
  w.key("median").value(s.median * factor);
  w.key("max").value(s.max * factor);
  w.key("count").value(static_cast<std::uint64_t>(s.count));
  w.endObject();
}

void writeApe(JsonWriter& w, const metrics::ApeMetrics& a) {
  w.beginObject();
  w.key("translation_m");
  writeStats(w, a.translation_m, 1.0);
  w.key("rotation_rad");
  writeStats(w, a.rotation_rad, 1.0);
  w.key("rotation_deg");
  writeStats(w, a.rotation_rad, kRadToDeg);
  w.endObject();
}

void writeRpe(JsonWriter& w, const metrics::RpeMetrics& r) {
  w.beginObject();
  w.key("delta").value(r.delta_m > 0.0 ? "distance" : "frame");
  if (r.delta_m > 0.0)
    w.key("delta_m").value(r.delta_m);
  else
    w.key("delta_frames").value(1);
  w.key("translation_m");
  writeStats(w, r.translation_m, 1.0);
  w.key("rotation_rad");
  writeStats(w, r.rotation_rad, 1.0);
  w.key("rotation_deg");
  writeStats(w, r.rotation_rad, kRadToDeg);
  w.endObject();
}

}  // namespace

std::string table1Markdown(const ReportInput& input) {
  const std::string plane = metrics::planeName(input.plane);
  const std::vector<Row> rows = {
      {"Trans. ARMSE [m]", [](const auto& e) { return e.table1.trans_armse_m; }},
      {"Trans. ARMSE (" + plane + ") [m]",
       [](const auto& e) { return e.table1.trans_armse_plane_m; }},
      {"Rot. ARMSE (×10⁻³) [axis-angle]",
       [](const auto& e) { return e.table1.rot_armse_rad * 1e3; }},
      {"Final trans. drift [m]", [](const auto& e) { return e.table1.final_drift_m; }},
      {"Final trans. drift [%]", [](const auto& e) { return e.table1.final_drift_pct; }},
      {"Final trans. drift (" + plane + ") [m]",
       [](const auto& e) { return e.table1.final_drift_plane_m; }},
      {"Final trans. drift (" + plane + ") [%]",
       [](const auto& e) { return e.table1.final_drift_plane_pct; }},
  };
  return markdownTable(input, "Metric", rows, true);
}

std::string extraMetricsMarkdown(const ReportInput& input) {
  double rpe_d = 100.0;
  if (!input.estimates.empty()) rpe_d = input.estimates.front().evaluation.rpe_distance.delta_m;
  const std::string d = fixed(rpe_d, 0);
  const std::vector<Row> rows = {
      {"KITTI t_err [%]", [](const auto& e) { return e.kitti.t_err_pct; }, 3},
      {"KITTI r_err [deg/m]", [](const auto& e) { return e.kitti.r_err_deg_per_m; }, 5},
      {"KITTI segments", [](const auto& e) { return static_cast<double>(e.kitti.num_segments); },
       0},
      {"APE trans. RMSE [m]", [](const auto& e) { return e.ape_raw.translation_m.rmse; }},
      {"APE trans. mean [m]", [](const auto& e) { return e.ape_raw.translation_m.mean; }},
      {"APE trans. median [m]", [](const auto& e) { return e.ape_raw.translation_m.median; }},
      {"APE trans. max [m]", [](const auto& e) { return e.ape_raw.translation_m.max; }},
      {"APE rot. RMSE [deg]", [](const auto& e) { return e.ape_raw.rotation_rad.rmse * kRadToDeg; },
       3},
      {"APE rot. max [deg]", [](const auto& e) { return e.ape_raw.rotation_rad.max * kRadToDeg; },
       3},
      {"APE SE(3)-aligned trans. RMSE [m]",
       [](const auto& e) { return e.ape_se3.translation_m.rmse; }},
      {"APE SE(3)-aligned trans. max [m]",
       [](const auto& e) { return e.ape_se3.translation_m.max; }},
      {"APE SE(3)-aligned rot. RMSE [deg]",
       [](const auto& e) { return e.ape_se3.rotation_rad.rmse * kRadToDeg; }, 3},
      {"RPE/frame trans. RMSE [m]", [](const auto& e) { return e.rpe_frame.translation_m.rmse; },
       4},
      {"RPE/frame rot. RMSE [deg]",
       [](const auto& e) { return e.rpe_frame.rotation_rad.rmse * kRadToDeg; }, 4},
      {"RPE/" + d + " m trans. RMSE [m]",
       [](const auto& e) { return e.rpe_distance.translation_m.rmse; }, 3},
      {"RPE/" + d + " m rot. RMSE [deg]",
       [](const auto& e) { return e.rpe_distance.rotation_rad.rmse * kRadToDeg; }, 3},
      {"RPE/" + d + " m (evo pairs) trans. RMSE [m]",
       [](const auto& e) { return e.rpe_evo.translation_m.rmse; }, 3},
      {"RPE/" + d + " m (evo pairs) rot. RMSE [deg]",
       [](const auto& e) { return e.rpe_evo.rotation_rad.rmse * kRadToDeg; }, 3},
  };
  return markdownTable(input, "Metric", rows, false);
}

std::string evaluationJson(const ReportInput& input) {
  JsonWriter w;
  w.beginObject();
  w.key("ground_truth").beginObject();
  w.key("path").value(input.gt_path);
  w.key("num_poses").value(static_cast<std::uint64_t>(input.num_poses));
  w.key("duration_s").value(input.gt_duration_s);
  w.key("times").value(input.gt_times_source);
  if (!input.estimates.empty()) {
    w.key("path_length_m").value(input.estimates.front().evaluation.table1.gt_path_length_m);
  }
  w.endObject();
  w.key("plane").value(metrics::planeKey(input.plane));
  w.key("plane_name").value(metrics::planeName(input.plane));
  w.key("estimates").beginArray();
  for (const auto& est : input.estimates) {
    const metrics::Evaluation& ev = est.evaluation;
    w.beginObject();
    w.key("name").value(est.name);
    w.key("path").value(est.path);

    const metrics::Table1Metrics& t = ev.table1;
    w.key("table1").beginObject();
    w.key("num_poses").value(static_cast<std::uint64_t>(t.num_poses));
    w.key("trans_armse_m").value(t.trans_armse_m);
    w.key("trans_armse_plane_m").value(t.trans_armse_plane_m);
    w.key("rot_armse_rad").value(t.rot_armse_rad);
    w.key("gt_path_length_m").value(t.gt_path_length_m);
    w.key("final_drift_m").value(t.final_drift_m);
    w.key("final_drift_pct").value(t.final_drift_pct);
    w.key("final_drift_plane_m").value(t.final_drift_plane_m);
    w.key("final_drift_plane_pct").value(t.final_drift_plane_pct);
    w.endObject();

    w.key("kitti_segments").beginObject();
    w.key("num_segments").value(static_cast<std::uint64_t>(ev.kitti.num_segments));
    w.key("t_err_pct").value(ev.kitti.t_err_pct);
    w.key("r_err_deg_per_m").value(ev.kitti.r_err_deg_per_m);
    w.key("per_length").beginArray();
    for (const auto& l : ev.kitti.per_length) {
      w.beginObject();
      w.key("length_m").value(l.length_m);
      w.key("num_segments").value(static_cast<std::uint64_t>(l.num_segments));
      w.key("t_err_pct").value(l.t_err_pct);
      w.key("r_err_deg_per_m").value(l.r_err_deg_per_m);
      w.endObject();
    }
    w.endArray();
    w.endObject();

    w.key("ape_raw");
    writeApe(w, ev.ape_raw);
    w.key("ape_se3");
    writeApe(w, ev.ape_se3);
    w.key("se3_alignment").beginObject();
    w.key("R").beginArray();
    for (int r = 0; r < 3; ++r) {
      w.beginArray();
      for (int c = 0; c < 3; ++c) w.value(ev.se3_alignment.R(r, c));
      w.endArray();
    }
    w.endArray();
    w.key("t_m").beginArray();
    for (int r = 0; r < 3; ++r) w.value(ev.se3_alignment.t(r));
    w.endArray();
    w.key("well_conditioned").value(ev.se3_alignment.well_conditioned);
    w.endObject();

    w.key("rpe_per_frame");
    writeRpe(w, ev.rpe_frame);
    w.key("rpe_per_distance");
    writeRpe(w, ev.rpe_distance);
    // evo_rpe --delta D --delta_unit m (consecutive pairs on the estimate's path).
    w.key("rpe_evo").beginObject();
    w.key("delta_m").value(ev.rpe_evo.delta_m);
    w.key("pairs").value("consecutive, path of the estimate (evo's default)");
    w.key("translation_m");
    writeStats(w, ev.rpe_evo.translation_m, 1.0);
    w.key("rotation_deg");
    writeStats(w, ev.rpe_evo.rotation_rad, kRadToDeg);
    w.endObject();
    w.endObject();
  }
  w.endArray();
  w.endObject();
  return w.str() + "\n";
}

}  // namespace sunvo::report
