// Runs the sunvo_eval executable as a user would and checks its exit codes and outputs.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo {
namespace {

const std::string kExe = SUNVO_EVAL_EXE;
const std::string kGt = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_gt_poses.txt";
const std::string kTimes = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_times.txt";
// One prefix per process: ctest runs each test of this file as its own process, in parallel, and
// they must not share the captured stdout/stderr or the scaled copy.
const std::string kTmp =
    std::string(SUNVO_BINARY_DIR) + "/eval_cli_test_" + std::to_string(::getpid()) + "_";

// Removes this process's files when the tests end.
class TmpCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    const std::filesystem::path prefix(kTmp);
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(prefix.parent_path(), ec)) {
      if (e.path().filename().string().rfind(prefix.filename().string(), 0) == 0) {
        std::filesystem::remove(e.path(), ec);
      }
    }
  }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new TmpCleanup);

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
  const std::string cmd = SUNVO_TOOL_EMULATOR + kExe + " " + args + " > " + kTmp +
                          "stdout.txt 2> " + kTmp + "stderr.txt";
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
  EXPECT_NE(j.find("\"duration_s\": 470.58"), std::string::npos) << j.substr(0, 400);  // times.txt
  std::ifstream png_in(png, std::ios::binary);
  char magic[4] = {};
  png_in.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

// The command-line convention (firmware_app/cli): a bad command line exits 2, a file that cannot
// be read, parsed or written exits 1; both say why on stderr.
TEST(EvalCli, BadArgumentsExit2AndBadFilesExit1) {
  const std::string gt = "--gt " + kGt;
  const std::string est = "--est a=" + kGt;
  EXPECT_EQ(runEval("--help").code, 0);
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const std::string malformed = kTmp + "malformed.txt";
  ASSERT_TRUE(files::writeWholeFile(malformed, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 y 0 0 1 0\n")
                  .isOk());
  const std::string short_est = kTmp + "short.txt";
  ASSERT_TRUE(files::writeWholeFile(short_est, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n")
                  .isOk());
  const Case cases[] = {
      {"", 2, "--gt is required"},
      {gt, 2, "--est is required"},
      {gt + " " + est + " --frobnicate 1", 2, "--frobnicate"},
      {gt + " --est nofile", 2, "--est: expects NAME=FILE, got 'nofile'"},
      {gt + " " + est + " --est a=" + kGt, 2, "--est name 'a' given twice"},
      {gt + " " + gt + " " + est, 2, "--gt"},
      {gt + " " + est + " --plane up", 2, "--plane: up not in {xz,en}"},
      {gt + " " + est + " --json", 2, "--json"},
      {"--gt " + kTmp + "missing.txt " + est, 1, "missing.txt: file not found"},
      {gt + " --est m=" + malformed, 1, malformed + ":2: field 'ty': not a number: 'y'"},
      {gt + " --est s=" + short_est, 1, "has 2 poses, the ground truth"},
      {gt + " " + est + " --json /nonexistent_dir/x.json", 1, "/nonexistent_dir/x.json"},
  };
  for (const Case& c : cases) {
    const CliResult r = runEval(c.args);
    EXPECT_EQ(r.code, c.code) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
}

// The number after the first "key": that follows `anchor` in a JSON text (NaN when absent).
double numberAfter(const std::string& json, const std::string& anchor, const std::string& key) {
  const std::size_t from = json.find(anchor);
  if (from == std::string::npos) return std::nan("");
  const std::string pattern = "\"" + key + "\": ";
  const std::size_t at = json.find(pattern, from);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + pattern.size(), nullptr);
}

// sunvo_eval against scripts/reference_metrics.py (Python standard library, quaternions, no
// shared code) on the real 00 ground truth and a copy that drifts like VO: every frame-to-frame
// motion perturbed by a random rotation (σ = 2e-4 rad per axis) and translation (σ = 5 mm).
TEST(EvalCli, AgreesWithIndependentPythonReference) {
  if (std::system("python3 -c pass > /dev/null 2>&1") != 0) GTEST_SKIP() << "no python3";
  auto gt = files::readKittiPoses(kGt);
  ASSERT_TRUE(gt);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  files::Trajectory est;
  est.T_w_c.push_back(gt->T_w_c.front());
  for (std::size_t k = 1; k < gt->size(); ++k) {
    Isometry3 noise = Isometry3::Identity();
    noise.linear() = expSO3(2e-4 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
    noise.translation() = 5e-3 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    est.T_w_c.push_back(est.T_w_c.back() * gt->T_w_c[k - 1].inverse(Eigen::Isometry) *
                        gt->T_w_c[k] * noise);
  }
  const std::string est_path = kTmp + "00_drift.txt";
  ASSERT_TRUE(files::writeKittiPoses(est_path, est).isOk());
  for (const std::string plane : {"xz", "en"}) {
    const std::string json_path = kTmp + "drift_" + plane + ".json";
    const CliResult r = runEval("--gt " + kGt + " --est drift=" + est_path + " --plane " + plane +
                                " --json " + json_path);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string ref_path = kTmp + "drift_ref_" + plane + ".json";
    const std::string cmd = "python3 " + std::string(SUNVO_SOURCE_DIR) +
                            "/scripts/reference_metrics.py " + kGt + " " + est_path + " " + plane +
                            " > " + ref_path;
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const std::string ours = slurp(json_path);
    const std::string ref = slurp(ref_path);
    for (const char* key :
         {"trans_armse_m", "trans_armse_plane_m", "rot_armse_rad", "gt_path_length_m",
          "final_drift_m", "final_drift_pct", "final_drift_plane_m", "final_drift_plane_pct"}) {
      const double a = numberAfter(ours, "\"table1\"", key);
      const double b = numberAfter(ref, "\"table1\"", key);
      ASSERT_TRUE(std::isfinite(a) && std::isfinite(b) && b > 0.0) << key;
      EXPECT_NEAR(a, b, 1e-9 * b) << plane << " " << key;  // measured: ~4e-14
    }
    for (const char* key : {"num_segments", "t_err_pct", "r_err_deg_per_m"}) {
      const double a = numberAfter(ours, "\"kitti_segments\"", key);
      const double b = numberAfter(ref, "\"kitti_segments\"", key);
      ASSERT_TRUE(std::isfinite(a) && std::isfinite(b) && b > 0.0) << key;
      EXPECT_NEAR(a, b, 1e-9 * b) << plane << " " << key;  // measured: ~4e-14
    }
  }
}

}  // namespace
}  // namespace sunvo
