// Runs the real sunvo_sun_eval on the 11 real KITTI 00 frames and checks what it writes.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {
namespace fs = std::filesystem;
const std::string kExe = SUNVO_SUN_EVAL_EXE;
const std::string kFrames = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_first_frames";
// One folder per process: ctest runs the tests of this file in parallel processes.
const std::string kOut =
    std::string(SUNVO_BINARY_DIR) + "/sun_eval_cli_test_out_" + std::to_string(::getpid());

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run(const std::string& args) {
  const std::string cmd = std::string(SUNVO_TOOL_EMULATOR) + kExe + " " + args + " > " + kOut +
                          "_stdout.txt 2> " + kOut + "_stderr.txt";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SunEvalCli, EvaluatesTheRealKittiFrames) {
  fs::remove_all(kOut);
  ASSERT_EQ(run("--images " + kFrames + " --out " + kOut + " --debug 1"), 0)
      << slurp(kOut + "_stderr.txt");
  const std::string md = slurp(kOut + "/sun_eval.md");
  EXPECT_NE(md.find("| lalonde | 00_first_frames | 11 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| lalonde_vo | 00_first_frames | 11 |"), std::string::npos) << md;
  const std::string json = slurp(kOut + "/sun_eval.json");
  EXPECT_NE(json.find("\"estimator\": \"lalonde_vo\""), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
  for (const char* f :
       {"hist/lalonde_00_first_frames_azimuth.png", "hist/lalonde_vo_00_first_frames_zenith.png",
        "debug/lalonde_00_first_frames_0.png", "frames/lalonde_00_first_frames.csv"}) {
    EXPECT_GT(fs::file_size(fs::path(kOut) / f), 100u) << f;
  }
  // One header line and one line per frame.
  const std::string csv = slurp(kOut + "/frames/lalonde_vo_00_first_frames.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 12);
  if (!::testing::Test::HasFailure()) fs::remove_all(kOut);  // kept for a look when it fails
}

// Every cell of the Markdown table row after `prefix` (estimator | set | frames |): a finite
// number ("–", undefined, only where allow_dash).
void expectFiniteRow(const std::string& md, const std::string& prefix, bool allow_dash) {
  const std::size_t at = md.find(prefix);
  ASSERT_NE(at, std::string::npos) << prefix << "\n" << md;
  const std::string row = md.substr(at + prefix.size(), md.find('\n', at) - at - prefix.size());
  std::stringstream cells(row);
  std::string cell;
  int n = 0;
  while (std::getline(cells, cell, '|')) {
    if (cell.find_first_not_of(' ') == std::string::npos) continue;
    ++n;
    if (cell.find("–") != std::string::npos) {
      EXPECT_TRUE(allow_dash) << prefix << ": " << row;
      continue;
    }
    const double v = std::strtod(cell.c_str() + cell.find_first_not_of(" +"), nullptr);
    EXPECT_TRUE(std::isfinite(v)) << prefix << ": " << cell;
    EXPECT_EQ(cell.find("nan"), std::string::npos) << prefix << ": " << row;
  }
  EXPECT_GE(n, 10) << row;  // the statistics columns after estimator | set | frames
}

// One command over several sets: the real frames by their own sun file and again as DIR:CSV,
// with the Sun-CNN on the gray frames (as three equal channels) and the JSON and CSV summaries.
TEST(SunEvalCli, OneCommandOverSeveralSetsWithSummaries) {
  fs::remove_all(kOut);
  const std::string sun_csv = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_sun_cam.csv";
  const std::string json_file = kOut + "_summary.json", csv_file = kOut + "_summary.csv";
  ASSERT_EQ(run("--images " + kFrames + " --images " + kFrames + ":" + sun_csv + " --out " + kOut +
                " --debug 0 --estimators lalonde,lalonde_vo,sun_cnn --json " + json_file +
                " --csv " + csv_file),
            0)
      << slurp(kOut + "_stderr.txt");
  const std::string md = slurp(kOut + "_stdout.txt");
  for (const std::string set : {"00_first_frames", "00_first_frames_2"}) {
    for (const std::string est : {"lalonde", "lalonde_vo"}) {
      // Lalonde is valid on 8 of these frames and gross on some, so every column has a value.
      // Lalonde-VO has no gross error on them (measured: 0 of 8), so its "gross flagged" share
      // is undefined ("–").
      expectFiniteRow(md, "| " + est + " | " + set + " | 11 |", est == "lalonde_vo");
      EXPECT_NE(md.find("| " + est + " | " + set + " | sky |"), std::string::npos) << md;
      EXPECT_NE(md.find("| " + est + " | " + set + " | shadow |"), std::string::npos) << md;
    }
    // The Sun-CNN (a colour model) may call every gray frame invalid: its error columns may be
    // "–", but the row is there, with the valid share and the time per call.
    expectFiniteRow(md, "| sun_cnn | " + set + " | 11 |", true);
  }
  // --json writes what <out>/sun_eval.json holds.
  const std::string json = slurp(json_file);
  EXPECT_EQ(json, slurp(kOut + "/sun_eval.json"));
  EXPECT_EQ(json.find("nan"), std::string::npos);
  EXPECT_NE(json.find("\"azimuth_signed_error_deg_median\""), std::string::npos);
  EXPECT_NE(json.find("\"gross_flagged_invalid_share\""), std::string::npos);
  EXPECT_NE(json.find("\"within_2sigma_share\""), std::string::npos);
  const std::string csv = slurp(csv_file);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);  // header + 2 sets x 3 estimators
  EXPECT_NE(csv.find("\nsun_cnn,00_first_frames_2,11,"), std::string::npos) << csv;
  // The per-frame CSV carries the CPU time of each call.
  const std::string frames = slurp(kOut + "/frames/sun_cnn_00_first_frames.csv");
  EXPECT_NE(frames.find(",cpu_ms\n"), std::string::npos);
  EXPECT_EQ(std::count(frames.begin(), frames.end(), '\n'), 12);
  if (!::testing::Test::HasFailure()) {
    fs::remove_all(kOut);
    fs::remove(json_file);
    fs::remove(csv_file);
  }
}

TEST(SunEvalCli, RejectsBadArgumentsAndInputs) {
  // Usage errors exit 2, a bad input exits 1; --help and --version exit 0.
  EXPECT_EQ(run("--out " + kOut), 2);
  EXPECT_EQ(run("--images /nonexistent --out " + kOut), 2);
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --estimators nope"), 2);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("nope"), std::string::npos);
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --frames x"), 2);
  // --camera color on gray-only frames: a runtime failure naming the set; a bad camera name: usage.
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --camera color"), 1);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("no colour camera"), std::string::npos);
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --camera infrared"), 2);
  // DIR:CSV with a CSV that is not there: a usage error naming it.
  EXPECT_EQ(run("--images " + kFrames + ":/nonexistent/sun.csv --out " + kOut), 2);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("/nonexistent/sun.csv"), std::string::npos);
  // A folder that is no dataset: a runtime failure naming it.
  EXPECT_EQ(run("--images " + std::string(SUNVO_DATA_DIR) + " --out " + kOut), 1);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("not a dataset"), std::string::npos);
  EXPECT_EQ(run("--help"), 0);
  EXPECT_NE(slurp(kOut + "_stdout.txt").find("--images"), std::string::npos);
  EXPECT_EQ(run("--version"), 0);
  EXPECT_NE(slurp(kOut + "_stdout.txt").find("sunvo_sun_eval"), std::string::npos);
}

}  // namespace
