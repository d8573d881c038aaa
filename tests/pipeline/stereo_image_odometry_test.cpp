#include "sunvo/pipeline/stereo_image_odometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "../support/kitti_first_frames.hpp"
#include "sunvo/files/trajectory_io.hpp"

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::pipeline {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

bool finiteResult(const FrameResult& r) {
  return allFinite(r.vo.T_w_c) && allFinite(r.vo.T_k_km1) && std::isfinite(r.times.total_ms);
}

// Angle between two vectors, deg.
double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

class KittiPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto f = testing::loadKittiFirstFrames();
    ASSERT_TRUE(f.hasValue()) << f.status().toString();
    data_ = new testing::KittiFrames(std::move(*f));
    auto gt =
        files::readKittiPoses(std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_gt_poses.txt");
    ASSERT_TRUE(gt.hasValue()) << gt.status().toString();
    ASSERT_GE(gt->size(), data_->frames.size());
    gt_ = new std::vector<Isometry3>(
        gt->T_w_c.begin(), gt->T_w_c.begin() + static_cast<std::ptrdiff_t>(data_->frames.size()));
  }
  static void TearDownTestSuite() {
    delete data_;
    delete gt_;
    data_ = nullptr;
    gt_ = nullptr;
  }
  static testing::KittiFrames* data_;
  static std::vector<Isometry3>* gt_;
};
testing::KittiFrames* KittiPipeline::data_ = nullptr;
std::vector<Isometry3>* KittiPipeline::gt_ = nullptr;

TEST(PipelineOptions, DefaultsValidAndBadKeysNamed) {
  EXPECT_TRUE(PipelineOptions{}.validate().isOk());
  PipelineOptions o;
  o.frontend.max_features = 3000;  // > vo.max_observations
  Status s = o.validate();
  EXPECT_FALSE(s.isOk());
  EXPECT_NE(s.message().find("frontend.max_features"), std::string::npos) << s.message();
  o = PipelineOptions{};
  o.max_hint_px = -1.0;
  s = o.validate();
  EXPECT_NE(s.message().find("max_hint_px"), std::string::npos) << s.message();
  o = PipelineOptions{};
  o.frontend.nms_radius = 0;
  s = o.validate();
  EXPECT_NE(s.message().find("nms_radius"), std::string::npos) << s.message();
  o = PipelineOptions{};
  o.vo.max_observations = 1;
  s = o.validate();
  EXPECT_NE(s.message().find("max_observations"), std::string::npos) << s.message();
  o = PipelineOptions{};
  o.self_calibration.enabled = true;  // without frontend.measure_v_right
  s = o.validate();
  EXPECT_NE(s.message().find("self_calibration.enabled"), std::string::npos) << s.message();
  o.frontend.measure_v_right = true;
  EXPECT_TRUE(o.validate().isOk());
  o.self_calibration.sigma_px = 0.0;
  s = o.validate();
  EXPECT_NE(s.message().find("self_calibration.sigma_px"), std::string::npos) << s.message();
}

