#include "sunvo/sunfusion/sun_residual.hpp"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "sunvo/core/geometry.hpp"
#include "sunvo/sunfusion/simulated_sun_source.hpp"
#include "sunvo/sunfusion/sun_gate.hpp"

namespace sunvo::sunfusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A rotation prior e = 2 vec(q_ref^-1 q) / sigma: keeps the problem well posed and lets a biased
// sun term show up as a pose change.
struct RotationPrior {
  RotationPrior(const Eigen::Quaterniond& q_ref, double sigma) : q_ref_(q_ref), sigma_(sigma) {}
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qq(q);
    const Eigen::Quaternion<T> d = q_ref_.cast<T>().conjugate() * qq;
    const T sign = d.w() < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) r[i] = T(2) * sign * d.vec()[i] / T(sigma_);
    return true;
  }
  Eigen::Quaterniond q_ref_;
  double sigma_;
};

// The naive azimuth-only formulation the design notes warn about: (m_x, 0, m_z) against s_hat.
struct NaiveAzimuthResidual {
  NaiveAzimuthResidual(const Eigen::Vector3d& sun_b, const Eigen::Vector2d& m)
      : sun_b_(sun_b), m_(m) {}
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> C(q);
    const Eigen::Matrix<T, 3, 1> s = C * sun_b_.cast<T>();
    r[0] = (s.x() - T(m_.x())) / T(0.05);  // same sigma as the proper term below
    r[1] = s.y() / T(0.05);
    r[2] = (s.z() - T(m_.y())) / T(0.05);
    return true;
  }
  Eigen::Vector3d sun_b_;
  Eigen::Vector2d m_;
};

double solveAndMeasureShift(const Eigen::Quaterniond& q_true, ceres::CostFunction* sun_cost) {
  Eigen::Quaterniond q = q_true;
  ceres::Problem problem;
  problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<RotationPrior, 3, 4>(new RotationPrior(q_true, 0.05)),
      nullptr, q.coeffs().data());
  problem.AddResidualBlock(sun_cost, nullptr, q.coeffs().data());
  ceres::Solver::Options opts;
  opts.max_num_iterations = 50;
  opts.function_tolerance = 1e-16;
  opts.gradient_tolerance = 1e-16;
  opts.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(opts, &problem, &summary);
  return rotationAngle((q_true.conjugate() * q).toRotationMatrix());
}

TEST(SunAzimuthResidual, PerfectMeasurementLeavesCorrectPoseUnchangedAtAnyElevation) {
  const Eigen::Quaterniond q_k_b(
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.1, 1.0, 0.05).normalized()));
  for (double elevation_deg = 0.0; elevation_deg <= 80.0; elevation_deg += 10.0) {
    // The true sun in camera k at this elevation above the camera's x-z plane, azimuth 35 deg.
    const Eigen::Vector3d sun_k = sunFromAzimuthZenith(35.0 * kDeg, (90.0 - elevation_deg) * kDeg);
    const Eigen::Vector3d sun_b = q_k_b.conjugate() * sun_k;
    const Eigen::Vector2d m = xzDirection(sun_k);

    const double shift = solveAndMeasureShift(q_k_b, SunAzimuthResidual::Create(sun_b, m, 0.05));
    EXPECT_LT(shift, 1e-9) << "elevation " << elevation_deg;

    const double naive_shift =
        solveAndMeasureShift(q_k_b, new ceres::AutoDiffCostFunction<NaiveAzimuthResidual, 3, 4>(
                                        new NaiveAzimuthResidual(sun_b, m)));
    if (elevation_deg >= 20.0) {
      // The naive form drags the camera to pull the sun into the x-z plane.
      EXPECT_GT(naive_shift, 1.0 * kDeg) << "elevation " << elevation_deg;
    }
  }
}

TEST(SunDirectionResidual, ZeroAtTruthAndCorrectsAYawError) {
  const Eigen::Quaterniond q_true(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d sun_k = sunFromAzimuthZenith(-60.0 * kDeg, 50.0 * kDeg);
  const Eigen::Vector3d sun_b = q_true.conjugate() * sun_k;
  SunDirectionResidual r(sun_b, sun_k, 0.1);
  Eigen::Vector3d res;
  ASSERT_TRUE(r(q_true.coeffs().data(), res.data()));
  EXPECT_LT(res.norm(), 1e-12);

  // Start 5 degrees off in yaw (about camera y); the sun alone pulls the estimate back.
  Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitY())) * q_true;
  ceres::Problem problem;
  problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  problem.AddResidualBlock(SunDirectionResidual::Create(sun_b, sun_k, 0.1), nullptr,
                           q.coeffs().data());
  ceres::Solver::Options opts;
  ceres::Solver::Summary summary;
  ceres::Solve(opts, &problem, &summary);
  // One direction leaves the rotation about the sun axis free, so compare the predicted sun.
  EXPECT_LT(((q * sun_b) - sun_k).norm(), 1e-8);
}

