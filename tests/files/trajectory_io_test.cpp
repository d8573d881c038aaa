#include "sunvo/files/trajectory_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace sunvo::files {
namespace {

const std::string kData = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/";
const std::string kTmp = std::string(SUNVO_BINARY_DIR) + "/trajectory_io_test_";

Trajectory randomTrajectory(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Trajectory t;
  for (int k = 0; k < n; ++k) {
    Isometry3 T = Isometry3::Identity();
    T.linear() = expSO3(3.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
    T.translation() = 500.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    t.T_w_c.push_back(T);
    // Times like a real recording: 2011-10-03 plus k * ~0.1 s, with odd nanoseconds.
    t.t_ns.push_back(1317646000'000000000 + k * 103'735'917LL + 1);
  }
  return t;
}

double maxPoseDifference(const Trajectory& a, const Trajectory& b) {
  double d = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    d = std::max(d, (a.T_w_c[k].matrix() - b.T_w_c[k].matrix()).cwiseAbs().maxCoeff());
  }
  return d;
}

TEST(TrajectoryIo, KittiRoundTrip) {
  const Trajectory t = randomTrajectory(50, 1);
  const std::string path = kTmp + "kitti.txt";
  ASSERT_TRUE(writeKittiPoses(path, t).isOk());
  auto r = readKittiPoses(path);
  ASSERT_TRUE(r) << r.status().toString();
  ASSERT_EQ(r->size(), t.size());
  EXPECT_LT(maxPoseDifference(t, *r), 1e-9);
  // No times file: nominal 10 Hz.
  EXPECT_EQ(r->t_ns[0], 0);
  EXPECT_EQ(r->t_ns[49], 49 * kKittiNominalFramePeriodNs);
  auto loaded = loadTrajectory(path);
  ASSERT_TRUE(loaded);
  EXPECT_LT(maxPoseDifference(t, *loaded), 1e-9);
}

TEST(TrajectoryIo, TumRoundTripKeepsNanosecondTimes) {
  const Trajectory t = randomTrajectory(50, 2);
  const std::string path = kTmp + "tum.txt";
  ASSERT_TRUE(writeTumTrajectory(path, t).isOk());
  auto r = loadTrajectory(path);  // detected as TUM (8 fields), '#' header skipped
  ASSERT_TRUE(r) << r.status().toString();
  ASSERT_EQ(r->size(), t.size());
  EXPECT_LT(maxPoseDifference(t, *r), 1e-9);
  EXPECT_EQ(r->t_ns, t.t_ns);  // exact: seconds are printed with 9 decimals
}

TEST(TrajectoryIo, DetectsFormat) {
  auto kitti = TextFile::fromString("a.txt", "\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(*detectTrajectoryFormat(kitti), TrajectoryFormat::kKitti);
  auto tum = TextFile::fromString("b.txt", "# comment\n  # another\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_EQ(*detectTrajectoryFormat(tum), TrajectoryFormat::kTum);
  auto other = TextFile::fromString("c.txt", "# c\n1 2 3 4 5 6 7\n");
  const Status s = detectTrajectoryFormat(other).status();
  EXPECT_EQ(s.message(),
            "c.txt:2: cannot tell the trajectory format: 7 fields (KITTI has 12, TUM has 8)");
}

TEST(TrajectoryIo, RealKitti00WithTimes) {
  auto t = loadTrajectory(kData + "00_gt_poses.txt", kData + "00_times.txt");
  ASSERT_TRUE(t) << t.status().toString();
  ASSERT_EQ(t->size(), 4541u);
  EXPECT_EQ(t->t_ns[0], 0);
  EXPECT_EQ(t->t_ns[1], 103'735'900);  // "1.037359e-01"
  // Line 2 of the file: t = (-4.690294e-02, -2.839928e-02, 8.586941e-01).
  EXPECT_DOUBLE_EQ(t->T_w_c[1].translation().z(), 8.586941e-01);
  EXPECT_DOUBLE_EQ(t->T_w_c[1].translation().x(), -4.690294e-02);
  // Rotations printed with 7 digits are re-orthonormalised on load.
  for (const Isometry3& T : t->T_w_c) {
    ASSERT_LT((T.linear() * T.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    ASSERT_NEAR(T.linear().determinant(), 1.0, 1e-14);
  }
  // A times file with another count is an error naming both files.
  const std::string short_times = kTmp + "short_times.txt";
  ASSERT_TRUE(writeWholeFile(short_times, "0\n0.1\n").isOk());
  const Status s = loadTrajectory(kData + "00_gt_poses.txt", short_times).status();
  EXPECT_EQ(s.code(), StatusCode::kParseError);
  EXPECT_NE(s.message().find("2 times for 4541 poses"), std::string::npos) << s.message();
}

TEST(TrajectoryIo, ParsesSecondsExactly) {
  const TextFile f = TextFile::fromString("t.txt", "");
  EXPECT_EQ(*parseSecondsToNs(f, "1317384588.915486123", "t"), 1317384588'915486123);
  EXPECT_EQ(*parseSecondsToNs(f, "1317384588.9154861236", "t"), 1317384588'915486124);
  EXPECT_EQ(*parseSecondsToNs(f, "12", "t"), 12'000'000'000);
  EXPECT_EQ(*parseSecondsToNs(f, "-0.5", "t"), -500'000'000);
  EXPECT_EQ(*parseSecondsToNs(f, ".25", "t"), 250'000'000);
  EXPECT_EQ(*parseSecondsToNs(f, "1.037359e-01", "t"), 103'735'900);
  EXPECT_FALSE(parseSecondsToNs(f, "1.2.3", "t"));
  EXPECT_FALSE(parseSecondsToNs(f, "-", "t"));
  EXPECT_FALSE(parseSecondsToNs(f, "99999999999", "t"));
}

// Each malformed input fails with a message naming the file, the line and the field.
struct BadCase {
  const char* name;
  const char* content;
  const char* message;
};

Status parseAs(const std::string& path, const std::string& content) {
  TextFile f = TextFile::fromString(path, content);
  auto format = detectTrajectoryFormat(f);
  if (!format) return format.status();
  TextFile g = TextFile::fromString(path, content);
  return *format == TrajectoryFormat::kKitti ? parseKittiPoses(g).status()
                                             : parseTumTrajectory(g).status();
}

TEST(TrajectoryIo, RejectsMalformedKittiAndTum) {
  const std::string kitti_ok = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const BadCase cases[] = {
      {"poses.txt", "1 0 0 0 0 1 x 0 0 0 1 0\n", "poses.txt:1: field 'r23': not a number: 'x'"},
      {"poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n",
       "poses.txt:2: expected 12 fields (3x4 row-major [R|t]), found 11"},
      {"poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n\n1 0 0 nan 0 1 0 0 0 0 1 0\n",
       "poses.txt:3: field 'tx': not finite: 'nan'"},
      {"poses.txt", "1 0 0 0 0 1 0 0 0 0 1 inf\n", "poses.txt:1: field 'tz': not finite: 'inf'"},
      {"poses.txt", "0 0 0 0 0 0 0 0 0 0 0 0\n",
       "poses.txt:1: field 'r11': rotation block is not a rotation (determinant 0.000000)"},
      {"traj.tum", "# t x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 0\n",
       "traj.tum:3: field 'qw': quaternion of zero norm"},
      {"traj.tum", "1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n",
       "traj.tum:2: field 't': time does not increase: '1.0'"},
      {"traj.tum", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1 5\n",
       "traj.tum:2: expected 8 fields (t tx ty tz qx qy qz qw), found 9"},
      {"traj.tum", "abc 0 0 0 0 0 0 1\n", "traj.tum:1: field 't': not a number: 'abc'"},
      {"traj.tum", "1.0 0 0 0 0 0 1e999 1\n", "traj.tum:1: field 'qz': not a number: '1e999'"},
  };
  for (const BadCase& c : cases) {
    const Status s = parseAs(c.name, c.content);
    EXPECT_EQ(s.code(), StatusCode::kParseError) << c.content;
    EXPECT_EQ(s.message(), c.message);
  }
  EXPECT_TRUE(parseAs("poses.txt", kitti_ok).isOk());
}

TEST(TrajectoryIo, RejectsBadFilesAndCombinations) {
  EXPECT_EQ(loadTrajectory(kTmp + "does_not_exist.txt").status().code(), StatusCode::kNotFound);
  const std::string empty = kTmp + "empty.txt";
  ASSERT_TRUE(writeWholeFile(empty, "# nothing\n\n").isOk());
  EXPECT_EQ(loadTrajectory(empty).status().message(), empty + ": no poses");
  // A TUM file carries its own times: a times file with it is refused.
  const std::string tum = kTmp + "tum_with_times.txt";
  ASSERT_TRUE(writeWholeFile(tum, "1.0 0 0 0 0 0 0 1\n").isOk());
  EXPECT_EQ(loadTrajectory(tum, kData + "00_times.txt").status().code(),
            StatusCode::kInvalidArgument);
  // A malformed times file names its line and field.
  const std::string times = kTmp + "bad_times.txt";
  ASSERT_TRUE(writeWholeFile(times, "0\n0.1\nzero\n").isOk());
  EXPECT_EQ(readTimes(times).status().message(), times + ":3: field 't': not a number: 'zero'");
  EXPECT_EQ(writeKittiPoses("/nonexistent_dir/x.txt", Trajectory{}).code(), StatusCode::kIoError);
}

TEST(TrajectoryIo, NormalisesTumQuaternions) {
  // q = 2 (cos 0.25, 0, sin 0.25, 0): a 0.5 rad turn about y, written with norm 2.
  const std::string text = "5.0 1 2 3 0 " + std::to_string(2 * std::sin(0.25)) + " 0 " +
                           std::to_string(2 * std::cos(0.25)) + "\n";
  TextFile f = TextFile::fromString("q.tum", text);
  auto t = parseTumTrajectory(f);
  ASSERT_TRUE(t) << t.status().toString();
  EXPECT_NEAR(rotationAngle(t->T_w_c[0].linear()), 0.5, 1e-6);
  EXPECT_NEAR(t->T_w_c[0].linear()(0, 2), std::sin(0.5), 1e-6);
  EXPECT_EQ(t->t_ns[0], 5'000'000'000);
}

}  // namespace
}  // namespace sunvo::files
