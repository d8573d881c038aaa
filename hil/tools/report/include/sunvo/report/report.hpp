#pragma once
// Evaluation reports: the paper's Table 1 as markdown, the remaining metrics as a markdown
// summary, and every metric of every estimate as JSON. Text only; writing files is the caller's
// job (files::writeWholeFile).

#include <limits>
#include <string>
#include <vector>

#include "sunvo/metrics/metrics.hpp"

namespace sunvo::report {

// One estimated trajectory and its metrics against the ground truth.
struct EstimateReport {
  std::string name;  // column header, e.g. "VO+Sun (file)"
  std::string path;  // where the estimate came from (for the JSON; may be empty)
  metrics::Evaluation evaluation;
};

struct ReportInput {
  std::string gt_path;  // where the ground truth came from (may be empty)
  std::size_t num_poses = 0;
  // Last minus first ground-truth time [s]; NaN when unknown (written as null).
  double gt_duration_s = std::numeric_limits<double>::quiet_NaN();
  std::string gt_times_source;  // where the times came from, e.g. "times file", "nominal 10 Hz"
  metrics::HorizontalPlane plane = metrics::HorizontalPlane::kCameraXZ;
  std::vector<EstimateReport> estimates;
};

// Paper Table 1 as a markdown table, one column per estimate, rows in the paper's order:
//   Trans. ARMSE [m] | Trans. ARMSE (<plane>) [m] | Rot. ARMSE (×10⁻³) [axis-angle] |
//   Final trans. drift [m] | Final trans. drift [%] | Final trans. drift (<plane>) [m] |
//   Final trans. drift (<plane>) [%]
// with <plane> = "EN-plane" or "x-z plane". Values have 2 decimals (as in the paper); the
// rotational row is rot_armse_rad × 10³. In each row the smallest printed value is bold (every
// column that prints it, when several tie); an undefined value prints "n/a".
std::string table1Markdown(const ReportInput& input);

// The other metrics as a markdown table, one column per estimate: KITTI segment errors
// (t_err %, r_err deg/m, segment count), APE (raw and SE(3)-aligned; translation RMSE/mean/
// median/max in m, rotation RMSE/max in deg) and RPE (per frame, per rpe distance).
std::string extraMetricsMarkdown(const ReportInput& input);

// Every metric of every estimate as one JSON document; units are part of the key names
// (_m, _pct, _rad, _deg_per_m). Undefined values are null.
std::string evaluationJson(const ReportInput& input);

}  // namespace sunvo::report
