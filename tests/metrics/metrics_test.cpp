#include "sunvo/metrics/metrics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "sunvo/files/trajectory_io.hpp"

namespace sunvo::metrics {
namespace {

const std::string kGt00 = std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_gt_poses.txt";

Isometry3 pose(const Eigen::Matrix3d& C, const Eigen::Vector3d& p) {
  Isometry3 T = Isometry3::Identity();
  T.linear() = C;
  T.translation() = p;
  return T;
}

Eigen::Matrix3d rotY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix();
}

// Ground truth along camera z, 1 m per frame: p_k = (0, 0, k), C_k = I, k = 0..n-1.
std::vector<Isometry3> straightLine(int n, double step_m = 1.0, double scale = 1.0) {
  std::vector<Isometry3> out;
  for (int k = 0; k < n; ++k) {
    out.push_back(pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, scale * step_m * k)));
  }
  return out;
}

TEST(Table1, StraightLineWithScaleError) {
  // GT p_k = (0,0,k), estimate p_k = (0,0,1.02 k), k = 0..10 (N = 11, path length L = 10 m).
  // Δp_k = (0,0,0.02 k):
  //   trans ARMSE = (1/11) Σ 0.02 k / √3 = 0.02 · 5 / √3 = 0.0577350...  (mean of k is 5)
  //   x-z plane   = (1/11) Σ 0.02 k / √2 = 0.1 / √2      = 0.0707106...
  //   EN plane    = 0 (x and y errors are 0);  rot ARMSE = 0
  //   final drift = 0.2 m = 2 % of 10 m, also in the x-z plane; 0 in the EN plane.
  const auto gt = straightLine(11);
  const auto est = straightLine(11, 1.0, 1.02);
  auto m = computeTable1(gt, est, HorizontalPlane::kCameraXZ);
  ASSERT_TRUE(m) << m.status().toString();
  EXPECT_EQ(m->num_poses, 11u);
  EXPECT_NEAR(m->trans_armse_m, 0.1 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(m->trans_armse_plane_m, 0.1 / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(m->rot_armse_rad, 0.0);
  EXPECT_NEAR(m->gt_path_length_m, 10.0, 1e-12);
  EXPECT_NEAR(m->final_drift_m, 0.2, 1e-12);
  EXPECT_NEAR(m->final_drift_pct, 2.0, 1e-10);
  EXPECT_NEAR(m->final_drift_plane_m, 0.2, 1e-12);
  EXPECT_NEAR(m->final_drift_plane_pct, 2.0, 1e-10);

  auto en = computeTable1(gt, est, HorizontalPlane::kEastNorth);
  ASSERT_TRUE(en);
  EXPECT_NEAR(en->trans_armse_plane_m, 0.0, 1e-15);
  EXPECT_NEAR(en->final_drift_plane_m, 0.0, 1e-15);
  EXPECT_NEAR(en->trans_armse_m, 0.1 / std::sqrt(3.0), 1e-12);
}

TEST(Table1, SingleHeadingErrorAtFrame5) {
  // GT: p_k = (0,0,k), C = I, k = 0..10. The estimate is exact up to frame 4; at frame 5 its
  // heading turns by α = 0.1 rad about y (C = R_y(α) for k >= 5) while p_5 is still right, and
  // from there it drives 1 m per frame along its own z: p_k = (0,0,5) + (k-5)(sin α, 0, cos α).
  //   Δp_k = (k-5) (sin α, 0, cos α - 1), |Δp_k| = (k-5) · 2 sin(α/2) for k >= 5, 0 before.
  //   Σ_k |Δp_k| = (0+1+2+3+4+5) · 2 sin(α/2) = 30 sin(α/2)
  //   trans ARMSE = 30 sin(α/2) / (11 √3);  x-z plane (Δy = 0): 30 sin(α/2) / (11 √2)
  //   θ_k = α for k = 5..10 (6 poses): rot ARMSE = 6 α / (11 √3)
  //   final drift = 5 · 2 sin(α/2) = 10 sin(α/2) m, = 10 sin(α/2) / 10 m · 100 %.
  const double a = 0.1;
  const auto gt = straightLine(11);
  std::vector<Isometry3> est;
  for (int k = 0; k < 11; ++k) {
    if (k < 5) {
      est.push_back(gt[static_cast<std::size_t>(k)]);
    } else {
      est.push_back(pose(rotY(a), Eigen::Vector3d(0, 0, 5) +
                                      (k - 5) * Eigen::Vector3d(std::sin(a), 0, std::cos(a))));
    }
  }
  auto m = computeTable1(gt, est, HorizontalPlane::kCameraXZ);
  ASSERT_TRUE(m);
  const double s = std::sin(a / 2);
  EXPECT_NEAR(m->trans_armse_m, 30 * s / (11 * std::sqrt(3.0)), 1e-12);
  EXPECT_NEAR(m->trans_armse_plane_m, 30 * s / (11 * std::sqrt(2.0)), 1e-12);
  EXPECT_NEAR(m->rot_armse_rad, 6 * a / (11 * std::sqrt(3.0)), 1e-12);
  EXPECT_NEAR(m->final_drift_m, 10 * s, 1e-12);
  EXPECT_NEAR(m->final_drift_pct, 10 * s / 10.0 * 100.0, 1e-10);
  EXPECT_NEAR(m->final_drift_plane_m, 10 * s, 1e-12);

  // The same numbers when both trajectories are moved into another world frame: the metric
  // takes each relative to its own first pose (the estimate may start anywhere).
  const Isometry3 W = pose(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix(),
                           Eigen::Vector3d(10, -4, 2));
  const Isometry3 V = pose(rotY(-1.2), Eigen::Vector3d(-3, 8, 1));
  std::vector<Isometry3> gt_w;
  std::vector<Isometry3> est_v;
  for (std::size_t k = 0; k < gt.size(); ++k) {
    gt_w.push_back(W * gt[k]);
    est_v.push_back(V * est[k]);
  }
  auto moved = computeTable1(gt_w, est_v, HorizontalPlane::kCameraXZ);
  ASSERT_TRUE(moved);
  EXPECT_NEAR(moved->trans_armse_m, m->trans_armse_m, 1e-12);
  EXPECT_NEAR(moved->rot_armse_rad, m->rot_armse_rad, 1e-12);
  EXPECT_NEAR(moved->final_drift_m, m->final_drift_m, 1e-12);
}

TEST(Table1, PureRotation) {
  // Both stay at the origin; the estimate turns θ_k = 0.01 k rad about a fixed axis, k = 0..4.
  //   rot ARMSE = mean(θ_k) / √3 = 0.02 / √3; no translation error; L = 0 -> percentages NaN.
  //   APE rotation: mean 0.02, median 0.02, max 0.04, RMSE = 0.01 sqrt((0+1+4+9+16)/5) = 0.01 √6.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  std::vector<Isometry3> gt(5, Isometry3::Identity());
  std::vector<Isometry3> est;
  for (int k = 0; k < 5; ++k) {
    est.push_back(pose(Eigen::AngleAxisd(0.01 * k, axis).matrix(), Eigen::Vector3d::Zero()));
  }
  auto m = computeTable1(gt, est, HorizontalPlane::kCameraXZ);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->rot_armse_rad, 0.02 / std::sqrt(3.0), 1e-14);
  EXPECT_EQ(m->trans_armse_m, 0.0);
  EXPECT_EQ(m->final_drift_m, 0.0);
  EXPECT_EQ(m->gt_path_length_m, 0.0);
  EXPECT_TRUE(std::isnan(m->final_drift_pct));
  EXPECT_TRUE(std::isnan(m->final_drift_plane_pct));

  auto ev = evaluate(gt, est);
  ASSERT_TRUE(ev) << ev.status().toString();
  EXPECT_NEAR(ev->ape_raw.rotation_rad.mean, 0.02, 1e-14);
  EXPECT_NEAR(ev->ape_raw.rotation_rad.median, 0.02, 1e-14);
  EXPECT_NEAR(ev->ape_raw.rotation_rad.max, 0.04, 1e-14);
  EXPECT_NEAR(ev->ape_raw.rotation_rad.rmse, 0.01 * std::sqrt(6.0), 1e-14);
  EXPECT_EQ(ev->ape_raw.translation_m.max, 0.0);
  EXPECT_EQ(ev->kitti.num_segments, 0u);  // no travel: no segment, averages undefined
  EXPECT_TRUE(std::isnan(ev->kitti.t_err_pct));
  EXPECT_FALSE(ev->se3_alignment.well_conditioned);
  // Per-frame RPE: every step turns 0.01 rad.
  EXPECT_NEAR(ev->rpe_frame.rotation_rad.max, 0.01, 1e-14);
  EXPECT_NEAR(ev->rpe_frame.rotation_rad.mean, 0.01, 1e-14);
}

TEST(Validation, RejectsBadInput) {
  const auto gt = straightLine(5);
  EXPECT_EQ(computeTable1(gt, straightLine(4), HorizontalPlane::kCameraXZ).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_FALSE(computeTable1(straightLine(1), straightLine(1), HorizontalPlane::kCameraXZ));
  auto bad = gt;
  bad[3].translation().x() = std::nan("");
  const auto s = computeTable1(gt, bad, HorizontalPlane::kCameraXZ).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("estimated pose 3"), std::string::npos) << s.message();
  EXPECT_FALSE(evaluate(bad, gt));
  EXPECT_FALSE(computeKittiSegments(gt, bad));
  KittiSegmentOptions opt;
  opt.step_frames = 0;
  EXPECT_NE(opt.validate().message().find("kitti.step_frames"), std::string::npos);
  EvaluationOptions eo;
  eo.rpe_distance_m = -1;
  EXPECT_NE(eo.validate().message().find("rpe_distance_m"), std::string::npos);
}

TEST(Percentile, NearestIndexWithoutInterpolation) {
  EXPECT_EQ(percentile({}, 0.5), 0.0);
  EXPECT_EQ(percentile({5.0, 1.0, 3.0}, 0.5), 3.0);
  EXPECT_EQ(percentile({4.0, 1.0, 2.0, 3.0}, 0.5), 3.0);  // index round(1.5) = 2
  std::vector<double> v;
  for (int i = 0; i < 101; ++i) v.push_back(100.0 - i);  // 100 .. 0, unsorted order
  EXPECT_EQ(percentile(v, 0.99), 99.0);
  EXPECT_EQ(percentile(v, 0.0), 0.0);
  EXPECT_EQ(percentile(v, 1.0), 100.0);
  EXPECT_EQ(percentile(v, 2.0), 100.0);  // q clamped to [0, 1]
}

TEST(ErrorStats, MedianRmseMeanMax) {
  const ErrorStats odd = summarize({3.0, 1.0, 2.0});
  EXPECT_EQ(odd.median, 2.0);
  EXPECT_EQ(odd.mean, 2.0);
  EXPECT_EQ(odd.max, 3.0);
  EXPECT_NEAR(odd.rmse, std::sqrt(14.0 / 3.0), 1e-15);
  const ErrorStats even = summarize({4.0, 1.0, 2.0, 3.0});
  EXPECT_EQ(even.median, 2.5);
  EXPECT_EQ(even.count, 4u);
  EXPECT_TRUE(std::isnan(summarize({}).rmse));
}

TEST(Umeyama, RecoversKnownSimilarityAndRigidMotion) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::vector<Eigen::Vector3d> x;
  for (int i = 0; i < 30; ++i) x.emplace_back(u(rng), u(rng), u(rng));
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(-1, 0.3, 2).normalized()).matrix();
  const Eigen::Vector3d t(12.0, -7.5, 3.25);
  const double s = 1.7;
  std::vector<Eigen::Vector3d> y_sim;
  std::vector<Eigen::Vector3d> y_rigid;
  for (const auto& p : x) {
    y_sim.push_back(s * R * p + t);
    y_rigid.push_back(R * p + t);
  }
  auto sim = umeyama(x, y_sim, true);
  ASSERT_TRUE(sim);
  EXPECT_NEAR(sim->scale, s, 1e-12);
  EXPECT_LT((sim->R - R).norm(), 1e-12);
  EXPECT_LT((sim->t - t).norm(), 1e-10);
  EXPECT_TRUE(sim->well_conditioned);

  auto rigid = umeyama(x, y_rigid, false);
  ASSERT_TRUE(rigid);
  EXPECT_EQ(rigid->scale, 1.0);
  EXPECT_LT((rigid->R - R).norm(), 1e-12);
  EXPECT_LT((rigid->t - t).norm(), 1e-10);
  EXPECT_NEAR(rigid->R.determinant(), 1.0, 1e-12);

  // A reflected point set must still give a proper rotation (det +1), never a reflection.
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : x) mirrored.emplace_back(p.x(), p.y(), -p.z());
  auto proper = umeyama(x, mirrored, false);
  ASSERT_TRUE(proper);
  EXPECT_NEAR(proper->R.determinant(), 1.0, 1e-12);

  EXPECT_FALSE(umeyama(x, std::vector<Eigen::Vector3d>(x.begin(), x.end() - 1), false));
  EXPECT_FALSE(umeyama(std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::Ones()),
                       std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::Zero()), false));
}

