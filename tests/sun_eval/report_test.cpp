// sunvo_sun_eval's reports (hil/tools/sun_eval/src/report.hpp): the rows they hold and how they
// write undefined values.

#include "report.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace {
using namespace sunvo::suneval;

std::vector<SetResult> twoResults() {
  SetResult a;
  a.estimator = "lalonde";
  a.set = "setA";
  a.camera = "color";
  FrameResult f;
  f.valid = true;
  f.azimuth_error_deg = -12.5;
  f.azimuth_sigma_deg = 10.0;
  f.cpu_ms = 4.0;
  a.frames = {f};
  a.summary = summarize(a.frames);
  a.cues = CueResults{summarizeCue({20.0}), summarizeCue({kNaN})};
  SetResult b;
  b.estimator = "sun_cnn";
  b.set = "setB";
  b.camera = "gray";
  FrameResult g;  // invalid, no direction
  b.frames = {g, g};
  b.summary = summarize(b.frames);
  return {a, b};
}

TEST(SunEvalReport, MarkdownHasOneRowPerSetAndEstimatorAndOnePerCue) {
  const std::string md = markdownReport(twoResults(), ReportMeta{5.0, 1, 1});
  EXPECT_NE(md.find("| lalonde | setA | 1 | 100 % | 12.5° | 12.5° | -12.5° | 0 % |"),
            std::string::npos)
      << md;
  // No valid frame: the error columns read "–".
  EXPECT_NE(md.find("| sun_cnn | setB | 2 | 0 % | – | – | – | – |"), std::string::npos) << md;
  EXPECT_NE(md.find("| lalonde | setA | sky | 100 % (1/1) | 20.0° |"), std::string::npos) << md;
  EXPECT_NE(md.find("| lalonde | setA | shadow | 0 % (0/1) | – |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| sun_cnn | setB | sky"), std::string::npos);
  EXPECT_NE(md.find("Cameras: setA colour (camera 2), setB gray (camera 0)."), std::string::npos)
      << md;
}

TEST(SunEvalReport, CsvLeavesUndefinedFieldsEmpty) {
  const std::string csv = csvReport(twoResults());
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);  // header + 2 rows
  const std::size_t header_end = csv.find('\n');
  const std::string header = csv.substr(0, header_end);
  const auto fields = std::count(header.begin(), header.end(), ',');
  for (std::size_t p = header_end + 1; p < csv.size();) {
    const std::size_t e = csv.find('\n', p);
    const std::string row = csv.substr(p, e - p);
    EXPECT_EQ(std::count(row.begin(), row.end(), ','), fields) << row;
    p = e + 1;
  }
  EXPECT_NE(csv.find("lalonde,setA,1,1,12.5,12.5,-12.5,0,,1,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("sun_cnn,setB,2,0,,,,,,,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",,,,,,,gray\n"), std::string::npos) << csv;  // no cues; the camera last
  EXPECT_EQ(csv.find("nan"), std::string::npos);
}

TEST(SunEvalReport, JsonWritesUndefinedValuesAsNull) {
  const std::string json = jsonReport(twoResults(), ReportMeta{5.0, 1, 1});
  EXPECT_NE(json.find("\"azimuth_signed_error_deg_median\": -12.5"), std::string::npos) << json;
  EXPECT_NE(json.find("\"azimuth_abs_error_deg_median\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"cues\""), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
}

}  // namespace
