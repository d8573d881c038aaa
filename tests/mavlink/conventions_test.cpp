// Camera pose -> ODOMETRY: frames (camera, body FRD, local NED/FRD), quaternion convention,
// velocities and the covariance mapping.

#include "sunvo/mavlink/conventions.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sunvo::mavlink {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A level camera whose optical axis (c.z) points along forward_w in ENU; c.x = right, c.y = down.
Isometry3 levelCameraFacing(const Eigen::Vector3d& forward_w, const Eigen::Vector3d& t_w) {
  const Eigen::Vector3d down_w(0, 0, -1);
  const Eigen::Vector3d right_w = down_w.cross(forward_w).normalized();  // y x z = x
  Isometry3 T_w_c = Isometry3::Identity();
  T_w_c.linear().col(0) = right_w;
  T_w_c.linear().col(1) = down_w;
  T_w_c.linear().col(2) = forward_w.normalized();
  T_w_c.translation() = t_w;
  return T_w_c;
}

Eigen::Matrix3d fromQuaternion(const Odometry& m) {
  return Eigen::Quaterniond(m.q[0], m.q[1], m.q[2], m.q[3]).toRotationMatrix();
}

OdometryInput inputAt(const Isometry3& T_w_c) {
  OdometryInput in;
  in.time_ns = 1'317'380'000'123'456'789LL;
  in.T_w_c = T_w_c;
  in.quality_percent = 80;
  return in;
}

TEST(Conventions, CameraForwardBodyAxes) {
  const Eigen::Matrix3d C_b_c = cameraForwardC_b_c();
  EXPECT_TRUE(C_b_c.isApprox(C_b_c.transpose().inverse()));
  EXPECT_NEAR(C_b_c.determinant(), 1.0, 1e-12);
  EXPECT_TRUE((C_b_c * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX()));  // fwd
  EXPECT_TRUE((C_b_c * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));  // right
  EXPECT_TRUE((C_b_c * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ()));  // down
}