TEST(Ape, Se3AlignmentRemovesAKnownRigidOffset) {
  // The estimate is the ground truth seen from another world frame: T_est = A^-1 T_gt.
  // Raw APE is large; after Umeyama SE(3) alignment APE vanishes and A is recovered.
  auto gt = files::readKittiPoses(kGt00);
  ASSERT_TRUE(gt) << gt.status().toString();
  const Isometry3 A =
      pose(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1, -0.1).normalized()).matrix(),
           Eigen::Vector3d(30, -2, 15));
  std::vector<Isometry3> est;
  for (const auto& T : gt->T_w_c) est.push_back(A.inverse(Eigen::Isometry) * T);
  auto ev = evaluate(gt->T_w_c, est);
  ASSERT_TRUE(ev);
  EXPECT_GT(ev->ape_raw.translation_m.rmse, 10.0);
  EXPECT_NEAR(ev->ape_raw.rotation_rad.max, 0.4, 1e-9);
  EXPECT_LT(ev->ape_se3.translation_m.max, 1e-9);
  EXPECT_LT(ev->ape_se3.rotation_rad.max, 1e-9);
  EXPECT_LT((ev->se3_alignment.R - A.linear()).norm(), 1e-12);
  EXPECT_LT((ev->se3_alignment.t - A.translation()).norm(), 1e-9);
  // Table 1 takes each trajectory relative to its first pose: no error at all.
  EXPECT_LT(ev->table1.trans_armse_m, 1e-9);
  EXPECT_LT(ev->table1.rot_armse_rad, 1e-12);
}

