#include "sunvo/track_stats/window_bias.hpp"

#include <gtest/gtest.h>

#include "../support/exact_tracks.hpp"

namespace sunvo::track_stats {
namespace {

StereoCamera kittiCamera() {
  return {707.0912, 707.0912, 601.8873, 183.1104, 0.5372, 1226, 370};
}

std::vector<Isometry3> straightDrive(int frames) {
  std::vector<Isometry3> T_0_k;
  Isometry3 T = Isometry3::Identity();
  for (int k = 0; k < frames; ++k) {
    T_0_k.push_back(T);
    Isometry3 step = Isometry3::Identity();
    step.translation() = Eigen::Vector3d(0, 0, 1.0);
    T = T * step;
  }
  return T_0_k;
}

std::vector<FrameFeatures> cleanTracks(const std::vector<Isometry3>& T_0_k) {
  return testing::exactTracks(T_0_k, kittiCamera());
}

// Exact tracks: the window at the true motion makes no error, and the hypothetical error fields
// map as a two-frame window must map them on tracks spread over the image: a constant vL shift
// into pitch only (-dv / fv), a shift c / z into none (the vertical translation takes it).
TEST(WindowBias, ExactTracksGiveNoErrorAndTheInjectedFieldsMapAsExpected) {
  const auto T_0_k = straightDrive(40);
  const auto frames = cleanTracks(T_0_k);
  WindowBiasOptions o;
  o.inject_v_px = -0.127;
  auto wb = computeWindowBias(kittiCamera(), frames, T_0_k, o);
  ASSERT_TRUE(wb) << wb.status().toString();
  ASSERT_EQ(wb->frames.size(), 40u);
  int used = 0;
  const double pitch_mdeg = 0.127 / kittiCamera().fv * 180.0 / M_PI * 1e3;  // 10.3 mdeg
  for (std::size_t k = 1; k < 20; ++k) {
    const FrameWindowBias& f = wb->frames[k];
    if (f.landmarks < 20) continue;
    ++used;
    EXPECT_LT(f.total.norm(), 1e-6) << k;
    // fv dpitch (1 + (v - cv)^2 / fv^2) and the vertical translation share the shift: ~ -fv dv.
    EXPECT_NEAR(f.inject_v.x(), -pitch_mdeg, 0.1 * pitch_mdeg) << k;
    EXPECT_LT(std::abs(f.inject_v.z()), 0.05 * pitch_mdeg) << k;
    EXPECT_LT(f.inject_v_z.norm(), 1e-3 * pitch_mdeg) << k;
    EXPECT_GT(f.sigma_mdeg.z(), 0.0) << k;
  }
  EXPECT_GT(used, 15);
  EXPECT_NEAR(wb->fit_k1, 0.0, 1e-9);
  EXPECT_NEAR(wb->rms_before_px, 0.0, 1e-9);
  for (const ColumnBin& c : wb->columns) {
    if (c.n > 0) {
      EXPECT_NEAR(c.mean_du, 0.0, 1e-6);
      EXPECT_NEAR(c.mean_dv, 0.0, 1e-6);
    }
  }
}

// A rolled observation in frame k (vL += theta (uL - cu), uL -= theta (vL - cv)) is a roll of
// the image: the window's one-step error must be that roll, all of it from the measurement rows.
TEST(WindowBias, AnImageRollIsReportedAsRoll) {
  const auto T_0_k = straightDrive(30);
  auto frames = cleanTracks(T_0_k);
  const StereoCamera cam = kittiCamera();
  const double theta = 1e-3;  // rad
  for (std::size_t k = 1; k < frames.size(); ++k) {
    for (StereoObservation& o : frames[k].observations) {
      const double du = -theta * (o.v_left - cam.cv), dv = theta * (o.u_left - cam.cu);
      o.u_left += du;
      o.v_left += dv;
      o.u_right += du;
      o.v_right += dv;
    }
  }
  auto wb = computeWindowBias(cam, frames, T_0_k, WindowBiasOptions{});
  ASSERT_TRUE(wb) << wb.status().toString();
  const double roll_mdeg = theta * 180.0 / M_PI * 1e3;
  int used = 0;
  for (std::size_t k = 2; k < 25; ++k) {
    const FrameWindowBias& f = wb->frames[k];
    if (f.landmarks < 20) continue;
    ++used;
    // Frame k-1 is rolled as well (k >= 2): the pair's relative roll is 0 ...
    EXPECT_LT(std::abs(f.total.z()), 0.02 * roll_mdeg) << k;
  }
  EXPECT_GT(used, 10);
  // ... and frame 1 against the unrolled frame 0 carries the whole roll. Image points turned by
  // +theta about the principal point are a camera turned by -theta about its optical axis:
  // C_km1_k,est = C_km1_k,true Rz(-theta), reported as log(C_true^T C_est) = -theta.
  EXPECT_NEAR(wb->frames[1].total.z(), -roll_mdeg, 0.05 * roll_mdeg);
  EXPECT_NEAR((wb->frames[1].from_u + wb->frames[1].from_v + wb->frames[1].from_d).z(),
              wb->frames[1].total.z(), 1e-9);
}

// Tracks seen through a radial distortion k1 = 0.02 in both images: the fit finds it.
TEST(WindowBias, FitsARadialDistortionOfTheTracks) {
  const auto T_0_k = straightDrive(40);
  auto frames = cleanTracks(T_0_k);
  const StereoCamera cam = kittiCamera();
  const double k1 = 0.02;
  auto distort = [&](double& u, double v) {
    const double x = (u - cam.cu) / cam.fu, y = (v - cam.cv) / cam.fv;
    u += cam.fu * k1 * (x * x + y * y) * x;
  };
  for (FrameFeatures& f : frames) {
    for (StereoObservation& o : f.observations) {
      const double x = (o.u_left - cam.cu) / cam.fu, y = (o.v_left - cam.cv) / cam.fv;
      const double v_shift = cam.fv * k1 * (x * x + y * y) * y;
      distort(o.u_left, o.v_left);
      distort(o.u_right, o.v_right);
      o.v_left += v_shift;
      o.v_right += v_shift;
    }
  }
  auto wb = computeWindowBias(cam, frames, T_0_k, WindowBiasOptions{});
  ASSERT_TRUE(wb) << wb.status().toString();
  std::printf("fitted k1 %.5f (true %.5f), rms %.4f -> %.4f px\n", wb->fit_k1, k1,
              wb->rms_before_px, wb->rms_after_px);
  EXPECT_NEAR(wb->fit_k1, k1, 0.2 * k1);
  EXPECT_LT(wb->rms_after_px, 0.5 * wb->rms_before_px);
  EXPECT_EQ(wb->k1_used, wb->fit_k1);
}

TEST(WindowBias, OptionsAndInputsAreChecked) {
  WindowBiasOptions o;
  o.sigma_v_px = 0.0;
  EXPECT_FALSE(computeWindowBias(kittiCamera(), {}, {}, o));
  const auto T_0_k = straightDrive(5);
  auto frames = cleanTracks(T_0_k);
  EXPECT_FALSE(computeWindowBias(kittiCamera(), frames, {T_0_k[0]}, WindowBiasOptions{}));
}

}  // namespace
}  // namespace sunvo::track_stats