TEST(Conventions, FacingNorthInEnuIsYawZeroInNed) {
  const auto in = inputAt(levelCameraFacing({0, 1, 0}, {3, 4, 5}));
  const Odometry m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_EQ(m.frame_id, kMavFrameLocalNed);
  EXPECT_EQ(m.child_frame_id, kMavFrameBodyFrd);
  EXPECT_NEAR(m.q[0], 1.0, 1e-7);
  EXPECT_NEAR(m.q[3], 0.0, 1e-7);
  const Eigen::Vector3d rpy = rollPitchYaw(fromQuaternion(m));
  EXPECT_NEAR(rpy.norm(), 0.0, 1e-6);
  // ENU (east 3, north 4, up 5) -> NED (north 4, east 3, down -5).
  EXPECT_FLOAT_EQ(m.x, 4.0f);
  EXPECT_FLOAT_EQ(m.y, 3.0f);
  EXPECT_FLOAT_EQ(m.z, -5.0f);
  EXPECT_EQ(m.time_usec, 1'317'380'000'123'456ULL);
  EXPECT_EQ(m.quality, 80);
}

TEST(Conventions, FacingEastIsYawPlus90) {
  const Odometry m = toOdometry(inputAt(levelCameraFacing({1, 0, 0}, {0, 0, 0})),
                                WorldConvention::kEnu, cameraForwardC_b_c());
  const Eigen::Vector3d rpy = rollPitchYaw(fromQuaternion(m));
  EXPECT_NEAR(rpy.z(), 90.0 * kDeg, 1e-6);
  EXPECT_NEAR(rpy.x(), 0.0, 1e-6);
  EXPECT_NEAR(rpy.y(), 0.0, 1e-6);
  // q = (cos 45deg, 0, 0, sin 45deg): a rotation about NED down, w >= 0.
  EXPECT_NEAR(m.q[0], std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(m.q[3], std::sqrt(0.5), 1e-7);
  // The body x axis (forward) maps to NED east.
  EXPECT_TRUE(
      (fromQuaternion(m) * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-6));
}

TEST(Conventions, PitchUpAndRollRight) {
  // Camera facing north, tilted up by 10 deg: forward gains an up (= -down) component.
  const Eigen::Vector3d fwd(0, std::cos(10 * kDeg), std::sin(10 * kDeg));
  Isometry3 T_w_c = levelCameraFacing({0, 1, 0}, {0, 0, 0});
  T_w_c.linear() = Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                   T_w_c.linear();  // about ENU east: north tips up
  EXPECT_TRUE((T_w_c.linear().col(2)).isApprox(fwd));
  Eigen::Vector3d rpy = rollPitchYaw(
      fromQuaternion(toOdometry(inputAt(T_w_c), WorldConvention::kEnu, cameraForwardC_b_c())));
  EXPECT_NEAR(rpy.y(), 10 * kDeg, 1e-6);
  EXPECT_NEAR(rpy.x(), 0.0, 1e-6);
  // Roll right wing down by 5 deg: about the forward (north) axis, east tips down.
  T_w_c = levelCameraFacing({0, 1, 0}, {0, 0, 0});
  T_w_c.linear() =
      Eigen::AngleAxisd(5 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix() * T_w_c.linear();
  EXPECT_LT(T_w_c.linear().col(0).z(), 0.0);  // right axis points below the horizon
  rpy = rollPitchYaw(
      fromQuaternion(toOdometry(inputAt(T_w_c), WorldConvention::kEnu, cameraForwardC_b_c())));
  EXPECT_NEAR(rpy.x(), 5 * kDeg, 1e-6);
  EXPECT_NEAR(rpy.y(), 0.0, 1e-6);
}

TEST(Conventions, VelocityAndRatesInBodyFrd) {
  OdometryInput in = inputAt(levelCameraFacing({1, 0, 0}, {0, 0, 0}));  // facing east
  in.v_w = {2.0, 0.0, 0.5};      // east (forward) 2 m/s, climbing 0.5 m/s
  in.omega_c = {0.0, 0.1, 0.0};  // about camera y (down): turning right
  const Odometry m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_NEAR(m.vx, 2.0, 1e-6);
  EXPECT_NEAR(m.vy, 0.0, 1e-6);
  EXPECT_NEAR(m.vz, -0.5, 1e-6);  // up is -down
  EXPECT_NEAR(m.yawspeed, 0.1, 1e-7);
  EXPECT_NEAR(m.rollspeed, 0.0, 1e-7);
  EXPECT_NEAR(m.pitchspeed, 0.0, 1e-7);
  // Unknown velocity and rates travel as NaN.
  const Odometry u = toOdometry(inputAt(in.T_w_c), WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_TRUE(std::isnan(u.vx) && std::isnan(u.vy) && std::isnan(u.vz));
  EXPECT_TRUE(std::isnan(u.rollspeed) && std::isnan(u.yawspeed));
}

TEST(Conventions, CameraFirstFrameWorldIsLocalFrd) {
  Isometry3 T_w_c = Isometry3::Identity();
  T_w_c.translation() = Eigen::Vector3d(0.5, 0.25, 2.0);  // 2 m forward, 0.5 right, 0.25 down
  const Odometry m =
      toOdometry(inputAt(T_w_c), WorldConvention::kCameraFirstFrame, cameraForwardC_b_c());
  EXPECT_EQ(m.frame_id, kMavFrameLocalFrd);
  EXPECT_FLOAT_EQ(m.x, 2.0f);
  EXPECT_FLOAT_EQ(m.y, 0.5f);
  EXPECT_FLOAT_EQ(m.z, 0.25f);
  EXPECT_NEAR(m.q[0], 1.0, 1e-7);
  // A camera turned right by 30 deg about its y (down) axis is yaw +30 deg.
  T_w_c.linear() = Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d rpy = rollPitchYaw(fromQuaternion(
      toOdometry(inputAt(T_w_c), WorldConvention::kCameraFirstFrame, cameraForwardC_b_c())));
  EXPECT_NEAR(rpy.z(), 30 * kDeg, 1e-6);
}

int upperIndex(int r, int c) {
  // Row-major upper triangle of a 6x6 matrix: row r starts after 6 + 5 + ... (r rows).
  return r * 6 - r * (r - 1) / 2 + (c - r);
}

TEST(Conventions, CovarianceOrderingAndFrames) {
  OdometryInput in = inputAt(levelCameraFacing({0, 1, 0}, {0, 0, 0}));
  in.cov_pose.setZero();
  in.cov_pose.block<3, 3>(0, 0).diagonal() << 1e-4, 2e-4, 3e-4;  // rot about E, N, U
  in.cov_pose.block<3, 3>(3, 3).diagonal() << 1.0, 2.0, 3.0;     // pos E, N, U
  in.cov_pose(3, 4) = in.cov_pose(4, 3) = 0.5;                   // E-N correlation
  const Odometry m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(0, 0)], 2.0f);  // north
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(1, 1)], 1.0f);  // east
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(2, 2)], 3.0f);  // down
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(0, 1)], 0.5f);
  // Facing north, level: roll is about north (ENU y), pitch about east (ENU x), yaw about down.
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(3, 3)], 2e-4f);
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(4, 4)], 1e-4f);
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(5, 5)], 3e-4f);
  EXPECT_EQ(upperIndex(5, 5), 20);
  EXPECT_FLOAT_EQ(m.pose_covariance[upperIndex(0, 3)], 0.0f);
  EXPECT_TRUE(std::isnan(m.velocity_covariance[0]));
  // Unknown covariance: NaN in the first element.
  const Odometry u = toOdometry(inputAt(in.T_w_c), WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_TRUE(std::isnan(u.pose_covariance[0]));
}