// Devkit segments on a straight 1 km line (1001 poses, 1 m apart) with a 1 % scale error.
// For a start f and length len the devkit takes l = the first frame with dist[l] > dist[f] + len,
// i.e. l = f + len + 1 (strictly greater), so each segment has |Δp_gt| = len + 1 m and
// t_err = 0.01 (len + 1) / len. A segment exists when f + len + 1 <= 1000, f = 0, 10, ...,
// so len has floor((999 - len) / 10) + 1 of them. Rotations are exact: r_err = 0.
TEST(KittiSegments, StraightKilometreWithOnePercentScale) {
  const auto gt = straightLine(1001);
  const auto est = straightLine(1001, 1.0, 1.01);
  auto m = computeKittiSegments(gt, est);
  ASSERT_TRUE(m);
  double expected_sum = 0.0;
  std::size_t expected_count = 0;
  ASSERT_EQ(m->per_length.size(), 8u);
  for (int len = 100; len <= 800; len += 100) {
    const std::size_t count = static_cast<std::size_t>((999 - len) / 10 + 1);
    const double t_err = 0.01 * (len + 1) / len;
    const auto& pl = m->per_length[static_cast<std::size_t>(len / 100 - 1)];
    EXPECT_EQ(pl.num_segments, count) << len;
    EXPECT_NEAR(pl.t_err_pct, 100.0 * t_err, 1e-10) << len;
    EXPECT_EQ(pl.r_err_deg_per_m, 0.0);
    expected_sum += count * t_err;
    expected_count += count;
  }
  EXPECT_EQ(m->num_segments, expected_count);
  EXPECT_NEAR(m->t_err_pct, 100.0 * expected_sum / static_cast<double>(expected_count), 1e-10);
  EXPECT_EQ(m->r_err_deg_per_m, 0.0);
}