// The 11 real frames with the right image moved down by 0.3 px (a rectification off by that
// much) against the same frames as recorded: with self-calibration on, the right pitch it
// estimates differs by about 0.3 px / fv between the two (the KITTI rig's own residual offset
// is in both), and the odometry gets corrected right rows; off, nothing changes.
TEST_F(KittiPipeline, SelfCalibrationLearnsAShiftedRightImage) {
  PipelineOptions o;
  o.frontend.measure_v_right = true;
  o.self_calibration.enabled = true;
  const double shift_px = 0.3;
  double pitch_mrad[2] = {0.0, 0.0};
  for (int shifted = 0; shifted < 2; ++shifted) {
    StereoImageOdometry vo;
    ASSERT_TRUE(vo.init(o, data_->camera).isOk());
    FrameResult last;
    // Forward and back twice over the 11 frames: 41 frames.
    for (int k = 0; k < 41; ++k) {
      const int i = std::abs((k + 10) % 20 - 10);
      StereoFrame f = data_->frames[static_cast<std::size_t>(i)];
      if (shifted == 1) {
        const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, 1, shift_px);
        cv::Mat moved;
        cv::warpAffine(f.right, moved, m, f.right.size(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
        f.right = moved;
      }
      f.sequence = static_cast<std::uint64_t>(k);
      f.trigger_time_ns = k * 100'000'000LL;
      auto r = vo.process(f);
      ASSERT_TRUE(r.hasValue()) << r.status().toString();
      last = *r;
    }
    EXPECT_TRUE(last.self_calibration.updated);
    EXPECT_EQ(last.self_calibration.resets, 0u);
    pitch_mrad[shifted] = last.self_calibration.pitch_mrad;
  }
  const double expected_mrad = 1e3 * shift_px / data_->camera.fv;
  std::printf(
      "self-calibration pitch: recorded %.4f mrad, shifted %.4f mrad, difference %.4f "
      "(0.3 px / fv = %.4f mrad)\n",
      pitch_mrad[0], pitch_mrad[1], pitch_mrad[1] - pitch_mrad[0], expected_mrad);
  EXPECT_NEAR(pitch_mrad[1] - pitch_mrad[0], expected_mrad, 0.2 * expected_mrad);
}

TEST_F(KittiPipeline, ProcessBeforeInitAndWrongImagesAreErrors) {
  StereoImageOdometry vo;
  EXPECT_FALSE(vo.process(data_->frames[0]).hasValue());
  ASSERT_TRUE(vo.init(PipelineOptions{}, data_->camera).isOk());
  StereoFrame bad;
  bad.left = cv::Mat(data_->camera.height, data_->camera.width, CV_8UC3, cv::Scalar(0, 0, 0));
  bad.right = bad.left.clone();
  EXPECT_FALSE(vo.process(bad).hasValue());
}

// Frames 0..10 of KITTI 00 against the first 11 ground-truth poses. Per consecutive pair:
// rotation error of the relative motion, angle between the estimated and true translation
// directions, and the translation length (the GT's constant 0.859 m/frame is not trusted there;
// independent stereo VO systems measure 0.68 -> 0.82 m, see data/README.md).
TEST_F(KittiPipeline, RealFramesMatchGroundTruthDirectionAndRotation) {
  StereoImageOdometry vo;
  ASSERT_TRUE(vo.init(PipelineOptions{}, data_->camera, (*gt_)[0]).isOk());
  std::vector<Isometry3> T_w_c;
  for (std::size_t k = 0; k < data_->frames.size(); ++k) {
    auto r = vo.process(data_->frames[k]);
    ASSERT_TRUE(r.hasValue()) << r.status().toString();
    ASSERT_TRUE(finiteResult(*r)) << "frame " << k;
    if (k == 0) {
      EXPECT_EQ(r->vo.status, vo::TrackingStatus::kInitializing);
    } else {
      EXPECT_EQ(r->vo.status, vo::TrackingStatus::kTracking) << "frame " << k;
      EXPECT_EQ(r->vo.reference_gap, 1);
      EXPECT_TRUE(r->vo.window_used) << "frame " << k;
    }
    T_w_c.push_back(r->vo.T_w_c);
    const FrameResult& f = *r;
    std::printf(
        "frame %2zu: %4d features %3d tracked %3d matches %3d inliers %3d window landmarks | "
        "detect %.1f temporal %.1f stereo %.1f ransac %.1f window %.1f total %.1f ms | hint "
        "(%.2f, %.2f) px\n",
        k, f.num_features, f.frontend.tracks_kept, f.vo.num_matches, f.vo.ransac_inliers,
        f.vo.window_landmarks, f.times.detect_ms, f.times.temporal_ms, f.times.stereo_ms,
        f.times.ransac_ms, f.times.window_ms, f.times.total_ms, static_cast<double>(f.hint_du_px),
        static_cast<double>(f.hint_dv_px));
    // Stage times are consistent with the total.
    EXPECT_LE(f.times.detect_ms + f.times.temporal_ms + f.times.stereo_ms,
              f.times.frontend_ms + 1e-6);
    EXPECT_LE(f.times.frontend_ms + f.times.odometry_ms, f.times.total_ms + 1e-6);
    EXPECT_GT(f.times.detect_cpu_ms, 0.0);
    EXPECT_GT(f.times.total_cpu_ms, f.times.frontend_cpu_ms);
  }
  double max_rot = 0.0;
  double max_dir = 0.0;
  double min_len = 1e9;
  double max_len = 0.0;
  for (std::size_t k = 1; k < T_w_c.size(); ++k) {
    const Isometry3 est = T_w_c[k - 1].inverse() * T_w_c[k];  // T_km1_k
    const Isometry3 gt = (*gt_)[k - 1].inverse() * (*gt_)[k];
    const double rot = rotationAngle(gt.linear().transpose() * est.linear()) * kRadToDeg;
    const double dir = angleDeg(est.translation(), gt.translation());
    const double len = est.translation().norm();
    std::printf(
        "pair %2zu-%2zu: rotation error %.4f deg (GT rotation %.4f deg), direction error "
        "%.3f deg, length %.4f m (GT %.4f m)\n",
        k - 1, k, rot, rotationAngle(gt.linear()) * kRadToDeg, dir, len, gt.translation().norm());
    max_rot = std::max(max_rot, rot);
    max_dir = std::max(max_dir, dir);
    min_len = std::min(min_len, len);
    max_len = std::max(max_len, len);
  }
  std::printf("max rotation error %.4f deg, max direction error %.3f deg, length %.4f..%.4f m\n",
              max_rot, max_dir, min_len, max_len);
  // Measured (Release, this tree): rotation error 0.11..0.27 deg per pair (the GT itself rotates a
  // constant 0.139 deg per frame there), direction error 1.85..2.97 deg (the GT's direction stays
  // fixed in the world while its camera turns), lengths 0.669 -> 0.814 m. Bounds: measured +
  // margin.
  EXPECT_LT(max_rot, 0.4);
  EXPECT_LT(max_dir, 4.0);
  // Scale loosely: inside the independent systems' range, and accelerating like them
  // (0.68 -> 0.82 m): first pair 0.669 m, last 0.814 m measured.
  EXPECT_GT(min_len, 0.6);
  EXPECT_LT(max_len, 0.9);
  const double first_len = (T_w_c[0].inverse() * T_w_c[1]).translation().norm();
  const double last_len = (T_w_c[9].inverse() * T_w_c[10]).translation().norm();
  EXPECT_NEAR(first_len, 0.68, 0.05);
  EXPECT_NEAR(last_len, 0.82, 0.05);
  // The whole 10-frame displacement: 7.4 m measured (GT 8.6 m, see the caveat), direction.
  const Isometry3 est10 = T_w_c[0].inverse() * T_w_c[10];
  const Isometry3 gt10 = (*gt_)[0].inverse() * (*gt_)[10];
  const double dir10 = angleDeg(est10.translation(), gt10.translation());
  const double rot10 = rotationAngle(gt10.linear().transpose() * est10.linear()) * kRadToDeg;
  std::printf(
      "frames 0-10: length %.3f m (GT %.3f m), direction error %.3f deg, rotation error "
      "%.3f deg\n",
      est10.translation().norm(), gt10.translation().norm(), dir10, rot10);
  EXPECT_NEAR(est10.translation().norm(), 7.5, 0.5);
  EXPECT_LT(dir10, 4.0);
  EXPECT_LT(rot10, 2.0);
}

// Neither stage allocates per frame inside the pipeline (the stage counter is sampled around
// each): the front end and the back end with the default window solver (schur_lm). The same
// frames with window.solver = ceres show that the counter does see the back end's allocations.
TEST_F(KittiPipeline, PipelineAllocatesNothingPerFrame) {
#if !defined(SUNVO_HAVE_ALLOC_COUNTER)
  GTEST_SKIP() << "no allocation counter in this build";
#else
  ASSERT_TRUE(runtime::allocCounterActive());
  std::uint64_t counts[2][2] = {};  // [solver][front end, back end]
  for (backend::WindowSolver solver :
       {backend::WindowSolver::kSchurLm, backend::WindowSolver::kCeres}) {
    PipelineOptions options;
    options.vo.window.solver = solver;
    StereoImageOdometry vo;
    ASSERT_TRUE(vo.init(options, data_->camera).isOk());
    vo.setStageCounter(&runtime::allocationCount);
    std::uint64_t* c = counts[solver == backend::WindowSolver::kCeres ? 1 : 0];
    for (std::size_t i = 0; i < 30; ++i) {
      const std::size_t k = (i % 20) <= 10 ? i % 20 : 20 - i % 20;  // 0..10..1 0..9
      StereoFrame f = data_->frames[k];
      f.sequence = i;
      f.trigger_time_ns = static_cast<TimeNs>(i) * 100'000'000;
      auto r = vo.process(f);
      ASSERT_TRUE(r.hasValue()) << r.status().toString();
      EXPECT_NE(r->vo.status, vo::TrackingStatus::kLost) << "frame " << i;
      if (i >= 2) {
        c[0] += r->frontend_counter_delta;
        c[1] += r->odometry_counter_delta;
      }
    }
  }
  std::printf(
      "allocations in frames 2..29: front end %llu, back end %llu (schur_lm); back end %llu "
      "(ceres)\n",
      static_cast<unsigned long long>(counts[0][0]), static_cast<unsigned long long>(counts[0][1]),
      static_cast<unsigned long long>(counts[1][1]));
  EXPECT_EQ(counts[0][0], 0u);
  EXPECT_EQ(counts[0][1], 0u);
  EXPECT_EQ(counts[1][0], 0u);
  EXPECT_GT(counts[1][1], 0u);  // the counter does see Ceres' allocations
#endif
}

// Degenerate images: black, identical left/right (zero disparity everywhere), independent noise.
// Never NaN, never an error, reported kLost; the pipeline recovers on the next good frames and
// then measures the true motion again.
TEST_F(KittiPipeline, DegenerateImagesAreLostThenRecovered) {
  const int h = data_->camera.height;
  const int w = data_->camera.width;
  cv::Mat black(h, w, CV_8UC1, cv::Scalar(0));
  cv::Mat noise_l(h, w, CV_8UC1);
  cv::Mat noise_r(h, w, CV_8UC1);
  cv::RNG rng(42);
  rng.fill(noise_l, cv::RNG::UNIFORM, 0, 256);
  rng.fill(noise_r, cv::RNG::UNIFORM, 0, 256);
  // Frames 0..3 good, 4 black, 5 left = right = the real left image 5, 6 noise, 7..10 good.
  std::vector<StereoFrame> frames = data_->frames;
  frames[4].left = black;
  frames[4].right = black;
  frames[5].right = frames[5].left;
  frames[6].left = noise_l;
  frames[6].right = noise_r;

  StereoImageOdometry vo;
  ASSERT_TRUE(vo.init(PipelineOptions{}, data_->camera, (*gt_)[0]).isOk());
  std::vector<FrameResult> results;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    auto r = vo.process(frames[k]);
    ASSERT_TRUE(r.hasValue()) << "frame " << k << ": " << r.status().toString();
    ASSERT_TRUE(finiteResult(*r)) << "frame " << k;
    std::printf("frame %2zu: %-12s %4d features %3d matches %3d inliers, gap %d\n", k,
                vo::toString(r->vo.status), r->num_features, r->vo.num_matches,
                r->vo.ransac_inliers, r->vo.reference_gap);
    results.push_back(*r);
  }
  for (std::size_t k = 1; k <= 3; ++k)
    EXPECT_EQ(results[k].vo.status, vo::TrackingStatus::kTracking);
  for (std::size_t k = 4; k <= 6; ++k) {
    EXPECT_EQ(results[k].vo.status, vo::TrackingStatus::kLost) << "frame " << k;
  }
  // Frame 7's features are all new (no id survives the bad frames), so it cannot be matched; frame
  // 8 matches frame 7 and recovers; later frames track.
  EXPECT_EQ(results[7].vo.status, vo::TrackingStatus::kLost);
  EXPECT_EQ(results[8].vo.status, vo::TrackingStatus::kRecovered);
  EXPECT_EQ(results[9].vo.status, vo::TrackingStatus::kTracking);
  EXPECT_EQ(results[10].vo.status, vo::TrackingStatus::kTracking);
  // After recovery the inter-frame motion is measured correctly again (bounds of the clean run).
  for (std::size_t k = 9; k <= 10; ++k) {
    const Isometry3 est = results[k - 1].vo.T_w_c.inverse() * results[k].vo.T_w_c;
    const Isometry3 gt = (*gt_)[k - 1].inverse() * (*gt_)[k];
    EXPECT_LT(rotationAngle(gt.linear().transpose() * est.linear()) * kRadToDeg, 0.4);
    EXPECT_LT(angleDeg(est.translation(), gt.translation()), 4.0);
    EXPECT_GT(est.translation().norm(), 0.6);
    EXPECT_LT(est.translation().norm(), 0.9);
  }
}

}  // namespace
}  // namespace sunvo::pipeline
