#include "sunvo/motion/stereo_ransac.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "../support/synthetic_stereo.hpp"

// GCC 12 flags free() on memory from a replaced operator new although the pair is consistent.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
// Counts heap allocations of this test binary (to check that estimate() does not allocate).
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace sunvo::motion {
namespace {

using sunvo::testing::forwardMotion;
using sunvo::testing::kittiCamera;

// Matches between frames 0 and 1 of a synthetic scene; `outlier` marks the corrupted ones.
std::vector<StereoMatch> makeMatches(const Isometry3& T_1_0, const testing::SceneOptions& o,
                                     std::vector<bool>* outlier = nullptr) {
  const auto cam = kittiCamera();
  const auto pts = testing::makeLandmarks(o, 5.0);
  testing::SceneOptions clean = o;
  clean.outlier_fraction = 0.0;
  // Outliers only in frame 1, so `outlier_fraction` is the fraction of corrupted matches.
  const FrameFeatures f0 = testing::observe(cam, pts, Isometry3::Identity(), 0, clean);
  const FrameFeatures f1 = testing::observe(cam, pts, T_1_0, 1, o);
  const FrameFeatures c1 = testing::observe(cam, pts, T_1_0, 1, clean);
  std::vector<StereoMatch> m;
  for (const auto& a : f0.observations) {
    for (std::size_t j = 0; j < f1.observations.size(); ++j) {
      const auto& b = f1.observations[j];
      if (a.landmark_id != b.landmark_id) continue;
      m.push_back({a.u_left, a.v_left, a.u_right, b.u_left, b.v_left, b.u_right});
      if (outlier != nullptr) {
        outlier->push_back(std::abs(b.u_left - c1.observations[j].u_left) > 1e-9);
      }
    }
  }
  return m;
}

TEST(StereoRansac, RecoversMotionUnderNoiseAndOutliers) {
  testing::SceneOptions o;
  o.pixel_noise_px = 1.0;
  o.outlier_fraction = 0.3;
  int trials = 0;
  for (double yaw : {-3.0, 0.5, 2.0}) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      o.seed = seed;
      const Isometry3 T_1_0 = forwardMotion(1.2, yaw, 0.3);
      std::vector<bool> outlier;
      const auto m = makeMatches(T_1_0, o, &outlier);
      ASSERT_GT(m.size(), 100u);
      StereoRansac ransac;
      // With 1 px noise on all six coordinates the (u, v, u_right) error of a clean match has a
      // norm of about sqrt(3 * 2) = 2.4 px (noise of frame k-1 enters through triangulation).
      RansacOptions ro;
      ro.inlier_threshold_px = 6.0;
      ASSERT_TRUE(ransac.init(ro, kittiCamera()).isOk());
      auto est = ransac.estimate(m, 7);
      ASSERT_TRUE(est) << est.status().toString();
      const double rot = testing::rotationErrorDeg(est->T_k_km1, T_1_0);
      const double dt = (est->T_k_km1.translation() - T_1_0.translation()).norm();
      std::printf("yaw %.1f seed %d: rot err %.4f deg, trans err %.4f m, inliers %d/%zu\n", yaw,
                  static_cast<int>(seed), rot, dt, est->num_inliers, m.size());
      // Two-frame RANSAC keeps the triangulated points fixed, so it is less precise than the
      // window (which estimates them): measured worst 0.081 deg and 6.3 cm (5.3 %) over these 9
      // cases. The window test holds the tighter bounds.
      EXPECT_LT(rot, 0.12) << "yaw " << yaw << " seed " << seed;
      EXPECT_LT(dt, 0.08 * T_1_0.translation().norm()) << "yaw " << yaw << " seed " << seed;
      // Every corrupted match is rejected; nearly every clean one is kept.
      int clean = 0, clean_kept = 0, bad_kept = 0;
      for (std::size_t i = 0; i < m.size(); ++i) {
        if (outlier[i]) {
          bad_kept += est->inlier_mask[i];
        } else {
          ++clean;
          clean_kept += est->inlier_mask[i];
        }
      }
      EXPECT_EQ(bad_kept, 0);
      EXPECT_GT(clean_kept, 0.85 * clean);
      ++trials;
    }
  }
  EXPECT_EQ(trials, 9);
}

