#include "sunvo/report/report_files.hpp"

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::report {

Expected<std::string> writeRouteReport(const std::string& stem, const ReportInput& input,
                                       const std::vector<Isometry3>& T_w_c_gt,
                                       const std::vector<PlotSeries>& series) {
  const std::string table = table1Markdown(input);
  SUNVO_RETURN_IF_ERROR(files::writeWholeFile(stem + "_table1.md", table));
  SUNVO_RETURN_IF_ERROR(files::writeWholeFile(stem + "_metrics.json", evaluationJson(input)));
  auto plot = renderTopView(T_w_c_gt, series, input.plane);
  if (!plot) return plot.status();
  SUNVO_RETURN_IF_ERROR(writePng(stem + "_topview.png", *plot));
  return table;
}

}  // namespace sunvo::report
