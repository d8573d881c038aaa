#include "sunvo/report/report.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/report/json_writer.hpp"
#include "sunvo/report/trajectory_plot.hpp"

namespace sunvo::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(JsonWriter, WritesNestedDocument) {
  JsonWriter w;
  w.beginObject();
  w.key("a").value(1.5);
  w.key("b").beginArray().value(1).value("x").null().endArray();
  w.key("c").beginObject().endObject();
  w.key("d").value(kNaN);
  w.key("e").value(true);
  w.key("f").value(0.1);
  w.endObject();
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(w.str(),
            "{\n  \"a\": 1.5,\n  \"b\": [\n    1,\n    \"x\",\n    null\n  ],\n  \"c\": {},\n"
            "  \"d\": null,\n  \"e\": true,\n  \"f\": 0.1\n}");
}

TEST(JsonWriter, EscapesAndDetectsMisuse) {
  EXPECT_EQ(jsonQuote("a\"b\\c\n\x01"), "\"a\\\"b\\\\c\\n\\u0001\"");
  JsonWriter no_key;
  no_key.beginObject().value(1.0).endObject();
  EXPECT_FALSE(no_key.ok());
  JsonWriter unbalanced;
  unbalanced.beginArray();
  EXPECT_FALSE(unbalanced.ok());
  JsonWriter wrong_end;
  wrong_end.beginArray().endObject();
  EXPECT_FALSE(wrong_end.ok());
}

metrics::Evaluation withTable1(double trans, double plane, double rot_rad, double drift,
                               double drift_pct, double drift_plane, double drift_plane_pct) {
  metrics::Evaluation e;
  e.table1.trans_armse_m = trans;
  e.table1.trans_armse_plane_m = plane;
  e.table1.rot_armse_rad = rot_rad;
  e.table1.final_drift_m = drift;
  e.table1.final_drift_pct = drift_pct;
  e.table1.final_drift_plane_m = drift_plane;
  e.table1.final_drift_plane_pct = drift_plane_pct;
  return e;
}

TEST(Table1Markdown, PaperRowsWithBestInBold) {
  ReportInput in;
  in.plane = metrics::HorizontalPlane::kEastNorth;
  in.estimates.push_back({"Pure VO", "", withTable1(1.234, 0.5, 0.0015, 3.0, 0.3, 2.0, 0.2)});
  in.estimates.push_back(
      {"VO+Sun (file)", "", withTable1(2.0, 0.504, 0.001, kNaN, 0.31, 1.0, 0.1)});
  const std::string md = table1Markdown(in);
  EXPECT_EQ(md,
            "| Metric | Pure VO | VO+Sun (file) |\n"
            "|---|---:|---:|\n"
            "| Trans. ARMSE [m] | **1.23** | 2.00 |\n"
            "| Trans. ARMSE (EN-plane) [m] | **0.50** | **0.50** |\n"
            "| Rot. ARMSE (×10⁻³) [axis-angle] | 1.50 | **1.00** |\n"
            "| Final trans. drift [m] | **3.00** | n/a |\n"
            "| Final trans. drift [%] | **0.30** | 0.31 |\n"
            "| Final trans. drift (EN-plane) [m] | 2.00 | **1.00** |\n"
            "| Final trans. drift (EN-plane) [%] | 0.20 | **0.10** |\n");
  in.plane = metrics::HorizontalPlane::kCameraXZ;
  EXPECT_NE(table1Markdown(in).find("| Trans. ARMSE (x-z plane) [m] |"), std::string::npos);
}

std::vector<Isometry3> line(int n, double scale) {
  std::vector<Isometry3> out;
  for (int k = 0; k < n; ++k) {
    Isometry3 T = Isometry3::Identity();
    T.translation() = Eigen::Vector3d(0, 0, scale * k);
    out.push_back(T);
  }
  return out;
}

