#pragma once
// What sunvo_sun_eval writes from its statistics: the Markdown tables it prints (one row per set
// and estimator; one row per set, Lalonde estimator and cue), the JSON summary (with every error,
// for plots) and a CSV of the summary rows.

#include <optional>
#include <string>
#include <vector>

#include "metrics.hpp"

namespace sunvo::suneval {

struct CueResults {
  CueSummary sky, shadow;
};

// One estimator on one set.
struct SetResult {
  std::string estimator, set;
  std::string camera;  // "color" (camera 2) or "gray" (camera 0)
  std::vector<FrameResult> frames;
  EstimatorSummary summary;
  std::optional<CueResults> cues;  // Lalonde estimators only
};

// What the run was: written into every report.
struct ReportMeta {
  double prior_error_deg = 0.0;  // per-axis 1-sigma VO prior attitude error, deg
  unsigned long long seed = 0;
  int threads = 1;  // OpenCV threads
};

std::string markdownReport(const std::vector<SetResult>& results, const ReportMeta& meta);
std::string jsonReport(const std::vector<SetResult>& results, const ReportMeta& meta);
// Header and one line per result; empty fields for undefined values (no valid frame, ...).
std::string csvReport(const std::vector<SetResult>& results);

// v with `digits` decimals; "–" when not finite.
std::string formatNumber(double v, int digits = 1);

}  // namespace sunvo::suneval
