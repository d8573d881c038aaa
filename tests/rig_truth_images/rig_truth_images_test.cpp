// Tests of sunvo_rig_truth_images' library: the rig-error file, the homography back to the nominal
// right camera on a synthetic image, and a rendered drive whose right camera is turned (the CI
// rig-error scenario), whose right rows the front end then finds where the left rows are.

#include "sunvo/rig_truth_images/rig_truth_images.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sunvo/frontend/stereo_frontend.hpp"
#include "sunvo/render/drive.hpp"

namespace sunvo::rigtruth {
namespace {
namespace fs = std::filesystem;

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::path(SUNVO_BINARY_DIR) / "test_tmp" / ("rig_truth_images_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(RigTruthImages, ABadLineNamesFileAndLine) {
  const fs::path d = tempDir("bad");
  const std::string path = (d / "rig_error.csv").string();
  std::ofstream(path)
      << "frame,right_roll_deg,right_pitch_deg,right_yaw_deg\n0,0.1,0.02,0\n1,x,0,0\n";
  const auto turns = readRigError(path);
  ASSERT_FALSE(turns.hasValue());
  EXPECT_NE(turns.status().message().find(path + ":3"), std::string::npos)
      << turns.status().message();
  std::ofstream(path) << "frame,right_roll_deg,right_pitch_deg,right_yaw_deg\n0,0.1,0.02,0.01\n";
  const auto ok = readRigError(path);
  ASSERT_TRUE(ok.hasValue()) << ok.status().message();
  ASSERT_EQ(ok->size(), 1u);
  EXPECT_DOUBLE_EQ((*ok)[0].yaw_deg, 0.01);
  EXPECT_FALSE(readRigError((d / "missing.csv").string()).hasValue());
}

// A smooth random image seen by the right camera turned by 0.3 deg roll, 0.1 deg pitch and
// 0.05 deg yaw (I_turned(q) = I_nom(K R K^-1 q)) comes back to within a fraction of a grey level,
// away from the border the turn moved in.
TEST(RigTruthImages, TheTurnedImageComesBack) {
  const StereoCamera cam{700.0, 700.0, 320.0, 120.0, 0.5, 640, 240};
  cv::Mat coarse(45, 110, CV_32F);
  cv::RNG(7).fill(coarse, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat fine;
  cv::resize(coarse, fine, cv::Size(660, 270), 0, 0, cv::INTER_CUBIC);
  cv::Mat nominal;
  fine(cv::Rect(10, 15, cam.width, cam.height)).convertTo(nominal, CV_8U);
  const RigTurn turn{0, 0.3, 0.1, 0.05};
  const Eigen::Matrix3d R = rightCameraTurn(turn, Axes{});
  Eigen::Matrix3d K;
  K << cam.fu, 0, cam.cu, 0, cam.fv, cam.cv, 0, 0, 1;
  cv::Mat h;
  cv::eigen2cv(Eigen::Matrix3d(K * R * K.inverse()), h);
  cv::Mat turned;
  cv::warpPerspective(nominal, turned, h, nominal.size(), cv::INTER_CUBIC | cv::WARP_INVERSE_MAP,
                      cv::BORDER_REPLICATE);
  cv::Mat back;
  warpToNominal(turned, cam, R, back);
  const cv::Rect inner(20, 20, cam.width - 40, cam.height - 40);
  const double before = cv::norm(turned(inner), nominal(inner), cv::NORM_L1) / inner.area();
  const double after = cv::norm(back(inner), nominal(inner), cv::NORM_L1) / inner.area();
  std::printf("mean |difference| to the nominal image: turned %.2f, back %.2f grey levels\n",
              before, after);
  EXPECT_GT(before, 5.0);
  EXPECT_LT(after, 1.0);
  // Only the named axes: the roll alone leaves the pitch and yaw in.
  const Eigen::Matrix3d roll_only = rightCameraTurn(turn, Axes{true, false, false});
  EXPECT_NEAR(std::atan2(roll_only(1, 0), roll_only(0, 0)) * 180.0 / M_PI, 0.3, 1e-9);
  EXPECT_NEAR(roll_only(2, 2), 1.0, 1e-12);
}

// The front end's measured right rows on frame k: the median of v_right - v_left over the
// matches more than 300 px right of cu minus the same left of cu (a roll's tilt of the rows).
double rowTilt(const std::string& sync, int k) {
  char name[32];
  std::snprintf(name, sizeof name, "/data/%010d.png", k);
  const cv::Mat left = cv::imread(sync + "/image_00" + name, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(sync + "/image_01" + name, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(left.empty() || right.empty()) << sync;
  FrontendOptions opt;
  opt.measure_v_right = true;
  StereoFrontend fe;
  const StereoCamera cam{721.5377, 721.5377, 609.5593, 172.854, 0.537, left.cols, left.rows};
  EXPECT_TRUE(fe.init(opt, cam).isOk());
  FrameFeatures out;
  EXPECT_TRUE(fe.process(left, right, 0, 0, out).isOk());
  std::vector<double> lhs;
  std::vector<double> rhs;
  for (const auto& o : out.observations) {
    if (!o.v_right_measured) continue;
    if (o.u_left < cam.cu - 300.0) lhs.push_back(o.v_right - o.v_left);
    if (o.u_left > cam.cu + 300.0) rhs.push_back(o.v_right - o.v_left);
  }
  EXPECT_GE(lhs.size(), 10u);
  EXPECT_GE(rhs.size(), 10u);
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return lhs.empty() || rhs.empty() ? 0.0 : median(rhs) - median(lhs);
}

// Two frames of the CI rig-error drive (right camera turned 0.1 deg in roll, 0.02 deg in pitch:
// rows off by up to 1.1 px at the sides): the front end's measured right rows tilt by about
// 2 * 0.1 deg * 420 px between the image's sides as rendered, by under 0.15 px once the turn is
// taken out; the other files are links, and gt/rig_error.csv says the turn is gone.
TEST(RigTruthImages, ARenderedTurnIsTakenOut) {
  auto scenario = render::loadScenario(std::string(SUNVO_SOURCE_DIR) +
                                       "/config/scenarios/ci_short_rig_error.yaml");
  ASSERT_TRUE(scenario.hasValue()) << scenario.status().message();
  scenario->frames = 2;
  const fs::path drive = fs::path(SUNVO_BINARY_DIR) / "test_render_cache" / "rig_truth_images";
  fs::remove_all(drive);
  const auto sync = render::renderDrive(*scenario, drive.string(), 2, {});
  ASSERT_TRUE(sync.hasValue()) << sync.status().message();
  const fs::path out = tempDir("drive");
  int frames = 0;
  const Status s = writeNominalDrive(drive.string(), (out / "nominal").string(), Axes{}, &frames);
  ASSERT_TRUE(s.isOk()) << s.message();
  EXPECT_EQ(frames, 2);
  const fs::path out_sync =
      out / "nominal" / fs::path(*sync).parent_path().filename() / fs::path(*sync).filename();
  ASSERT_TRUE(fs::exists(out_sync / "image_01" / "data" / "0000000001.png"));
  EXPECT_TRUE(fs::is_symlink(out_sync / "image_00"));
  EXPECT_FALSE(fs::is_symlink(out_sync / "gt" / "rig_error.csv"));
  const auto gone = readRigError((out_sync / "gt" / "rig_error.csv").string());
  ASSERT_TRUE(gone.hasValue());
  EXPECT_EQ((*gone)[1].roll_deg, 0.0);
  const double as_rendered = rowTilt(*sync, 1);
  const double taken_out = rowTilt(out_sync.string(), 1);
  std::printf("right rows, right side minus left side: as rendered %+.3f px, taken out %+.3f px\n",
              as_rendered, taken_out);
  EXPECT_GT(std::abs(as_rendered), 1.0);
  EXPECT_LT(std::abs(taken_out), 0.15);
  // Writing over an existing drive is refused, naming it.
  const Status again =
      writeNominalDrive(drive.string(), (out / "nominal").string(), Axes{}, &frames);
  EXPECT_FALSE(again.isOk());
  EXPECT_NE(again.message().find("exists"), std::string::npos) << again.message();
}

}  // namespace
}  // namespace sunvo::rigtruth