// The number after the first "key": in a JSON text (NaN when absent).
double firstNumber(const std::string& json, const std::string& key) {
  const std::string pattern = "\"" + key + "\": ";
  const std::size_t at = json.find(pattern);
  if (at == std::string::npos) return kNaN;
  return std::strtod(json.c_str() + at + pattern.size(), nullptr);
}

TEST(EvaluationJson, HoldsEveryMetric) {
  // Straight line, 2 % scale error over 10 m: final drift 0.2 m = 2 % (see metrics_test).
  auto ev = metrics::evaluate(line(11, 1.0), line(11, 1.02));
  ASSERT_TRUE(ev);
  ReportInput in;
  in.gt_path = "gt \"quoted\".txt";
  in.num_poses = 11;
  in.estimates.push_back({"scaled", "est.txt", *ev});
  const std::string json = evaluationJson(in);
  for (const char* key : {"\"plane\": \"xz\"",
                          "\"name\": \"scaled\"",
                          "\"path\": \"gt \\\"quoted\\\".txt\"",
                          "\"trans_armse_m\": ",
                          "\"trans_armse_plane_m\": ",
                          "\"rot_armse_rad\": 0,",
                          "\"final_drift_m\": ",
                          "\"final_drift_pct\": ",
                          "\"final_drift_plane_m\": ",
                          "\"final_drift_plane_pct\": ",
                          "\"kitti_segments\": {",
                          "\"num_segments\": 0",
                          "\"t_err_pct\": null",
                          "\"ape_raw\": {",
                          "\"ape_se3\": {",
                          "\"se3_alignment\": {",
                          "\"rpe_per_frame\": {",
                          "\"rpe_per_distance\": {",
                          "\"rotation_deg\": {",
                          "\"well_conditioned\": false",
                          "\"length_m\": 800"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  }
  EXPECT_NEAR(firstNumber(json, "final_drift_m"), 0.2, 1e-12);
  EXPECT_NEAR(firstNumber(json, "final_drift_pct"), 2.0, 1e-12);
  EXPECT_NEAR(firstNumber(json, "trans_armse_m"), 0.1 / std::sqrt(3.0), 1e-12);
}

// An independent syntax check of the JSON with Python's json module, when Python is present.
TEST(EvaluationJson, ParsesWithPython) {
  if (std::system("python3 -c pass > /dev/null 2>&1") != 0) GTEST_SKIP() << "no python3";
  auto ev = metrics::evaluate(line(30, 1.0), line(30, 1.01));
  ASSERT_TRUE(ev);
  ReportInput in;
  in.estimates.push_back({"a", "a.txt", *ev});
  in.estimates.push_back({"b\tc", "b.txt", *ev});
  const std::string path = std::string(SUNVO_BINARY_DIR) + "/report_test.json";
  ASSERT_TRUE(files::writeWholeFile(path, evaluationJson(in)).isOk());
  const std::string cmd =
      "python3 -c \"import json,sys; d=json.load(open(sys.argv[1])); "
      "assert len(d['estimates'])==2; "
      "assert abs(d['estimates'][0]['table1']['final_drift_pct']-1.0)<1e-9\" " +
      path;
  EXPECT_EQ(std::system(cmd.c_str()), 0);
}

TEST(ExtraMetricsMarkdown, HasKittiApeRpeRows) {
  auto ev = metrics::evaluate(line(11, 1.0), line(11, 1.02));
  ASSERT_TRUE(ev);
  ReportInput in;
  in.estimates.push_back({"x", "", *ev});
  const std::string md = extraMetricsMarkdown(in);
  EXPECT_NE(md.find("| KITTI t_err [%] | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| APE trans. max [m] | 0.20 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| RPE/frame trans. RMSE [m] | 0.0200 |"), std::string::npos) << md;
}

// A 100 m square loop in the x-z plane, and an estimate 1.1x larger.
std::vector<Isometry3> square(double side, double scale) {
  std::vector<Isometry3> out;
  const Eigen::Vector3d corners[] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}};
  for (int c = 0; c < 4; ++c) {
    for (int i = 0; i < 20; ++i) {
      Isometry3 T = Isometry3::Identity();
      T.translation() = scale * side * (corners[c] + (corners[c + 1] - corners[c]) * i / 20.0);
      out.push_back(T);
    }
  }
  return out;
}