// With 1 cm spacing (100,001 poses) the devkit's overshoot is below 1 cm per segment, so the
// average is 1 % to within 0.01 / 100 relative, and never below 1 %.
TEST(KittiSegments, DenseStraightKilometreIsOnePercent) {
  const auto gt = straightLine(100001, 0.01);
  const auto est = straightLine(100001, 0.01, 1.01);
  auto m = computeKittiSegments(gt, est);
  ASSERT_TRUE(m);
  EXPECT_GE(m->t_err_pct, 1.0 - 1e-12);
  EXPECT_LE(m->t_err_pct, 1.0 * (1.0 + 0.01 / 100.0) + 1e-12);
  EXPECT_EQ(m->r_err_deg_per_m, 0.0);
  EXPECT_GT(m->num_segments, 0u);
}

// The real KITTI 00 ground truth against a copy with every translation × 1.01.
TEST(RealKitti00, OnePercentScaleCopy) {
  auto gt = files::readKittiPoses(kGt00);
  ASSERT_TRUE(gt) << gt.status().toString();
  ASSERT_EQ(gt->size(), 4541u);
  std::vector<Isometry3> est = gt->T_w_c;
  for (auto& T : est) T.translation() *= 1.01;
  auto ev = evaluate(gt->T_w_c, est);
  ASSERT_TRUE(ev) << ev.status().toString();
  const Eigen::Vector3d p0 = gt->T_w_c.front().translation();
  const Eigen::Vector3d pN = gt->T_w_c.back().translation();
  // Δp_N = 0.01 (p_N - p_0) in the first frame: the final drift is 1 % of |p_N - p_0|.
  const double expected = 0.01 * (pN - p0).norm();
  EXPECT_NEAR(ev->table1.final_drift_m / expected, 1.0, 1e-6);
  EXPECT_NEAR(ev->table1.final_drift_pct, 100.0 * expected / cumulativeDistances(gt->T_w_c).back(),
              1e-6);
  // Same rotations: every rotational error is exactly zero.
  EXPECT_EQ(ev->table1.rot_armse_rad, 0.0);
  EXPECT_EQ(ev->kitti.r_err_deg_per_m, 0.0);
  EXPECT_EQ(ev->ape_raw.rotation_rad.max, 0.0);
  EXPECT_EQ(ev->rpe_frame.rotation_rad.max, 0.0);
  EXPECT_EQ(ev->rpe_distance.rotation_rad.max, 0.0);
  // The segment translation error is 1 % of the segment's chord, at most 1 % of its length.
  EXPECT_GT(ev->kitti.t_err_pct, 0.5);
  EXPECT_LE(ev->kitti.t_err_pct, 1.0 + 1e-9);
  EXPECT_GT(ev->kitti.num_segments, 3000u);
}

