// Runs the real sunvo_sun_eval on the 11 real KITTI 00 frames and checks what it writes.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

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

TEST(SunEvalCli, RejectsBadArgumentsAndInputs) {
  // Usage errors exit 2, a bad input exits 1; --help and --version exit 0.
  EXPECT_EQ(run("--out " + kOut), 2);
  EXPECT_EQ(run("--images /nonexistent --out " + kOut), 2);
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --estimators nope"), 2);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("nope"), std::string::npos);
  EXPECT_EQ(run("--images " + kFrames + " --out " + kOut + " --frames x"), 2);
  // A folder that is no dataset: a runtime failure naming it.
  EXPECT_EQ(run("--images " + std::string(SUNVO_DATA_DIR) + " --out " + kOut), 1);
  EXPECT_NE(slurp(kOut + "_stderr.txt").find("not a dataset"), std::string::npos);
  EXPECT_EQ(run("--help"), 0);
  EXPECT_NE(slurp(kOut + "_stdout.txt").find("--images"), std::string::npos);
  EXPECT_EQ(run("--version"), 0);
  EXPECT_NE(slurp(kOut + "_stdout.txt").find("sunvo_sun_eval"), std::string::npos);
}

}  // namespace