bool near(const cv::Vec3b& px, const cv::Scalar& c, int tol) {
  return std::abs(px[0] - c[0]) <= tol && std::abs(px[1] - c[1]) <= tol &&
         std::abs(px[2] - c[2]) <= tol;
}

TEST(TopViewPlot, DrawsTrajectoriesToScaleAndWritesPng) {
  const auto gt = square(100.0, 1.0);
  const std::vector<PlotSeries> est = {{"scaled", square(100.0, 1.1)}};
  PlotOptions opt;
  auto img = renderTopView(gt, est, metrics::HorizontalPlane::kCameraXZ, opt);
  ASSERT_TRUE(img) << img.status().toString();
  EXPECT_EQ(img->rows, 2 * opt.margin_px + opt.plot_size_px);
  EXPECT_EQ(img->cols, 2 * opt.margin_px + opt.plot_size_px + opt.legend_width_px);

  // Extent 110 m × 1.05 over 900 px; the right (a = x) and up (b = z) directions are kept.
  const TopViewLayout L = computeTopViewLayout(gt, est, metrics::HorizontalPlane::kCameraXZ, opt);
  EXPECT_NEAR(L.px_per_m, 900.0 / (110.0 * 1.05), 1e-9);
  EXPECT_EQ(L.grid_step_m, 20.0);  // 115.5 m / 8 = 14.4 m -> 20 m
  const cv::Point origin = L.toPixel(0, 0);
  const cv::Point right = L.toPixel(50, 0);
  const cv::Point up = L.toPixel(0, 50);
  EXPECT_GT(right.x, origin.x);
  EXPECT_LT(up.y, origin.y);
  // Equal scale: 50 m is the same number of pixels on both axes.
  EXPECT_EQ(right.x - origin.x, origin.y - up.y);

  // The ground truth (black) passes through (50, 100); the estimate (first palette colour)
  // through (55, 110).
  const cv::Point g = L.toPixel(50, 100);
  EXPECT_TRUE(near(img->at<cv::Vec3b>(g), groundTruthColor(), 60)) << img->at<cv::Vec3b>(g);
  const cv::Point e = L.toPixel(55, 110);
  EXPECT_TRUE(near(img->at<cv::Vec3b>(e), estimateColor(0), 60)) << img->at<cv::Vec3b>(e);
  // Background away from everything stays white.
  EXPECT_TRUE(near(img->at<cv::Vec3b>(L.toPixel(31, 71)), cv::Scalar(255, 255, 255), 0));

  const std::string path = std::string(SUNVO_BINARY_DIR) + "/report_test_plot.png";
  ASSERT_TRUE(writePng(path, *img).isOk());
  const cv::Mat back = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, *img, cv::NORM_INF), 0.0);  // PNG is lossless
  EXPECT_EQ(writePng("/nonexistent_dir/p.png", *img).code(), StatusCode::kIoError);
}

TEST(TopViewPlot, RejectsBadOptionsAndInputs) {
  PlotOptions opt;
  opt.plot_size_px = 10;
  const auto s = renderTopView(square(10, 1), {}, metrics::HorizontalPlane::kEastNorth, opt);
  EXPECT_NE(s.status().message().find("plot.plot_size_px"), std::string::npos);
  EXPECT_FALSE(renderTopView({}, {}, metrics::HorizontalPlane::kEastNorth));
  EXPECT_FALSE(renderTopView(square(10, 1), {{"empty", {}}}, metrics::HorizontalPlane::kEastNorth));
  // A trajectory that never moves still gives an image (1 m minimum extent).
  EXPECT_TRUE(renderTopView(std::vector<Isometry3>(3, Isometry3::Identity()), {},
                            metrics::HorizontalPlane::kEastNorth));
}

}  // namespace
}  // namespace sunvo::report