// ---- An independent reference for Table 1: long double, quaternions, no Eigen geometry. ----
using LD = long double;
using Quat = std::array<LD, 4>;  // (w, x, y, z)
using Vec = std::array<LD, 3>;

Quat quatFromMatrix(const Eigen::Matrix3d& R) {
  // Shepperd's method: pick the largest of 4w², 4x², 4y², 4z² to divide by.
  const LD m00 = R(0, 0), m11 = R(1, 1), m22 = R(2, 2);
  const LD tr = m00 + m11 + m22;
  Quat q{};
  if (tr >= m00 && tr >= m11 && tr >= m22) {
    const LD s = 2 * std::sqrt(1 + tr);
    q = {s / 4, (R(2, 1) - R(1, 2)) / s, (R(0, 2) - R(2, 0)) / s, (R(1, 0) - R(0, 1)) / s};
  } else if (m00 >= m11 && m00 >= m22) {
    const LD s = 2 * std::sqrt(1 + m00 - m11 - m22);
    q = {(R(2, 1) - R(1, 2)) / s, s / 4, (R(0, 1) + R(1, 0)) / s, (R(0, 2) + R(2, 0)) / s};
  } else if (m11 >= m22) {
    const LD s = 2 * std::sqrt(1 + m11 - m00 - m22);
    q = {(R(0, 2) - R(2, 0)) / s, (R(0, 1) + R(1, 0)) / s, s / 4, (R(1, 2) + R(2, 1)) / s};
  } else {
    const LD s = 2 * std::sqrt(1 + m22 - m00 - m11);
    q = {(R(1, 0) - R(0, 1)) / s, (R(0, 2) + R(2, 0)) / s, (R(1, 2) + R(2, 1)) / s, s / 4};
  }
  return q;
}
Quat mul(const Quat& a, const Quat& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
          a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
          a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
Quat conj(const Quat& q) {
  return {q[0], -q[1], -q[2], -q[3]};
}
Vec rotate(const Quat& q, const Vec& v) {
  const Quat r = mul(mul(q, {0, v[0], v[1], v[2]}), conj(q));
  return {r[1], r[2], r[3]};
}
Vec sub(const Vec& a, const Vec& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
LD norm(const Vec& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}
Vec pos(const Isometry3& T) {
  return {T.translation().x(), T.translation().y(), T.translation().z()};
}

struct Reference {
  LD trans = 0, plane = 0, rot = 0, drift = 0, drift_plane = 0, length = 0;
};
Reference referenceTable1(const std::vector<Isometry3>& gt, const std::vector<Isometry3>& est,
                          int ia, int ib) {
  Reference r;
  const Quat qg0 = quatFromMatrix(gt[0].linear());
  const Quat qe0 = quatFromMatrix(est[0].linear());
  const std::size_t n = gt.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec rel_g = rotate(conj(qg0), sub(pos(gt[k]), pos(gt[0])));
    const Vec rel_e = rotate(conj(qe0), sub(pos(est[k]), pos(est[0])));
    const Vec d = rotate(qg0, sub(rel_e, rel_g));
    const Quat qrel_g = mul(conj(qg0), quatFromMatrix(gt[k].linear()));
    const Quat qrel_e = mul(conj(qe0), quatFromMatrix(est[k].linear()));
    const Quat dq = mul(qrel_e, conj(qrel_g));
    const LD theta =
        2 * std::atan2(std::sqrt(dq[1] * dq[1] + dq[2] * dq[2] + dq[3] * dq[3]), std::fabs(dq[0]));
    r.trans += norm(d) / std::sqrt(3.0L);
    const LD dp = std::sqrt(d[static_cast<std::size_t>(ia)] * d[static_cast<std::size_t>(ia)] +
                            d[static_cast<std::size_t>(ib)] * d[static_cast<std::size_t>(ib)]);
    r.plane += dp / std::sqrt(2.0L);
    r.rot += theta / std::sqrt(3.0L);
    if (k + 1 == n) {
      r.drift = norm(d);
      r.drift_plane = dp;
    }
    if (k > 0) r.length += norm(sub(pos(gt[k]), pos(gt[k - 1])));
  }
  r.trans /= static_cast<LD>(n);
  r.plane /= static_cast<LD>(n);
  r.rot /= static_cast<LD>(n);
  return r;
}

double g_max_rel_diff = 0.0;  // largest relative difference seen, printed by the test

void expectRelNear(double value, LD reference, double rel, const char* what) {
  const double ref = static_cast<double>(reference);
  EXPECT_NEAR(value, ref, rel * std::abs(ref)) << what;
  if (ref != 0.0) g_max_rel_diff = std::max(g_max_rel_diff, std::abs(value - ref) / std::abs(ref));
}

// The real 00 ground truth against a copy that drifts like VO: every frame-to-frame motion is
// perturbed by a small random rotation (σ = 2e-4 rad per axis) and translation (σ = 5 mm), and
// the perturbations accumulate. The copy goes through the KITTI writer and reader first.
TEST(RealKitti00, Table1MatchesIndependentLongDoubleReference) {
  auto gt = files::readKittiPoses(kGt00);
  ASSERT_TRUE(gt);
  std::mt19937 rng(2024);
  std::normal_distribution<double> n01(0.0, 1.0);
  files::Trajectory est;
  est.T_w_c.push_back(gt->T_w_c.front());
  for (std::size_t k = 1; k < gt->size(); ++k) {
    const Isometry3 step = gt->T_w_c[k - 1].inverse(Eigen::Isometry) * gt->T_w_c[k];
    const Isometry3 noise = pose(expSO3(2e-4 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng))),
                                 5e-3 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
    est.T_w_c.push_back(est.T_w_c.back() * step * noise);
  }
  const std::string path = std::string(SUNVO_BINARY_DIR) + "/metrics_test_00_drift.txt";
  ASSERT_TRUE(files::writeKittiPoses(path, est).isOk());
  auto est_read = files::readKittiPoses(path);
  ASSERT_TRUE(est_read);

  for (HorizontalPlane plane : {HorizontalPlane::kCameraXZ, HorizontalPlane::kEastNorth}) {
    auto m = computeTable1(gt->T_w_c, est_read->T_w_c, plane);
    ASSERT_TRUE(m);
    const auto [ia, ib] = planeAxes(plane);
    const Reference r = referenceTable1(gt->T_w_c, est_read->T_w_c, ia, ib);
    // The drift is real (metres, milliradians), not a degenerate zero.
    EXPECT_GT(m->final_drift_m, 1.0);
    EXPECT_GT(m->rot_armse_rad, 1e-3);
    expectRelNear(m->trans_armse_m, r.trans, 1e-6, "trans_armse_m");
    expectRelNear(m->trans_armse_plane_m, r.plane, 1e-6, "trans_armse_plane_m");
    expectRelNear(m->rot_armse_rad, r.rot, 1e-6, "rot_armse_rad");
    expectRelNear(m->final_drift_m, r.drift, 1e-6, "final_drift_m");
    expectRelNear(m->final_drift_plane_m, r.drift_plane, 1e-6, "final_drift_plane_m");
    expectRelNear(m->gt_path_length_m, r.length, 1e-9, "gt_path_length_m");
    expectRelNear(m->final_drift_pct, 100 * r.drift / r.length, 1e-6, "final_drift_pct");
    expectRelNear(m->final_drift_plane_pct, 100 * r.drift_plane / r.length, 1e-6,
                  "final_drift_plane_pct");
    std::printf(
        "%s: trans ARMSE %.6f m, plane %.6f m, rot ARMSE %.6e rad, drift %.6f m (%.6f %%)\n",
        planeName(plane), m->trans_armse_m, m->trans_armse_plane_m, m->rot_armse_rad,
        m->final_drift_m, m->final_drift_pct);
  }
  std::printf("largest relative difference to the long-double reference: %.3e\n", g_max_rel_diff);
}