TEST(SunResiduals, AutodiffMatchesCentralDifferences) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  const Eigen::Vector3d sun_b = Eigen::Vector3d(0.2, -0.6, 0.7).normalized();
  const Eigen::Vector3d meas = Eigen::Vector3d(0.25, -0.55, 0.75).normalized();
  std::unique_ptr<ceres::CostFunction> full(SunDirectionResidual::Create(sun_b, meas, 0.1));
  std::unique_ptr<ceres::CostFunction> az(
      SunAzimuthResidual::Create(sun_b, xzDirection(meas), 0.1));
  for (ceres::CostFunction* f : {full.get(), az.get()}) {
    const int m = f->num_residuals();
    Eigen::VectorXd r(m);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> J(m, 4);
    const double* params[] = {q.coeffs().data()};
    double* jacs[] = {J.data()};
    ASSERT_TRUE(f->Evaluate(params, r.data(), jacs));
    for (int j = 0; j < 4; ++j) {
      Eigen::Vector4d p = q.coeffs(), mnus = q.coeffs();
      const double h = 1e-6;
      p[j] += h;
      mnus[j] -= h;
      Eigen::VectorXd rp(m), rm(m);
      const double* pp[] = {p.data()};
      const double* pm[] = {mnus.data()};
      ASSERT_TRUE(f->Evaluate(pp, rp.data(), nullptr));
      ASSERT_TRUE(f->Evaluate(pm, rm.data(), nullptr));
      EXPECT_LT(((rp - rm) / (2 * h) - J.col(j)).norm(), 1e-6);
    }
  }
}

// The square-root information of a direction measured better along one axis: W^T W is the inverse
// of R_s = sigma^2 (I - a a^T) + sigma_s^2 a a^T for an axis a normal to the measurement, the axis
// is first made normal to it, and an unusable axis or sigma_strong falls back to I / sigma.
TEST(DirectionSqrtInformationTest, WhitensTheStrongAxisByItsOwnSigma) {
  const Eigen::Vector3d s = Eigen::Vector3d(0.1, -0.99, 0.05).normalized();
  const Eigen::Vector3d a = s.cross(Eigen::Vector3d::UnitZ()).normalized();
  const double sigma = 0.02, sigma_s = 0.004;
  const Eigen::Matrix3d R = sigma * sigma * (Eigen::Matrix3d::Identity() - a * a.transpose()) +
                            sigma_s * sigma_s * a * a.transpose();
  const Eigen::Matrix3d W = directionSqrtInformation(s, sigma, sigma_s, a);
  EXPECT_LT((W.transpose() * W - R.inverse()).norm() / R.inverse().norm(), 1e-12);
  // An axis with a part along s is projected: the same W.
  const Eigen::Matrix3d W2 = directionSqrtInformation(s, sigma, sigma_s, 3.0 * a + 0.5 * s);
  EXPECT_LT((W2 - W).norm(), 1e-9 * W.norm());
  const Eigen::Matrix3d iso = Eigen::Matrix3d::Identity() / sigma;
  EXPECT_EQ(directionSqrtInformation(s, sigma, 0.0, a), iso);
  EXPECT_EQ(directionSqrtInformation(s, sigma, sigma, a), iso);  // not smaller
  EXPECT_EQ(directionSqrtInformation(s, sigma, 2.0 * sigma, a), iso);
  EXPECT_EQ(directionSqrtInformation(s, sigma, sigma_s, Eigen::Vector3d::Zero()), iso);
  EXPECT_EQ(directionSqrtInformation(s, sigma, sigma_s, s), iso);  // along the measurement
  EXPECT_EQ(directionSqrtInformation(s, sigma, sigma_s, Eigen::Vector3d(NAN, 0.0, 1.0)), iso);
  EXPECT_EQ(directionSqrtInformation(s, sigma, NAN, a), iso);
}

// The residual applies it: an error along the strong axis is weighed by 1 / sigma_strong, one
// across it by 1 / sigma.
TEST(SunDirectionResidualTest, StrongAxisWeighsItsErrorByItsOwnSigma) {
  const Eigen::Vector3d measured(0.0, -1.0, 0.0);
  const double eps = 1e-4;
  const auto whitenedNorm = [&](const Eigen::Vector3d& truth_b, double sigma_strong) {
    SunDirectionResidual r(truth_b, measured, 0.02);
    r.set(truth_b, measured, 0.02, 0.0, sigma_strong, Eigen::Vector3d::UnitX());
    const double q[4] = {0.0, 0.0, 0.0, 1.0};  // identity, Eigen order x, y, z, w
    double e[3];
    EXPECT_TRUE(r(q, e));
    return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  };
  const Eigen::Vector3d along_x = Eigen::Vector3d(eps, -1.0, 0.0).normalized();
  const Eigen::Vector3d along_z = Eigen::Vector3d(0.0, -1.0, eps).normalized();
  EXPECT_NEAR(whitenedNorm(along_x, 0.004), eps / 0.004, 1e-3 * eps / 0.004);
  EXPECT_NEAR(whitenedNorm(along_z, 0.004), eps / 0.02, 1e-3 * eps / 0.02);
  EXPECT_NEAR(whitenedNorm(along_x, 0.0), eps / 0.02, 1e-3 * eps / 0.02);
}

}  // namespace
}  // namespace sunvo::sunfusion
