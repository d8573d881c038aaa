// TumPoseLog (telemetry.pose_log): what it writes reads back through the project's TUM reader
// with the exact frame times and the poses to the printed precision; each start appends a
// comment line; a failed write is an error naming the file; appending allocates nothing.

#include "sunvo/rover/pose_log.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/files/trajectory_io.hpp"
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::rover {
namespace {

namespace fs = std::filesystem;

fs::path testFile(const std::string& name) {
  const fs::path dir = fs::path(SUNVO_BINARY_DIR) / "test_out" / "pose_log";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  fs::remove(p);
  return p;
}

// Pose k of a drive: times 0.1 s apart from a UTC time with odd nanoseconds, a position on a
// curve with negative coordinates, C_w_c a rotation about a tilted axis (unit quaternion x y z w).
PoseRecord poseAt(int k) {
  PoseRecord p;
  p.sequence = static_cast<std::uint64_t>(k);
  p.utc_ns = 1'782'043'200'123'456'789 + static_cast<TimeNs>(k) * 100'000'007;
  p.p_w[0] = -12.5 + 0.731 * k;
  p.p_w[1] = 3.25 * std::sin(0.1 * k);
  p.p_w[2] = -0.0125 * k;
  const double angle = 0.05 * k;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 0.93).normalized();
  const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
  p.q_w_c[0] = q.x();
  p.q_w_c[1] = q.y();
  p.q_w_c[2] = q.z();
  p.q_w_c[3] = q.w();
  return p;
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void expectPose(const files::Trajectory& t, std::size_t i, const PoseRecord& p) {
  EXPECT_EQ(t.t_ns[i], p.utc_ns) << i;  // exact: seconds and nanoseconds printed as integers
  EXPECT_NEAR(t.T_w_c[i].translation().x(), p.p_w[0], 1e-6) << i;
  EXPECT_NEAR(t.T_w_c[i].translation().y(), p.p_w[1], 1e-6) << i;
  EXPECT_NEAR(t.T_w_c[i].translation().z(), p.p_w[2], 1e-6) << i;
  const Eigen::Quaterniond q(p.q_w_c[3], p.q_w_c[0], p.q_w_c[1], p.q_w_c[2]);
  const Eigen::Quaterniond q_read(t.T_w_c[i].linear());
  EXPECT_LT(q.angularDistance(q_read), 1e-8) << i;
}

TEST(TumPoseLog, ReadsBackThroughTheTumReaderAcrossManyWrites) {
  const fs::path path = testFile("round_trip.tum");
  constexpr int kPoses = 200;
  {
    // A buffer of two lines: most appends write the buffer out first.
    auto log = TumPoseLog::open(path.string(), 2 * TumPoseLog::kMaxLineBytes, "test run");
    ASSERT_TRUE(log) << log.status().toString();
    for (int k = 0; k < kPoses; ++k) ASSERT_TRUE((*log)->append(poseAt(k)).isOk()) << k;
    EXPECT_EQ((*log)->lines(), static_cast<std::uint64_t>(kPoses));
  }  // the destructor writes the rest
  const std::string text = slurp(path);
  EXPECT_EQ(text.rfind("# test run\n", 0), 0u) << text.substr(0, 80);
  auto t = files::readTumTrajectory(path.string());
  ASSERT_TRUE(t) << t.status().toString();
  ASSERT_EQ(t->size(), static_cast<std::size_t>(kPoses));
  for (int k = 0; k < kPoses; ++k) expectPose(*t, static_cast<std::size_t>(k), poseAt(k));
}

TEST(TumPoseLog, EachStartAppendsItsCommentAndPoses) {
  const fs::path path = testFile("two_starts.tum");
  for (int start = 0; start < 2; ++start) {
    auto log = TumPoseLog::open(path.string(), 4096, "start " + std::to_string(start));
    ASSERT_TRUE(log) << log.status().toString();
    for (int k = 0; k < 3; ++k) ASSERT_TRUE((*log)->append(poseAt(10 * start + k)).isOk());
    ASSERT_TRUE((*log)->flush().isOk());
  }
  const std::string text = slurp(path);
  EXPECT_NE(text.find("# start 0\n"), std::string::npos) << text;
  EXPECT_LT(text.find("# start 0\n"), text.find("# start 1\n")) << text;
  auto t = files::readTumTrajectory(path.string());
  ASSERT_TRUE(t) << t.status().toString();
  ASSERT_EQ(t->size(), 6u);
  expectPose(*t, 0, poseAt(0));
  expectPose(*t, 2, poseAt(2));
  expectPose(*t, 3, poseAt(10));
  expectPose(*t, 5, poseAt(12));
}

TEST(TumPoseLog, ErrorsNameTheFile) {
  const std::string missing = (testFile("x") / "no_such_dir" / "poses.tum").string();
  auto no_dir = TumPoseLog::open(missing, 4096, "h");
  ASSERT_FALSE(no_dir);
  EXPECT_NE(no_dir.status().message().find(missing), std::string::npos)
      << no_dir.status().message();
  EXPECT_FALSE(TumPoseLog::open(testFile("small.tum").string(), 100, "h"));  // < one line
  PoseRecord before_1970 = poseAt(0);
  before_1970.utc_ns = -5;
  auto ok = TumPoseLog::open(testFile("neg.tum").string(), 4096, "h");
  ASSERT_TRUE(ok);
  EXPECT_FALSE((*ok)->append(before_1970).isOk());
  EXPECT_EQ((*ok)->lines(), 0u);
  // /dev/full takes the open and fails every write (ENOSPC).
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no writable /dev/full";
  auto full = TumPoseLog::open("/dev/full", 4096, "h");
  ASSERT_TRUE(full) << full.status().toString();
  Status first_error = Status::ok();
  for (int k = 0; k < 100 && first_error.isOk(); ++k) first_error = (*full)->append(poseAt(k));
  ASSERT_FALSE(first_error.isOk()) << "100 lines into a 4 KiB buffer must have written";
  EXPECT_NE(first_error.message().find("/dev/full"), std::string::npos) << first_error.message();
  EXPECT_FALSE((*full)->flush().isOk());
}

TEST(TumPoseLog, AppendingAllocatesNothing) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(runtime::allocCounterActive());
  const fs::path path = testFile("alloc.tum");
  auto log = TumPoseLog::open(path.string(), 4096, "allocation test");
  ASSERT_TRUE(log);
  std::vector<PoseRecord> poses;
  for (int k = 0; k < 1000; ++k) poses.push_back(poseAt(k));
  runtime::AllocationScope scope;
  for (const PoseRecord& p : poses) ASSERT_TRUE((*log)->append(p).isOk());  // ~30 writes
  ASSERT_TRUE((*log)->flush().isOk());
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ((*log)->lines(), 1000u);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::rover
