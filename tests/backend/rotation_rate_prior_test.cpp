// The window's zero-mean rotation-rate prior (WindowOptions::rotation_rate_prior, issue 15): on
// tracks that all lie on one side of the image, a small left-image error field whose slope across
// the image differs between the two sides is read by the two-frame window as roll about the
// optical axis and accumulates (docs/backend.md, the roll of one-sided frames); the prior takes
// a share of it out. On clean tracks, on balanced tracks and in turns about a tilted yaw axis it
// changes the result by little, and the yaw axis it acts orthogonal to is recovered from the
// window's own motion.

#include <gtest/gtest.h>

#include <random>

#include "../support/synthetic_stereo.hpp"
#include "sunvo/backend/bundle_window.hpp"

namespace sunvo::backend {
namespace {

using sunvo::testing::kittiCamera;

struct DriveOptions {
  bool one_sided = true;  // landmarks only right of the principal point
  double field_px = 0.0;  // vL error of frame k: field_px * ((u - cu) / 500)^2
  double noise_px = 0.3;  // Gaussian noise of uL, vL, uR
  Eigen::Vector3d axis_c = Eigen::Vector3d::UnitY();  // turn axis (camera frame)
  double turn_deg = 0.0;         // per frame about axis_c (alternating sign every 20 frames)
  double roll_wobble_deg = 0.0;  // true per-frame roll, alternating sign every frame
  int frames = 60;
  bool prior = true;
  bool restore_last = false;       // restoreInitialGuess() after the last solve
  double random_wobble_deg = 0.0;  // true per-frame rotation, Gaussian std per camera axis
  double yaw_axis_memory_s = WindowOptions{}.yaw_axis_memory_s;
  double yaw_axis_prior_deg = WindowOptions{}.yaw_axis_prior_deg;
  int rate_prior_adapt_frames = WindowOptions{}.rate_prior_adapt_frames;
};

struct DriveResult {
  Eigen::Vector3d final_rot_err_deg = Eigen::Vector3d::Zero();  // log(C_true^T C_est), camera
  double final_trans_err_m = 0.0;                               // |t_est - t_true|, world
  double last_roll_std_deg_s = 0.0;  // the last solve's rate-prior std on the roll-like axis
  Eigen::Vector3d yaw_axis = Eigen::Vector3d::Zero();
  Eigen::Vector3d yaw_axis_before_last = Eigen::Vector3d::Zero();  // before the last solve
};

// A 10 Hz drive, 1 m per frame; each frame pair (k-1, k) sees its own 40 landmarks, 6-40 m deep,
// observed exactly (plus noise) in k-1 and with the error field added in k.
DriveResult drive(const DriveOptions& o) {
  const StereoCamera cam = kittiCamera();
  WindowOptions wo;
  wo.rotation_rate_prior = o.prior;
  wo.yaw_axis_memory_s = o.yaw_axis_memory_s;
  wo.yaw_axis_prior_deg = o.yaw_axis_prior_deg;
  wo.rate_prior_adapt_frames = o.rate_prior_adapt_frames;
  wo.max_num_iterations = 20;
  wo.max_solver_time_in_seconds = 10.0;
  BundleWindow w;
  EXPECT_TRUE(w.init(wo, cam).isOk());
  w.reset(Isometry3::Identity());
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, o.noise_px);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double u_min = o.one_sided ? cam.width - 320.0 : 20.0;
  Isometry3 T_w_true = Isometry3::Identity();
  std::vector<WindowObservation> next;  // observations of the current frame for the next pair
  std::int64_t id = 0;
  Eigen::Vector3d before_last = Eigen::Vector3d::Zero();
  double last_roll_std = 0.0;
  for (int k = 0; k < o.frames; ++k) {
    // Motion into frame k: forward 1 m, a turn about axis_c, a roll wobble.
    const double turn = ((k / 20) % 2 == 0 ? 1.0 : -1.0) * o.turn_deg * M_PI / 180.0;
    const double wobble = (k % 2 == 0 ? 1.0 : -1.0) * o.roll_wobble_deg * M_PI / 180.0;
    Isometry3 T_km1_k = Isometry3::Identity();
    const Eigen::Vector3d random_wobble = o.random_wobble_deg * M_PI / 180.0 *
                                          Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) /
                                          o.noise_px;
    T_km1_k.linear() =
        expSO3(turn * o.axis_c.normalized() + Eigen::Vector3d(0.0, 0.0, wobble) + random_wobble);
    T_km1_k.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
    const Isometry3 T_k_km1 = k == 0 ? Isometry3::Identity() : T_km1_k.inverse();
    std::vector<WindowObservation> obs = next;
    for (auto& ob : obs) {
      // `next` holds the landmark in camera k-1 coordinates encoded in y; re-project into k.
      const Eigen::Vector3d p_km1 = cam.triangulate(ob.y.u, ob.y.v, ob.y.d);
      const Eigen::Vector3d y = cam.project(T_k_km1 * p_km1);
      const double field = o.field_px * std::pow((y.x() - cam.cu) / 500.0, 2);
      ob.y = {y.x() + noise(rng), y.y() + field + noise(rng), y.z() + noise(rng)};
    }
    // New landmarks of frame k, exact positions kept for the next frame.
    next.clear();
    std::vector<WindowObservation> fresh;
    while (static_cast<int>(next.size()) < 40) {
      const double u = u_min + unit(rng) * (cam.width - 20.0 - u_min);
      const double v =
          o.one_sided ? cam.cv - 100.0 + unit(rng) * 120.0 : 20.0 + unit(rng) * (cam.height - 40.0);
      const double z = 6.0 + unit(rng) * 34.0;
      const double d = cam.fu * cam.baseline_m / z;
      next.push_back({id, {u, v, d}});
      fresh.push_back({id++, {u + noise(rng), v + noise(rng), d + noise(rng)}});
    }
    obs.insert(obs.end(), fresh.begin(), fresh.end());
    if (k > 0) T_w_true = T_w_true * T_km1_k;
    EXPECT_TRUE(w.addFrame(static_cast<std::uint64_t>(k), static_cast<TimeNs>(k) * 100'000'000, obs,
                           T_k_km1)
                    .isOk());
    if (k == 0) continue;
    const Eigen::Vector3d axis_before = w.yawAxis();
    const auto s = w.solve();
    EXPECT_TRUE(s.hasValue()) << s.status().toString();
    if (s.hasValue()) last_roll_std = s->rate_prior_std_deg_s[2];
    if (k == o.frames - 1) {
      before_last = axis_before;
      if (o.restore_last) w.restoreInitialGuess();
    }
  }
  DriveResult r;
  r.yaw_axis_before_last = before_last;
  r.final_rot_err_deg =
      logSO3(T_w_true.linear().transpose() * w.T_w_newest().linear()) * 180.0 / M_PI;
  r.yaw_axis = w.yawAxis();
  r.final_trans_err_m = (w.T_w_newest().translation() - T_w_true.translation()).norm();
  r.last_roll_std_deg_s = last_roll_std;
  return r;
}

