#pragma once
// Writes the files of one route's report: <stem>_table1.md, <stem>_metrics.json and
// <stem>_topview.png (ground truth and every estimate of input.estimates, in that order in
// `series`). Returns the Table-1 markdown.

#include <string>
#include <vector>

#include "sunvo/report/report.hpp"
#include "sunvo/report/trajectory_plot.hpp"

namespace sunvo::report {

Expected<std::string> writeRouteReport(const std::string& stem, const ReportInput& input,
                                       const std::vector<Isometry3>& T_w_c_gt,
                                       const std::vector<PlotSeries>& series);

}  // namespace sunvo::report