TEST(Conventions, EulerCovarianceJacobianMatchesFiniteDifferences) {
  // For random attitudes, the rotation rows of the mapping must equal the numerical derivative of
  // (roll, pitch, yaw) of C_l_b under a world perturbation Exp(d) * C_w_c. Checked column by
  // column by feeding a covariance with a single unit variance on one world axis.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d C_b_c = cameraForwardC_b_c();
  for (int trial = 0; trial < 20; ++trial) {
    Isometry3 T_w_c = Isometry3::Identity();
    T_w_c.linear() = expSO3(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 1.2);
    const Eigen::Matrix3d C_l_w = worldToLocal(WorldConvention::kEnu, C_b_c);
    auto rpyOf = [&](const Eigen::Matrix3d& C_w_c) {
      return rollPitchYaw(C_l_w * C_w_c * C_b_c.transpose());
    };
    const Eigen::Vector3d rpy0 = rpyOf(T_w_c.linear());
    if (std::abs(std::cos(rpy0.y())) < 0.2) continue;  // stay away from gimbal lock
    for (int axis = 0; axis < 3; ++axis) {
      const double h = 1e-6;
      const Eigen::Vector3d d = Eigen::Vector3d::Unit(axis) * h;
      Eigen::Vector3d diff =
          (rpyOf(expSO3(d) * T_w_c.linear()) - rpyOf(expSO3(-d) * T_w_c.linear())) / (2 * h);
      OdometryInput in = inputAt(T_w_c);
      in.cov_pose.setZero();
      in.cov_pose(axis, axis) = 1.0;
      const Odometry m = toOdometry(in, WorldConvention::kEnu, C_b_c);
      // With a single unit variance, cov(i, j) = J_i J_j; the diagonal gives J_i^2 and the
      // off-diagonal terms give the signs.
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(m.pose_covariance[upperIndex(3 + i, 3 + i)], diff(i) * diff(i), 1e-4)
            << "trial " << trial << " axis " << axis << " angle " << i;
        for (int j = i + 1; j < 3; ++j) {
          EXPECT_NEAR(m.pose_covariance[upperIndex(3 + i, 3 + j)], diff(i) * diff(j), 1e-4);
        }
      }
    }
  }
}

TEST(Conventions, NonFinitePoseIsSentAsFailedNeverAsNaN) {
  OdometryInput in = inputAt(Isometry3::Identity());
  in.T_w_c.translation().x() = std::numeric_limits<double>::quiet_NaN();
  const Odometry m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_EQ(m.quality, -1);
  EXPECT_TRUE(std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z));
  EXPECT_EQ(m.q, (std::array<float, 4>{1, 0, 0, 0}));
  EXPECT_TRUE(std::isnan(m.pose_covariance[0]));
}

TEST(Conventions, QualityIsClampedAndNegativeTimeIsZero) {
  OdometryInput in = inputAt(Isometry3::Identity());
  in.quality_percent = 250;
  in.time_ns = -5;
  Odometry m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_EQ(m.quality, 100);
  EXPECT_EQ(m.time_usec, 0u);
  in.quality_percent = -7;
  m = toOdometry(in, WorldConvention::kEnu, cameraForwardC_b_c());
  EXPECT_EQ(m.quality, -1);
}

}  // namespace
}  // namespace sunvo::mavlink