// One-sided tracks (40 in a 300 x 120 px patch right of cu) and a vL field of 0.3 px at 500 px
// from cu: the two-frame window reads its slope as roll. Measured: without the prior the roll
// error grows by 0.048 deg per frame (2.84 deg after 59 frames), with it 2.10 deg (pitch 0.54 ->
// 0.06 deg; 1.95 deg with the fixed std, which also acts in the first 10 frames); how much the
// prior takes out depends on the window's roll information, which this patch leaves at about
// what the weaker one-sided frames of the 0020 tracks have.
TEST(RotationRatePrior, RemovesRollDriftOfOneSidedTracksWithAnImageErrorField) {
  DriveOptions o;
  o.field_px = 0.3;
  o.prior = false;
  const DriveResult off = drive(o);
  o.prior = true;
  const DriveResult on = drive(o);
  std::printf(
      "one-sided, field 0.3 px: roll error after 59 frames %.3f deg (no prior), %.3f deg "
      "(prior); pitch %.3f / %.3f, yaw %.3f / %.3f deg\n",
      off.final_rot_err_deg.z(), on.final_rot_err_deg.z(), off.final_rot_err_deg.x(),
      on.final_rot_err_deg.x(), off.final_rot_err_deg.y(), on.final_rot_err_deg.y());
  EXPECT_GT(std::abs(off.final_rot_err_deg.z()), 1.0);
  EXPECT_LT(std::abs(on.final_rot_err_deg.z()), 0.75 * std::abs(off.final_rot_err_deg.z()));
  EXPECT_LT(on.final_rot_err_deg.norm(), off.final_rot_err_deg.norm());
}

