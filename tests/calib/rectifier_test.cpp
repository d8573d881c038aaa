// calib::StereoRectifier: the rectified camera and the maps agree with the raw calibration
// (points projected both ways), bad rigs are refused, and a frame allocates nothing once warm.

#include "sunvo/calib/rectifier.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::calib {
namespace {

cv::Matx33d rotY(double deg) {
  const double a = deg * CV_PI / 180.0;
  return {std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a)};
}
cv::Matx33d rotX(double deg) {
  const double a = deg * CV_PI / 180.0;
  return {1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a)};
}

// 640x480, 0.12 m baseline, the right camera turned 1.5 deg about y and 0.5 deg about x.
RawStereoCalibration rig(DistortionModel model = DistortionModel::kRadTan) {
  RawStereoCalibration c;
  c.file = "test_rig.yaml";
  c.size = cv::Size(640, 480);
  c.model = model;
  c.K_left = cv::Matx33d(500, 0, 322, 0, 501, 238, 0, 0, 1);
  c.K_right = cv::Matx33d(505, 0, 317, 0, 504, 243, 0, 0, 1);
  if (model == DistortionModel::kRadTan) {
    c.D_left = (cv::Mat_<double>(1, 5) << -0.12, 0.03, 0.0005, -0.0004, 0.0);
    c.D_right = (cv::Mat_<double>(1, 5) << -0.10, 0.02, -0.0003, 0.0002, 0.0);
  } else {
    c.D_left = (cv::Mat_<double>(1, 4) << 0.02, -0.004, 0.001, 0.0);
    c.D_right = (cv::Mat_<double>(1, 4) << 0.015, -0.003, 0.0, 0.0);
  }
  c.C_r_l = rotY(1.5) * rotX(0.5);
  // The right camera's centre at (0.12, 0.002, -0.001) in the left frame: t_r_l = -C_r_l c_r.
  c.t_r_l = -(c.C_r_l * cv::Vec3d(0.12, 0.002, -0.001));
  return c;
}

