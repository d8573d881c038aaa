#include "sunvo/vertical/vertical_estimator.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "sunvo/core/geometry.hpp"

namespace sunvo::vertical {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

StereoCamera kittiCamera() {
  return {718.856, 718.856, 607.1928, 185.2157, 0.53716, 1241, 376};
}

// A street seen by a camera rolled and pitched against gravity: poles (vertical 3-D segments from
// the road to 6 m up) at random places, plus horizontal lines (kerbs, window rows) as distractors.
// The world is camera-like with up = (0, -1, 0); C_c_w turns it into the camera.
class VerticalEstimatorTest : public ::testing::Test {
 protected:
  cv::Mat street(const Eigen::Matrix3d& C_c_w, double x_min, double x_max, int poles) const {
    const StereoCamera cam = kittiCamera();
    cv::Mat img(cam.height, cam.width, CV_8UC1, cv::Scalar(90));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> x(x_min, x_max), z(8.0, 40.0);
    const auto draw = [&](const Eigen::Vector3d& a_w, const Eigen::Vector3d& b_w) {
      const Eigen::Vector3d a = C_c_w * a_w, b = C_c_w * b_w;
      if (a.z() < 1.0 || b.z() < 1.0) return;
      const auto px = [&](const Eigen::Vector3d& p) {
        // cv::line with shift 4 takes 1/16 px; pixel centres are at integers.
        return cv::Point(static_cast<int>(std::lround(16.0 * (cam.fu * p.x() / p.z() + cam.cu))),
                         static_cast<int>(std::lround(16.0 * (cam.fv * p.y() / p.z() + cam.cv))));
      };
      cv::line(img, px(a), px(b), cv::Scalar(220), 2, cv::LINE_AA, 4);
    };
    for (int i = 0; i < poles; ++i) {
      const double px = x(rng), pz = z(rng);
      draw({px, 1.6, pz}, {px, -6.0, pz});
    }
    for (int i = 0; i < 10; ++i) {
      const double pz = z(rng), py = -1.0 - 0.4 * i;
      draw({-12.0, py, pz}, {12.0, py, pz});
    }
    return img;
  }
};

TEST_F(VerticalEstimatorTest, FindsTheTrueUpOfARolledAndPitchedCamera) {
  const Eigen::Matrix3d C_c_w = expSO3(Eigen::Vector3d(-2.0 * kDeg, 0.0, 3.0 * kDeg));
  const Eigen::Vector3d up_true = C_c_w * Eigen::Vector3d(0.0, -1.0, 0.0);
  VerticalEstimator est;
  ASSERT_TRUE(est.init(VerticalOptions{}, kittiCamera()).isOk());
  auto m = est.estimate(street(C_c_w, -15.0, 15.0, 30), Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(m) << m.status().toString();
  ASSERT_TRUE(m->valid) << m->reason;
  const double err_deg = std::acos(std::min(1.0, m->up_c.dot(up_true))) / kDeg;
  EXPECT_LT(err_deg, 0.15);
  EXPECT_GE(m->inliers, 20);
  EXPECT_GT(m->sigma_rad, 0.0);
  EXPECT_LT(m->sigma_rad, 1.0 * kDeg);
  EXPECT_NEAR(m->up_c.norm(), 1.0, 1e-12);
  // The candidates of the call (sunvo_vertical_eval --segments-csv): each plane holds the rays
  // of its two end points, is as long as they are apart, and about as many lie within the inlier
  // bound of the truth as of the estimate.
  int near_truth = 0;
  for (const auto& p : est.candidates()) {
    const StereoCamera cam = kittiCamera();
    const auto ray = [&](const Eigen::Vector2d& q) {
      return Eigen::Vector3d((q.x() - cam.cu) / cam.fu, (q.y() - cam.cv) / cam.fv, 1.0)
          .normalized();
    };
    EXPECT_NEAR(p.n.norm(), 1.0, 1e-12);
    EXPECT_NEAR(p.n.dot(ray(p.a)), 0.0, 1e-12);
    EXPECT_NEAR(p.n.dot(ray(p.b)), 0.0, 1e-12);
    EXPECT_NEAR(p.w, (p.b - p.a).norm(), 1e-9);
    if (std::abs(p.n.dot(up_true)) < std::sin(VerticalOptions{}.inlier_angle_deg * kDeg)) {
      ++near_truth;
    }
  }
  EXPECT_EQ(static_cast<int>(est.candidates().size()), m->candidates);
  EXPECT_NEAR(near_truth, m->inliers, 2);
  // The level prior is 3.6 deg off; a prior at the truth gives the same answer.
  auto again = est.estimate(street(C_c_w, -15.0, 15.0, 30), up_true);
  ASSERT_TRUE(again && again->valid);
  EXPECT_LT(std::acos(std::min(1.0, again->up_c.dot(m->up_c))) / kDeg, 0.05);
}

TEST_F(VerticalEstimatorTest, SameImageSameAnswer) {
  const Eigen::Matrix3d C_c_w = expSO3(Eigen::Vector3d(1.0 * kDeg, 0.0, -1.5 * kDeg));
  const cv::Mat img = street(C_c_w, -15.0, 15.0, 30);
  VerticalEstimator est;
  ASSERT_TRUE(est.init(VerticalOptions{}, kittiCamera()).isOk());
  auto a = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
  auto b = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->up_c, b->up_c);
  EXPECT_EQ(a->inliers, b->inliers);
  EXPECT_EQ(a->sigma_rad, b->sigma_rad);
}

TEST_F(VerticalEstimatorTest, PolesInOneColumnGiveALargerSigma) {
  // Segments spread over the image fix both tilts; bunched near the centre column their planes
  // nearly coincide, and the tilt towards the optical axis (pitch) is weak.
  const Eigen::Matrix3d C_c_w = expSO3(Eigen::Vector3d(-1.0 * kDeg, 0.0, 1.0 * kDeg));
  VerticalEstimator est;
  ASSERT_TRUE(est.init(VerticalOptions{}, kittiCamera()).isOk());
  auto spread = est.estimate(street(C_c_w, -15.0, 15.0, 30), Eigen::Vector3d(0.0, -1.0, 0.0));
  auto bunched = est.estimate(street(C_c_w, -0.5, 0.5, 30), Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(spread && bunched);
  ASSERT_TRUE(spread->valid);
  EXPECT_GT(bunched->sigma_rad, 3.0 * spread->sigma_rad);
}

TEST_F(VerticalEstimatorTest, PolesInOneColumnFixTheRollButNotThePitch) {
  // Bunched poles keep their image angles, which is the roll of a level camera (a turn about the
  // optical axis moves "up" along the camera's x axis): the better direction is that axis, and
  // its sigma stays small while the pitch's grows. With per_axis_sigma off both are the worse one.
  const Eigen::Matrix3d C_c_w = expSO3(Eigen::Vector3d(-1.0 * kDeg, 0.0, 1.0 * kDeg));
  const cv::Mat img = street(C_c_w, -2.0, 2.0, 30);
  VerticalOptions options;
  options.min_sigma_deg = 0.001;  // the raw sigmas, not the floor
  VerticalEstimator est;
  ASSERT_TRUE(est.init(options, kittiCamera()).isOk());
  auto m = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(m) << m.status().toString();
  ASSERT_GE(m->inliers, 8);
  EXPECT_NEAR(m->strong_axis_c.norm(), 1.0, 1e-9);
  EXPECT_NEAR(m->strong_axis_c.dot(m->up_c), 0.0, 1e-9);
  EXPECT_GT(std::abs(m->strong_axis_c.x()), 0.99);
  EXPECT_LT(m->sigma_strong_rad * 5.0, m->sigma_rad);
  options.per_axis_sigma = false;
  ASSERT_TRUE(est.init(options, kittiCamera()).isOk());
  auto iso = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(iso);
  EXPECT_EQ(iso->sigma_strong_rad, iso->sigma_rad);
  EXPECT_EQ(iso->sigma_rad, m->sigma_rad);
  // The floor holds for both directions.
  options.per_axis_sigma = true;
  options.min_sigma_deg = 0.2;
  ASSERT_TRUE(est.init(options, kittiCamera()).isOk());
  auto floored = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(floored);
  EXPECT_GE(floored->sigma_strong_rad, 0.2 * kDeg);
  EXPECT_LE(floored->sigma_strong_rad, floored->sigma_rad);
}

TEST_F(VerticalEstimatorTest, NoVerticalEdgesIsAnInvalidMeasurementNotAnError) {
  VerticalEstimator est;
  ASSERT_TRUE(est.init(VerticalOptions{}, kittiCamera()).isOk());
  const StereoCamera cam = kittiCamera();
  const cv::Mat blank(cam.height, cam.width, CV_8UC1, cv::Scalar(128));
  auto m = est.estimate(blank, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(m) << m.status().toString();
  EXPECT_FALSE(m->valid);
  EXPECT_STREQ(m->reason, "too few near-vertical segments");
  EXPECT_TRUE(m->up_c.allFinite());
  // Horizontal lines only: none is near the prior's vertical.
  cv::Mat lines = blank.clone();
  for (int r = 40; r < cam.height; r += 30) {
    cv::line(lines, {50, r}, {1100, r + 5}, cv::Scalar(250), 2, cv::LINE_AA);
  }
  auto h = est.estimate(lines, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_TRUE(h);
  EXPECT_FALSE(h->valid);
}

TEST_F(VerticalEstimatorTest, BadInputIsAClearError) {
  VerticalEstimator est;
  const StereoCamera cam = kittiCamera();
  const cv::Mat gray(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  auto before = est.estimate(gray, Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_FALSE(before);
  ASSERT_TRUE(est.init(VerticalOptions{}, cam).isOk());
  auto colour = est.estimate(cv::Mat(cam.height, cam.width, CV_8UC3, cv::Scalar(0, 0, 0)),
                             Eigen::Vector3d(0.0, -1.0, 0.0));
  ASSERT_FALSE(colour);
  EXPECT_NE(colour.status().message().find("CV_8UC1"), std::string::npos);
  auto small = est.estimate(cv::Mat(100, 200, CV_8UC1, cv::Scalar(0)), Eigen::Vector3d(0, -1, 0));
  ASSERT_FALSE(small);
  EXPECT_NE(small.status().message().find("200x100"), std::string::npos);
  auto nan_prior = est.estimate(gray, Eigen::Vector3d(0.0, std::nan(""), 0.0));
  ASSERT_FALSE(nan_prior);
}

TEST(VerticalOptionsTest, ValidationNamesTheKey) {
  VerticalOptions o;
  EXPECT_TRUE(o.validate().isOk());
  o.line_sigma_deg = 0.0;
  EXPECT_NE(o.validate().message().find("vertical.line_sigma_deg"), std::string::npos);
  o = VerticalOptions{};
  o.max_width_px = 10;
  EXPECT_NE(o.validate().message().find("vertical.max_width_px"), std::string::npos);
  o = VerticalOptions{};
  o.min_inliers = 2;
  EXPECT_NE(o.validate().message().find("vertical.min_inliers"), std::string::npos);
  o = VerticalOptions{};
  o.min_segment_rows_share = 1.5;
  EXPECT_NE(o.validate().message().find("vertical.min_segment_rows_share"), std::string::npos);
  o = VerticalOptions{};
  o.min_gradient = 0.0;
  EXPECT_NE(o.validate().message().find("vertical.min_gradient"), std::string::npos);
  o = VerticalOptions{};
  o.max_segments = 8;
  EXPECT_NE(o.validate().message().find("vertical.max_segments"), std::string::npos);
}

// The default detector (edge chains) and the baseline (LSD) find the same up on the same street.
TEST_F(VerticalEstimatorTest, BothSegmentDetectorsAgree) {
  const Eigen::Matrix3d C_c_w = expSO3(Eigen::Vector3d(1.5 * kDeg, 0.0, -2.5 * kDeg));
  const Eigen::Vector3d up_true = C_c_w * Eigen::Vector3d(0.0, -1.0, 0.0);
  const cv::Mat img = street(C_c_w, -15.0, 15.0, 30);
  for (const SegmentDetector d : {SegmentDetector::kEdgeChains, SegmentDetector::kLsd}) {
    VerticalOptions o;
    o.detector = d;
    VerticalEstimator est;
    ASSERT_TRUE(est.init(o, kittiCamera()).isOk());
    auto m = est.estimate(img, Eigen::Vector3d(0.0, -1.0, 0.0));
    ASSERT_TRUE(m && m->valid) << static_cast<int>(d);
    EXPECT_LT(std::acos(std::min(1.0, m->up_c.dot(up_true))) / kDeg, 0.15) << static_cast<int>(d);
  }
}

}  // namespace
}  // namespace sunvo::vertical