// The same field on tracks spread over the whole image: its slopes on the two sides cancel, the
// window has roll information, and with or without the prior the roll error stays small.
TEST(RotationRatePrior, BalancedTracksWithTheFieldStayAccurate) {
  DriveOptions o;
  o.one_sided = false;
  o.field_px = 0.3;
  o.prior = false;
  const DriveResult off = drive(o);
  o.prior = true;
  const DriveResult on = drive(o);
  std::printf("balanced, field 0.3 px: roll error %.3f / %.3f deg\n", off.final_rot_err_deg.z(),
              on.final_rot_err_deg.z());
  EXPECT_LT(std::abs(off.final_rot_err_deg.z()), 0.5);
  EXPECT_LT(std::abs(on.final_rot_err_deg.z()), 0.5);
}

// Clean tracks (noise only) with turns of 2 deg/frame about an axis tilted 3 deg from the
// camera's y axis and a true roll wobble of +-0.1 deg/frame: the prior's zero-mean pull on the
// wobble and on the turn's leakage into the camera's z axis must not cost accuracy, and the
// estimated yaw axis must find the tilt.
TEST(RotationRatePrior, CleanTurnsAboutATiltedAxisAreNotBiased) {
  DriveOptions o;
  o.one_sided = false;
  o.axis_c = Eigen::Vector3d(0.0, std::cos(3.0 * M_PI / 180.0), std::sin(3.0 * M_PI / 180.0));
  o.turn_deg = 2.0;
  o.roll_wobble_deg = 0.1;
  o.frames = 80;
  o.prior = false;
  const DriveResult off = drive(o);
  o.prior = true;
  const DriveResult on = drive(o);
  const double axis_err_deg =
      std::acos(std::min(1.0, on.yaw_axis.dot(o.axis_c.normalized()))) * 180.0 / M_PI;
  std::printf(
      "clean turns: rotation error %.4f deg (no prior), %.4f deg (prior); yaw axis "
      "%.4f %.4f %.4f, %.3f deg from the truth\n",
      off.final_rot_err_deg.norm(), on.final_rot_err_deg.norm(), on.yaw_axis.x(), on.yaw_axis.y(),
      on.yaw_axis.z(), axis_err_deg);
  EXPECT_LT(axis_err_deg, 0.5);
  // A solution the caller rejects does not enter the yaw-axis estimate.
  EXPECT_NE(on.yaw_axis, on.yaw_axis_before_last);
  o.restore_last = true;
  const DriveResult restored = drive(o);
  EXPECT_EQ(restored.yaw_axis, restored.yaw_axis_before_last);
  EXPECT_EQ(restored.yaw_axis_before_last, on.yaw_axis_before_last);
  EXPECT_LT(on.final_rot_err_deg.norm(), off.final_rot_err_deg.norm() + 0.05);
  EXPECT_LT(on.final_rot_err_deg.norm(), 0.2);
}

