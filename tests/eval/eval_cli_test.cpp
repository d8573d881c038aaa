// Runs the sunvo_eval executable as a user would and checks its exit codes and outputs.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo {
namespace {

const std::string kExe = SUNVO_EVAL_EXE;
const std::string kGt = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_gt_poses.txt";
const std::string kTimes = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_times.txt";
const std::string kTmp = std::string(SUNVO_BINARY_DIR) + "/eval_cli_test_";

struct CliResult {
  int code = -1;
  std::string out;
  std::string err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CliResult runEval(const std::string& args) {
  const std::string cmd = kExe + " " + args + " > " + kTmp + "stdout.txt 2> " + kTmp + "stderr.txt";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(kTmp + "stdout.txt");
  r.err = slurp(kTmp + "stderr.txt");
  return r;
}

// The real 00 ground truth with every translation × 1.01, written once per test.
std::string scaledCopy() {
  const std::string path = kTmp + "00_scaled.txt";
  auto gt = files::readKittiPoses(kGt);
  if (!gt) return "";
  for (auto& T : gt->T_w_c) T.translation() *= 1.01;
  if (!files::writeKittiPoses(path, *gt).isOk()) return "";
  return path;
}

TEST(EvalCli, EvaluatesRealKitti00AgainstScaledCopy) {
  const std::string est = scaledCopy();
  ASSERT_FALSE(est.empty());
  const std::string json = kTmp + "out.json";
  const std::string md = kTmp + "out.md";
  const std::string png = kTmp + "out.png";
  std::remove(json.c_str());
  std::remove(md.c_str());
  std::remove(png.c_str());
  const CliResult r = runEval("--gt " + kGt + " --gt-times " + kTimes + " --est 'VO 1%=" + est +
                              "' --est Truth=" + kGt + " --plane xz --json " + json + " --md " +
                              md + " --plot " + png);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| Metric | VO 1% | Truth |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| Rot. ARMSE (×10⁻³) [axis-angle] | **0.00** | **0.00** |"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("4541 poses"), std::string::npos);
  EXPECT_NE(slurp(md).find("| Final trans. drift (x-z plane) [%] |"), std::string::npos);
  const std::string j = slurp(json);
  EXPECT_NE(j.find("\"name\": \"VO 1%\""), std::string::npos);
  EXPECT_NE(j.find("\"rot_armse_rad\": 0,"), std::string::npos);
  std::ifstream png_in(png, std::ios::binary);
  char magic[4] = {};
  png_in.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

TEST(EvalCli, BadArgumentsAndFilesExitWithCode2) {
  const std::string gt = "--gt " + kGt;
  const std::string est = "--est a=" + kGt;
  EXPECT_EQ(runEval("--help").code, 0);
  struct Case {
    std::string args;
    std::string message;
  };
  const std::string malformed = kTmp + "malformed.txt";
  ASSERT_TRUE(files::writeWholeFile(malformed, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 y 0 0 1 0\n")
                  .isOk());
  const std::string short_est = kTmp + "short.txt";
  ASSERT_TRUE(files::writeWholeFile(short_est, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n")
                  .isOk());
  const Case cases[] = {
      {"", "--gt is required"},
      {gt, "at least one --est is required"},
      {gt + " " + est + " --frobnicate 1", "unknown argument '--frobnicate'"},
      {gt + " --est nofile", "--est expects NAME=FILE, got 'nofile'"},
      {gt + " " + est + " --est a=" + kGt, "--est name 'a' given twice"},
      {gt + " " + est + " --plane up", "--plane must be 'xz' or 'en', got 'up'"},
      {gt + " " + est + " --json", "--json needs a value"},
      {"--gt " + kTmp + "missing.txt " + est, "missing.txt: file not found"},
      {gt + " --est m=" + malformed, malformed + ":2: field 'ty': not a number: 'y'"},
      {gt + " --est s=" + short_est, "has 2 poses, the ground truth"},
      {gt + " " + est + " --json /nonexistent_dir/x.json", "/nonexistent_dir/x.json"},
  };
  for (const Case& c : cases) {
    const CliResult r = runEval(c.args);
    EXPECT_EQ(r.code, 2) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
}

}  // namespace
}  // namespace sunvo