cv::Point2d project(const cv::Vec3d& p, const cv::Matx33d& K, const cv::Mat& D,
                    DistortionModel model) {
  std::vector<cv::Point3d> in{cv::Point3d(p[0], p[1], p[2])};
  std::vector<cv::Point2d> out;
  if (model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(in, out, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  } else {
    cv::projectPoints(in, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, out);
  }
  return out[0];
}

// The raw pixel a rectified pixel (integer) samples, from the fixed-point maps.
cv::Point2d sample(const StereoRectifier& r, bool right, int u, int v) {
  cv::Mat xy, unused;
  cv::convertMaps(r.map1(right), r.map2(right), xy, unused, CV_32FC2);
  const cv::Vec2f p = xy.at<cv::Vec2f>(v, u);
  return {p[0], p[1]};
}

void expectMapsMatchProjection(DistortionModel model) {
  const RawStereoCalibration c = rig(model);
  auto r = StereoRectifier::create(c);
  ASSERT_TRUE(r.hasValue()) << r.status().toString();
  const StereoCamera& cam = (*r)->camera();
  EXPECT_NEAR(cam.baseline_m, cv::norm(c.t_r_l), 1e-9);
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  const Eigen::Matrix3d C = (*r)->C_c_l();
  EXPECT_LT((C * C.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  // Points in the rectified left frame, at the integer pixels where the maps are exact.
  for (const auto& [u, v, z] : {std::tuple<int, int, double>{320, 240, 8.0},
                                {100, 80, 5.0},
                                {540, 400, 12.0},
                                {200, 350, 3.0}}) {
    const Eigen::Vector3d p_c = cam.triangulate(u, v, cam.fu * cam.baseline_m / z);
    const Eigen::Vector3d p_l = C.transpose() * p_c;
    const cv::Vec3d pl(p_l.x(), p_l.y(), p_l.z());
    const cv::Point2d raw_left = project(pl, c.K_left, c.D_left, model);
    const cv::Point2d got_left = sample(**r, false, u, v);
    EXPECT_LT(cv::norm(raw_left - got_left), 0.05) << u << "," << v;
    // The right eye sees it at (u - d, v) in its rectified image: same row.
    const double d = cam.fu * cam.baseline_m / p_c.z();
    const double u_right = u - d;
    const int ur = static_cast<int>(std::lround(u_right));
    // Shift the point so that its right-eye column is an integer too.
    const Eigen::Vector3d p_c2 = cam.triangulate(ur + d, v, d);
    const Eigen::Vector3d p_l2 = C.transpose() * p_c2;
    const cv::Vec3d p_r = c.C_r_l * cv::Vec3d(p_l2.x(), p_l2.y(), p_l2.z()) + c.t_r_l;
    const cv::Point2d raw_right = project(p_r, c.K_right, c.D_right, model);
    EXPECT_LT(cv::norm(raw_right - sample(**r, true, ur, v)), 0.05) << u << "," << v;
  }
}

TEST(StereoRectifier, MapsSampleWhereTheRawCamerasSeeThePoint) {
  expectMapsMatchProjection(DistortionModel::kRadTan);
}

TEST(StereoRectifier, EquidistantModelToo) {
  expectMapsMatchProjection(DistortionModel::kEquidistant);
}

TEST(StereoRectifier, AlphaZeroKeepsOnlyValidPixels) {
  RawStereoCalibration c = rig();
  for (const double alpha : {0.0, 1.0}) {
    auto r = StereoRectifier::create(c, RectifyOptions{alpha});
    ASSERT_TRUE(r.hasValue()) << r.status().toString();
    StereoFrame raw;
    raw.left = cv::Mat(c.size, CV_8UC1, cv::Scalar(200));
    raw.right = cv::Mat(c.size, CV_8UC1, cv::Scalar(100));
    raw.sequence = 7;
    StereoFrame out;
    ASSERT_TRUE((*r)->rectify(raw, out).isOk());
    EXPECT_EQ(out.sequence, 7u);
    // alpha 0: no black pixel away from the outermost row/column; alpha 1: black corners.
    const cv::Mat inner = out.left(cv::Rect(2, 2, 636, 476));
    const int black = static_cast<int>(inner.total()) - cv::countNonZero(inner);
    if (alpha == 0.0) {
      EXPECT_EQ(black, 0);
      EXPECT_EQ(out.right.at<std::uint8_t>(240, 320), 100);
    } else {
      EXPECT_GT(black, 100);
    }
  }
}

// The per-frame remap against cv::remap with the same maps: grey and colour, random images.
TEST(StereoRectifier, RemapMatchesOpenCvRemap) {
  const RawStereoCalibration c = rig();
  auto r = StereoRectifier::create(c, RectifyOptions{0.5});
  ASSERT_TRUE(r.hasValue()) << r.status().toString();
  for (const int type : {CV_8UC1, CV_8UC3}) {
    for (const bool right : {false, true}) {
      cv::Mat raw(c.size, type);
      cv::randu(raw, 0, 256);
      cv::GaussianBlur(raw, raw, cv::Size(5, 5), 1.5);  // texture at several scales
      cv::Mat ours;
      cv::Mat theirs;
      ASSERT_TRUE((*r)->rectifyEye(raw, right, ours).isOk());
      cv::remap(raw, theirs, (*r)->map1(right), (*r)->map2(right), cv::INTER_LINEAR,
                cv::BORDER_CONSTANT, cv::Scalar::all(0));
      ASSERT_EQ(ours.type(), type);
      cv::Mat diff;
      cv::absdiff(ours, theirs, diff);
      double max_diff = 0.0;
      cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
      EXPECT_LE(max_diff, 1.0) << "type " << type << " right " << right;
      EXPECT_GT(cv::countNonZero(ours.reshape(1)), static_cast<int>(ours.total()) / 2);
    }
  }
}

TEST(StereoRectifier, RefusesBadRigsAndBadImages) {
  RawStereoCalibration swapped = rig();
  swapped.t_r_l = -swapped.t_r_l;  // the second camera on the left
  auto s = StereoRectifier::create(swapped);
  ASSERT_FALSE(s.hasValue());
  EXPECT_NE(s.status().message().find("swap"), std::string::npos) << s.status().message();
  RawStereoCalibration vertical = rig();
  vertical.C_r_l = cv::Matx33d::eye();
  vertical.t_r_l = cv::Vec3d(0.0, -0.12, 0.0);
  auto v = StereoRectifier::create(vertical);
  ASSERT_FALSE(v.hasValue());
  EXPECT_NE(v.status().message().find("vertically"), std::string::npos);
  auto a = StereoRectifier::create(rig(), RectifyOptions{1.5});
  ASSERT_FALSE(a.hasValue());
  EXPECT_NE(a.status().message().find("alpha"), std::string::npos);

  auto r = StereoRectifier::create(rig());
  ASSERT_TRUE(r.hasValue());
  StereoFrame raw;
  raw.left = cv::Mat(480, 320, CV_8UC1, cv::Scalar(1));
  raw.right = cv::Mat(480, 640, CV_8UC1, cv::Scalar(1));
  StereoFrame out;
  const Status bad = (*r)->rectify(raw, out);
  ASSERT_FALSE(bad.isOk());
  EXPECT_NE(bad.message().find("left image: 320x480"), std::string::npos) << bad.message();
}

TEST(StereoRectifier, NoHeapAllocationPerFrameOnceWarm) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(runtime::allocCounterActive());
  RawStereoCalibration c = rig();
  c.size = cv::Size(1242, 375);  // the rover's default frame
  c.K_left = cv::Matx33d(720, 0, 620, 0, 720, 187, 0, 0, 1);
  c.K_right = cv::Matx33d(722, 0, 622, 0, 721, 186, 0, 0, 1);
  auto r = StereoRectifier::create(c);
  ASSERT_TRUE(r.hasValue()) << r.status().toString();
  StereoFrame raw;
  raw.left = cv::Mat(c.size, CV_8UC1);
  raw.right = cv::Mat(c.size, CV_8UC1);
  raw.left_color = cv::Mat(c.size, CV_8UC3);
  cv::randu(raw.left, 0, 255);
  cv::randu(raw.right, 0, 255);
  cv::randu(raw.left_color, 0, 255);
  StereoFrame out;
  ASSERT_TRUE((*r)->rectify(raw, out).isOk());  // allocates out's Mats
  const void* data = out.left_color.data;
  std::uint64_t allocations = 0;
  std::vector<double> ms;
  for (int k = 0; k < 300; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    runtime::AllocationScope scope;
    const Status s = (*r)->rectify(raw, out);
    allocations += scope.count();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ASSERT_TRUE(s.isOk());
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(out.left_color.data, data);
  std::sort(ms.begin(), ms.end());
  std::printf(
      "rectify 1242x375, grey pair + left colour: median %.2f ms, p90 %.2f ms per frame "
      "(300 frames, one thread), %llu allocations\n",
      ms[ms.size() / 2], ms[ms.size() * 9 / 10], static_cast<unsigned long long>(allocations));
  // For the record (not a bound: OpenCV's business): what cv::remap itself allocates per call
  // with the same maps, the reason the rectifier has its own remap loop.
  cv::Mat cv_out = out.left.clone();
  cv::remap(raw.left, cv_out, (*r)->map1(false), (*r)->map2(false), cv::INTER_LINEAR);
  std::uint64_t cv_allocations = 0;
  {
    runtime::AllocationScope scope;
    cv::remap(raw.left, cv_out, (*r)->map1(false), (*r)->map2(false), cv::INTER_LINEAR);
    cv_allocations = scope.count();
  }
  std::printf("cv::remap of one 1242x375 grey image into a warm Mat: %llu allocations\n",
              static_cast<unsigned long long>(cv_allocations));
  // The grey pair alone (what a GREY rig rectifies per frame).
  raw.left_color = cv::Mat();
  ms.clear();
  for (int k = 0; k < 300; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE((*r)->rectify(raw, out).isOk());
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  std::printf("rectify 1242x375, grey pair: median %.2f ms, p90 %.2f ms per frame\n",
              ms[ms.size() / 2], ms[ms.size() * 9 / 10]);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::calib