// 60 s of straight driving with a body wobble of 0.1 deg/frame per axis (the size of the
// ground truth's per-frame pitch and roll on 0020): without turns the yaw-axis estimate must stay
// at the camera's y axis (the defaults' regulariser outweighs the wobble's scatter over the
// memory); with a long memory and a weak regulariser the wobble alone tilts it.
TEST(RotationRatePrior, ALongStraightDoesNotTiltTheYawAxis) {
  DriveOptions o;
  o.one_sided = false;
  o.random_wobble_deg = 0.1;
  o.frames = 600;
  const DriveResult def = drive(o);
  o.yaw_axis_memory_s = 120.0;
  o.yaw_axis_prior_deg = 1.0;
  const DriveResult weak = drive(o);
  const auto tilt = [](const Eigen::Vector3d& a) {
    return std::acos(std::min(1.0, std::abs(a.y()))) * 180.0 / M_PI;
  };
  std::printf(
      "straight drive, 0.1 deg/frame wobble: yaw axis %.2f deg from y (defaults), %.2f deg "
      "(120 s, 1 deg)\n",
      tilt(def.yaw_axis), tilt(weak.yaw_axis));
  EXPECT_LT(tilt(def.yaw_axis), 3.0);
  EXPECT_GT(tilt(weak.yaw_axis), tilt(def.yaw_axis));
}

// Rough ground (a rover, or the rendered rough-road drives): the vehicle itself pitches, yaws
// and rolls by a Gaussian 1.5 deg per frame (15 deg/s at 10 Hz). A fixed 2 deg/s prior pulls each
// frame's true rotation towards 0 and the window moves the rest into the translation; the prior
// adapted to the spread of the vehicle's own rates (WindowOptions::rate_prior_adapt_frames) must
// end as close as no prior at all, with a roll std near the rates' own 15 deg/s.
TEST(RotationRatePrior, OnRoughGroundThePriorFollowsTheVehicle) {
  DriveOptions o;
  o.one_sided = false;
  o.random_wobble_deg = 1.5;
  o.frames = 120;
  o.prior = false;
  const DriveResult off = drive(o);
  o.prior = true;
  o.rate_prior_adapt_frames = 0;
  const DriveResult fixed = drive(o);
  o.rate_prior_adapt_frames = WindowOptions{}.rate_prior_adapt_frames;
  const DriveResult adapted = drive(o);
  std::printf(
      "rough ground, 1.5 deg/frame: final translation error %.3f m (no prior), %.3f m (fixed "
      "2 deg/s), %.3f m (adapted, roll std %.1f deg/s); rotation %.3f / %.3f / %.3f deg\n",
      off.final_trans_err_m, fixed.final_trans_err_m, adapted.final_trans_err_m,
      adapted.last_roll_std_deg_s, off.final_rot_err_deg.norm(), fixed.final_rot_err_deg.norm(),
      adapted.final_rot_err_deg.norm());
  EXPECT_GT(fixed.final_trans_err_m, 2.0 * off.final_trans_err_m);
  EXPECT_LT(adapted.final_trans_err_m, 1.2 * off.final_trans_err_m + 0.01);
  EXPECT_GT(adapted.last_roll_std_deg_s, 10.0);
  EXPECT_LT(adapted.last_roll_std_deg_s, 25.0);
  EXPECT_EQ(fixed.last_roll_std_deg_s, 2.0);
}

TEST(RotationRatePrior, OptionsAreValidated) {
  WindowOptions wo;
  EXPECT_TRUE(wo.validate().isOk());
  wo.rate_prior_roll_deg_s = -1.0;
  EXPECT_NE(wo.validate().message().find("window.rate_prior_roll_deg_s"), std::string::npos);
  wo = WindowOptions{};
  wo.rate_prior_pitch_deg_s = 2000.0;
  EXPECT_NE(wo.validate().message().find("window.rate_prior_pitch_deg_s"), std::string::npos);
  wo = WindowOptions{};
  wo.yaw_axis_memory_s = 0.0;
  EXPECT_NE(wo.validate().message().find("window.yaw_axis_memory_s"), std::string::npos);
  wo = WindowOptions{};
  wo.yaw_axis_prior_deg = 0.0;
  EXPECT_NE(wo.validate().message().find("window.yaw_axis_prior_deg"), std::string::npos);
  wo = WindowOptions{};
  wo.rate_prior_adapt_frames = RateSpread::kMaxFrames + 1;
  EXPECT_NE(wo.validate().message().find("window.rate_prior_adapt_frames"), std::string::npos);
  wo.rate_prior_adapt_frames = -1;
  EXPECT_NE(wo.validate().message().find("window.rate_prior_adapt_frames"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::backend
