// The window's own Schur-complement Levenberg-Marquardt against ceres::Solve on the same window:
// the same minimum (noise, outliers, robust losses, a motion prior, a caller block), and no heap
// allocation per solve after the first.
#include "sunvo/backend/schur_lm_solver.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <random>

#include "../support/synthetic_stereo.hpp"
#include "sunvo/backend/bundle_window.hpp"

#ifdef SUNVO_HAVE_ALLOC_COUNTER
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::backend {
namespace {

using sunvo::testing::kittiCamera;

// A direction residual over q_k_b and a caller block delta_b (rotation vector of a correction of
// the base, as the sun term's): s_hat_k = C_k_b Exp(delta_b)^T s_b, r = w (s_hat_k - s_k).
struct CorrectedDirection {
  const Eigen::Vector3d* s_b;  // rewritten by the hook before each solve
  const Eigen::Vector3d* s_k;
  double weight;
  template <typename T>
  bool operator()(const T* q_k_b, const T* delta_b, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> C_k_b(q_k_b);
    T R[9];
    const T minus[3] = {-delta_b[0], -delta_b[1], -delta_b[2]};
    ceres::AngleAxisToRotationMatrix(minus, ceres::ColumnMajorAdapter3x3(R));
    const Eigen::Map<const Eigen::Matrix<T, 3, 3>> C(R);
    const Eigen::Matrix<T, 3, 1> s_hat = C_k_b * (C * s_b->cast<T>());
    for (int i = 0; i < 3; ++i) r[i] = T(weight) * (s_hat[i] - T((*s_k)[i]));
    return true;
  }
};

// A prior delta_b ~ N(0, sigma^2 I): r = delta_b / sigma.
struct DeltaPrior {
  double sigma;
  template <typename T>
  bool operator()(const T* delta_b, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = delta_b[i] / T(sigma);
    return true;
  }
};

std::vector<WindowObservation> toWindow(const FrameFeatures& f) {
  std::vector<WindowObservation> out;
  for (const auto& o : f.observations) {
    out.push_back({o.landmark_id, {o.u_left, o.v_left, o.disparity()}});
  }
  return out;
}

struct Scenario {
  int window_size = 2;
  double noise_px = 1.0;
  double outlier_fraction = 0.0;  // observations moved by 5..30 px
  bool with_prior = false;
  bool with_direction = false;
  RobustLoss loss = RobustLoss::kCauchy;
};

struct Result {
  std::vector<Isometry3> T_w_k;
  std::array<double, 3> delta{0.0, 0.0, 0.0};
  std::vector<WindowSolveSummary> summaries;
};

// Runs `frames` frames of a synthetic drive through a window with the given solver; the first
// frames warm the window up, every solve is recorded.
Result run(const Scenario& sc, WindowSolver solver, int frames = 6) {
  const auto cam = kittiCamera();
  testing::SceneOptions so;
  so.pixel_noise_px = sc.noise_px;
  so.seed = 21;
  so.max_per_frame = 250;
  const Isometry3 T_k_km1 = testing::forwardMotion(1.0, 1.5, 0.3);
  const auto T_w_k = testing::trajectory(frames, T_k_km1);
  const auto pts = testing::makeLandmarks(so, frames * 1.0);
  WindowOptions wo;
  wo.window_size = sc.window_size;
  wo.solver = solver;
  wo.loss = sc.loss;
  wo.max_num_iterations = 100;
  wo.max_solver_time_in_seconds = 30.0;  // bounded by iterations, also under qemu-aarch64
  // The fixed-std rotation-rate prior: in the problem from the first solve on (the adapted one
  // waits for RateSpread::kMinSamples frames of the vehicle's own rates).
  wo.rate_prior_adapt_frames = 0;
  if (sc.with_prior) {
    wo.motion_prior_sigma_rot_deg = 0.2;
    wo.motion_prior_sigma_trans_m = 0.05;
    wo.motion_prior_sigma_accel_m_s2 = 0.0;  // the per-frame form instead
  }
  BundleWindow w;
  Result out;
  EXPECT_TRUE(w.init(wo, cam).isOk());
  w.reset(Isometry3::Identity());
  const Eigen::Vector3d s_w = Eigen::Vector3d(0.4, -0.7, 0.6).normalized();
  Eigen::Vector3d s_b = s_w;
  Eigen::Vector3d s_k = s_w;
  auto direction = std::make_unique<ceres::AutoDiffCostFunction<CorrectedDirection, 3, 4, 3>>(
      new CorrectedDirection{&s_b, &s_k, 20.0});
  ceres::AutoDiffCostFunction<DeltaPrior, 3, 3> prior(new DeltaPrior{0.02});
  double delta[3] = {0.0, 0.0, 0.0};
  if (sc.with_direction) {
    w.setPoseResidualHook([&](BundleWindow& win) -> Status {
      // The direction "measured" in the newest frame: the true one, 0.5 deg off about x.
      const int s = win.size() - 1;
      const Isometry3 T_k_w = T_w_k[win.sequence(s)].inverse();
      s_b = win.T_w_b().linear().transpose() * s_w;
      s_k = expSO3(Eigen::Vector3d(0.5 * M_PI / 180.0, 0.0, 0.0)) * T_k_w.linear() * s_w;
      delta[0] = delta[1] = delta[2] = 0.0;
      double* extra[] = {delta};
      SUNVO_RETURN_IF_ERROR(win.addResidual(s, direction.get(), nullptr, extra));
      return win.addResidual(-1, &prior, nullptr, extra);
    });
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Isometry3 guess = T_k_km1;
  guess.linear() = expSO3(Eigen::Vector3d(0.01, 0.005, -0.01)) * guess.linear();
  guess.translation() += Eigen::Vector3d(0.05, -0.03, 0.08);
  for (int k = 0; k < frames; ++k) {
    const auto f = testing::observe(cam, pts, T_w_k[static_cast<std::size_t>(k)].inverse(),
                                    static_cast<std::uint64_t>(k), so);
    auto obs = toWindow(f);
    for (auto& o : obs) {
      if (unit(rng) < sc.outlier_fraction)
        o.y.u += (unit(rng) < 0.5 ? -1 : 1) * (5 + 25 * unit(rng));
    }
    EXPECT_TRUE(w.addFrame(f.sequence, f.time_ns, obs, guess, &T_k_km1).isOk());
    if (k == 0) continue;
    auto s = w.solve();
    EXPECT_TRUE(s) << s.status().toString();
    if (!s) break;
    // The rotation-rate prior (on by default) is part of both solvers' problem.
    EXPECT_EQ(s->num_rate_prior_residuals, w.size() - 1);
    out.summaries.push_back(*s);
    out.T_w_k.push_back(w.T_w_newest());
    std::copy(delta, delta + 3, out.delta.begin());
  }
  return out;
}

double rotDiffDeg(const Isometry3& a, const Isometry3& b) {
  return testing::rotationErrorDeg(a, b);
}

void expectSameMinimum(const Scenario& sc, const char* what) {
  const Result ours = run(sc, WindowSolver::kSchurLm);
  const Result ref = run(sc, WindowSolver::kCeres);
  ASSERT_EQ(ours.T_w_k.size(), ref.T_w_k.size()) << what;
  ASSERT_EQ(ours.T_w_k.size(), 5u) << what;
  double worst_rot = 0.0, worst_pos = 0.0, worst_cost = 0.0;
  for (std::size_t i = 0; i < ours.T_w_k.size(); ++i) {
    worst_rot = std::max(worst_rot, rotDiffDeg(ours.T_w_k[i], ref.T_w_k[i]));
    worst_pos =
        std::max(worst_pos, (ours.T_w_k[i].translation() - ref.T_w_k[i].translation()).norm());
    const double c0 = ref.summaries[i].final_cost;
    worst_cost = std::max(worst_cost, std::abs(ours.summaries[i].final_cost - c0) / c0);
    // The same Levenberg-Marquardt (Ceres' Jacobi column scaling leaves Marquardt's diag(J^T J)
    // damping unchanged), so the same stop; Ceres does not count the step that met the tolerance.
    EXPECT_EQ(ours.summaries[i].converged, ref.summaries[i].converged) << what << " solve " << i;
    EXPECT_NEAR(ours.summaries[i].iterations, ref.summaries[i].iterations, 1) << what;
    EXPECT_EQ(ours.summaries[i].num_stereo_residuals, ref.summaries[i].num_stereo_residuals);
    EXPECT_EQ(ours.summaries[i].num_extra_residuals, ref.summaries[i].num_extra_residuals);
    EXPECT_NEAR(ours.summaries[i].initial_cost, ref.summaries[i].initial_cost,
                1e-9 * ref.summaries[i].initial_cost)
        << what;  // the same problem
  }
  std::printf("%s: worst pose difference %.2e deg, %.2e m; final cost %.2e relative\n", what,
              worst_rot, worst_pos, worst_cost);
  // Measured: the poses agree to 5e-15 deg and 5e-15 m, the costs to 4e-15 (the iterates are
  // the same up to rounding). The bounds leave room for another compiler's rounding; they are
  // still far below the noise (1 px gives ~0.03 deg and ~1 cm per frame).
  EXPECT_LT(worst_rot, 1e-4) << what;
  EXPECT_LT(worst_pos, 1e-4) << what;
  EXPECT_LT(worst_cost, 1e-5) << what;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(ours.delta[static_cast<std::size_t>(i)], ref.delta[static_cast<std::size_t>(i)],
                1e-6)
        << what;
  }
}

TEST(SchurLmSolver, SameMinimumAsCeresWithNoiseAndCauchy) {
  expectSameMinimum({}, "2 frames, 1 px, Cauchy");
}

TEST(SchurLmSolver, SameMinimumAsCeresWithOutliersAndHuber) {
  Scenario sc;
  sc.outlier_fraction = 0.1;
  sc.loss = RobustLoss::kHuber;
  expectSameMinimum(sc, "2 frames, 10 % outliers, Huber");
  sc.loss = RobustLoss::kCauchy;
  expectSameMinimum(sc, "2 frames, 10 % outliers, Cauchy");
}

TEST(SchurLmSolver, SameMinimumAsCeresWithThreeFramesAndMotionPrior) {
  Scenario sc;
  sc.window_size = 3;
  sc.with_prior = true;
  sc.loss = RobustLoss::kNone;
  expectSameMinimum(sc, "3 frames, motion prior, no loss");
}

TEST(SchurLmSolver, SameMinimumAsCeresWithACallerBlock) {
  Scenario sc;
  sc.with_direction = true;
  expectSameMinimum(sc, "2 frames, direction over (q, delta) + delta prior");
  // The caller block moved: the direction disagrees with the stereo motion by 0.5 deg.
  const Result ours = run(sc, WindowSolver::kSchurLm);
  const double moved = Eigen::Vector3d(ours.delta[0], ours.delta[1], ours.delta[2]).norm();
  EXPECT_GT(moved, 1e-4);
}

TEST(SchurLmSolver, RejectsMismatchedBlocksAndCapacity) {
  SchurLmSolver solver;
  double q0[4] = {0, 0, 0, 1}, q1[4] = {0, 0, 0, 1}, t0[3] = {}, t1[3] = {};
  double* q[] = {q0, q1};
  double* t[] = {t0, t1};
  EXPECT_EQ(solver.begin(2, q, t).code(), StatusCode::kFailedPrecondition);  // before init
  ASSERT_TRUE(solver.init(4, 1, 2).isOk());
  ASSERT_TRUE(solver.begin(2, q, t).isOk());
  EXPECT_FALSE(solver.addStereo(1, nullptr, nullptr).isOk());  // no landmark yet
  double p[3] = {0, 0, 10};
  ASSERT_TRUE(solver.addLandmark(p).isOk());
  EXPECT_FALSE(solver.addLandmark(p).isOk());  // capacity 1
  ceres::AutoDiffCostFunction<DeltaPrior, 3, 3> prior(new DeltaPrior{1.0});
  using Kind = SchurLmSolver::BlockRef::Kind;
  const SchurLmSolver::BlockRef rotation{Kind::kRotation, 1, nullptr};
  EXPECT_FALSE(solver.addGeneric(&prior, nullptr, {&rotation, 1}).isOk());  // 3 != 4
  double delta[3] = {};
  const SchurLmSolver::BlockRef extra{Kind::kExtra, 0, delta};
  EXPECT_TRUE(solver.addGeneric(&prior, nullptr, {&extra, 1}).isOk());
  EXPECT_TRUE(solver.addGeneric(&prior, nullptr, {&extra, 1}).isOk());
  EXPECT_FALSE(solver.addGeneric(&prior, nullptr, {&extra, 1}).isOk());  // capacity 2
  EXPECT_EQ(solver.begin(1, q, t).code(), StatusCode::kInvalidArgument);
}

#ifdef SUNVO_HAVE_ALLOC_COUNTER
// After the first solve, a solve (gathering, the hook with a caller block, the minimisation)
// makes no heap allocation; the Ceres reference makes thousands.
TEST(SchurLmSolver, SolvesWithoutHeapAllocation) {
  ASSERT_TRUE(runtime::allocCounterActive());
  const auto cam = kittiCamera();
  testing::SceneOptions so;
  so.pixel_noise_px = 0.5;
  so.max_per_frame = 300;
  const Isometry3 T_1_0 = testing::forwardMotion(1.0, 1.0, 0.2);
  const auto pts = testing::makeLandmarks(so, 2.0);
  const auto f0 = toWindow(testing::observe(cam, pts, Isometry3::Identity(), 0, so));
  const auto f1 = toWindow(testing::observe(cam, pts, T_1_0, 1, so));
  ceres::AutoDiffCostFunction<DeltaPrior, 3, 3> prior(new DeltaPrior{0.02});
  double delta[3] = {};
  std::uint64_t counts[2] = {0, 0};
  for (WindowSolver solver : {WindowSolver::kSchurLm, WindowSolver::kCeres}) {
    WindowOptions wo;
    wo.solver = solver;
    wo.max_solver_time_in_seconds = 1.0;
    BundleWindow w;
    ASSERT_TRUE(w.init(wo, cam).isOk());
    w.setPoseResidualHook([&](BundleWindow& win) -> Status {
      double* extra[] = {delta};
      return win.addResidual(-1, &prior, nullptr, extra);
    });
    std::uint64_t allocations = 0;
    for (int k = 0; k < 4; ++k) {
      w.reset(Isometry3::Identity());
      const runtime::AllocationScope scope;
      ASSERT_TRUE(w.addFrame(0, 0, f0, Isometry3::Identity()).isOk());
      ASSERT_TRUE(w.addFrame(1, 1, f1, T_1_0).isOk());
      const auto s = w.solve();
      ASSERT_TRUE(s);
      ASSERT_GT(s->num_landmarks, 100);
      if (k > 0) allocations += scope.count();
    }
    counts[solver == WindowSolver::kCeres ? 1 : 0] = allocations / 3;
  }
  std::printf("heap allocations per solve: schur_lm %llu, ceres %llu\n",
              static_cast<unsigned long long>(counts[0]),
              static_cast<unsigned long long>(counts[1]));
  EXPECT_EQ(counts[0], 0u);
  EXPECT_GT(counts[1], 100u);  // the reference really is measured by the same counter
}
#endif

}  // namespace
}  // namespace sunvo::backend