TEST(StereoRansac, DeterministicForASeed) {
  testing::SceneOptions o;
  o.outlier_fraction = 0.3;
  const auto m = makeMatches(forwardMotion(1.0, 1.0), o);
  StereoRansac a, b;
  ASSERT_TRUE(a.init(RansacOptions{}, kittiCamera()).isOk());
  ASSERT_TRUE(b.init(RansacOptions{}, kittiCamera()).isOk());
  auto ea = a.estimate(m, 42);
  ASSERT_TRUE(ea);
  const Isometry3 Ta = ea->T_k_km1;
  const std::vector<std::uint8_t> mask(ea->inlier_mask.begin(), ea->inlier_mask.end());
  auto eb = b.estimate(m, 42);
  ASSERT_TRUE(eb);
  EXPECT_TRUE(Ta.matrix() == eb->T_k_km1.matrix());
  EXPECT_TRUE(std::equal(mask.begin(), mask.end(), eb->inlier_mask.begin()));
  EXPECT_EQ(ea->hypotheses, eb->hypotheses);
}

TEST(StereoRansac, FailsCleanlyOnDegenerateInput) {
  StereoRansac r;
  ASSERT_TRUE(r.init(RansacOptions{}, kittiCamera()).isOk());
  // No matches.
  auto e0 = r.estimate({}, 1);
  ASSERT_FALSE(e0);
  EXPECT_EQ(e0.status().code(), StatusCode::kFailedPrecondition);
  // Zero disparity everywhere (points at infinity): nothing can be triangulated.
  std::vector<StereoMatch> inf(50);
  for (std::size_t i = 0; i < inf.size(); ++i) {
    const double u = 100.0 + 10.0 * static_cast<double>(i);
    inf[i] = {u, 100.0, u, u + 1.0, 100.0, u + 1.0};
  }
  auto e1 = r.estimate(inf, 1);
  ASSERT_FALSE(e1);
  EXPECT_EQ(e1.status().code(), StatusCode::kFailedPrecondition);
  // Pure garbage: no consistent motion with enough inliers.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1200.0), v(0.0, 370.0), d(1.0, 80.0);
  std::vector<StereoMatch> junk(60);
  for (auto& m : junk) {
    const double u0 = u(rng), u1 = u(rng);
    m = {u0, v(rng), u0 - d(rng), u1, v(rng), u1 - d(rng)};
  }
  auto e2 = r.estimate(junk, 1);
  EXPECT_FALSE(e2);
  // Too many matches for the buffers.
  RansacOptions small;
  small.max_observations = 10;
  StereoRansac rs;
  ASSERT_TRUE(rs.init(small, kittiCamera()).isOk());
  auto e3 = rs.estimate(junk, 1);
  ASSERT_FALSE(e3);
  EXPECT_EQ(e3.status().code(), StatusCode::kInvalidArgument);
}

TEST(StereoRansac, ZeroMotionIsIdentity) {
  testing::SceneOptions o;
  o.pixel_noise_px = 0.0;
  const auto m = makeMatches(Isometry3::Identity(), o);
  StereoRansac r;
  ASSERT_TRUE(r.init(RansacOptions{}, kittiCamera()).isOk());
  auto e = r.estimate(m, 1);
  ASSERT_TRUE(e);
  EXPECT_LT(testing::rotationErrorDeg(e->T_k_km1, Isometry3::Identity()), 1e-6);
  EXPECT_LT(e->T_k_km1.translation().norm(), 1e-6);
  EXPECT_EQ(e->num_inliers, static_cast<int>(m.size()));
}

TEST(StereoRansac, NoHeapAllocationPerCallAfterInit) {
  testing::SceneOptions o;
  o.outlier_fraction = 0.3;
  const auto m = makeMatches(forwardMotion(1.0, 1.0), o);
  RansacOptions ro;
  ro.inlier_threshold_px = 6.0;
  StereoRansac r;
  ASSERT_TRUE(r.init(ro, kittiCamera()).isOk());
  const long before = g_allocations.load();
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    auto e = r.estimate(m, seed);
    ASSERT_TRUE(e);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
}

TEST(RansacOptions, ValidateNamesTheBadKey) {
  RansacOptions o;
  EXPECT_TRUE(o.validate().isOk());
  o.inlier_threshold_px = 0.0;
  EXPECT_NE(o.validate().message().find("ransac.inlier_threshold_px"), std::string::npos);
  o = RansacOptions{};
  o.min_inliers = 2;
  EXPECT_NE(o.validate().message().find("ransac.min_inliers"), std::string::npos);
  o = RansacOptions{};
  o.max_iterations = 0;
  EXPECT_NE(o.validate().message().find("ransac.max_iterations"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::motion