// evo's RPE per 100 m on a synthetic estimate of the real KITTI 06 ground truth (a yaw drift of
// 2e-5 rad per frame, 1 % scale, a 5 cm sideways wobble). The expected numbers were computed by
// evo's own pair selection and error (filters.filter_pairs_by_path, metrics.RPE.rpe_base at evo
// commits 02751b2 / 01c1dd5) run with numpy on the same input (hil/tools/eval/README.md, "evo").
TEST(RpeEvo, MatchesEvoOnAKittiCase) {
  auto gt = files::readKittiPoses(std::string(SUNVO_DATA_DIR) + "/kitti_odometry/06_gt_poses.txt");
  ASSERT_TRUE(gt);
  std::vector<Isometry3> est;
  for (std::size_t k = 0; k < gt->size(); ++k) {
    const Eigen::Matrix3d Ry = rotY(2e-5 * static_cast<double>(k));
    est.push_back(pose(Ry * gt->T_w_c[k].linear(),
                       1.01 * (Ry * gt->T_w_c[k].translation()) +
                           Eigen::Vector3d(0.05 * std::sin(0.1 * static_cast<double>(k)), 0, 0)));
  }
  auto on_est = computeRpeEvo(gt->T_w_c, est, 100.0, RpePathOf::kEstimate);
  ASSERT_TRUE(on_est) << on_est.status().toString();
  EXPECT_EQ(on_est->translation_m.count, 11u);
  EXPECT_NEAR(on_est->translation_m.rmse, 0.987240380371232, 1e-5);
  EXPECT_NEAR(on_est->translation_m.mean, 0.972693396952079, 1e-5);
  EXPECT_NEAR(on_est->translation_m.median, 0.9965973075055002, 1e-5);
  EXPECT_NEAR(on_est->translation_m.max, 1.2321359342320595, 1e-5);
  EXPECT_NEAR(on_est->rotation_rad.rmse, 0.0018026243495122914, 1e-8);
  EXPECT_NEAR(on_est->rotation_rad.max, 0.0024800000000001084, 1e-8);
  auto on_ref = computeRpeEvo(gt->T_w_c, est, 100.0, RpePathOf::kReference);
  ASSERT_TRUE(on_ref);
  EXPECT_EQ(on_ref->translation_m.count, 11u);
  EXPECT_NEAR(on_ref->translation_m.rmse, 1.0007315253033464, 1e-5);
  EXPECT_NEAR(on_ref->translation_m.median, 1.0029159733667843, 1e-5);
  EXPECT_NEAR(on_ref->rotation_rad.rmse, 0.0018293168123646598, 1e-8);
  // evo's consecutive pairs differ from the every-start pairs of computeRpePerDistance.
  auto all_starts = computeRpePerDistance(gt->T_w_c, est, 100.0);
  ASSERT_TRUE(all_starts);
  EXPECT_GT(all_starts->translation_m.count, 900u);
  EXPECT_FALSE(computeRpeEvo(gt->T_w_c, est, 0.0));
}

}  // namespace
}  // namespace sunvo::metrics
