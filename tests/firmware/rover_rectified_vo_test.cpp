// The live path with a raw calibration: the 11 real KITTI 00 frames (already rectified) are
// distorted and un-rectified into what a real, imperfect rig would see, with a known calibration
// written as OpenCV stereo YAML; the emulated V4L2 cameras serve those raw frames to
// V4l2FrameSource (driver, strobe pairing, calib::StereoRectifier), and the same stereo VO runs on
// its output and on the original rectified frames. Issue 17's criterion: the live path's VO
// within 5 % of the originals' (every per-frame translation and the whole displacement), and the
// same rotations. The source also allocates nothing per frame once warm, and YUYV colour
// reaches the colour Sun-CNN.

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "../support/kitti_first_frames.hpp"
#include "../support/temp_dir.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/pipeline/stereo_image_odometry.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/device_sources.hpp"
#include "sunvo/rover/mavlink_link.hpp"
#include "sunvo/rover/sun_provider.hpp"
#include "sunvo/sunestimators/sun_estimators.hpp"

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::rover {
namespace {

constexpr double kDeg = CV_PI / 180.0;
constexpr double kRateHz = 10.0;
constexpr TimeNs kPeriod = 100'000'000;
constexpr TimeNs kDelay = 3'000'000;  // strobe edge -> buffer timestamp
constexpr TimeNs kT0 = 5'000'000'000;

cv::Matx33d rotation(double x_deg, double y_deg, double z_deg) {
  cv::Matx33d R;
  cv::Rodrigues(cv::Vec3d(x_deg * kDeg, y_deg * kDeg, z_deg * kDeg), R);
  return R;
}

// The raw rig behind the rectified KITTI pair. o = the original rectified left camera (KITTI's);
// the raw left camera l and right camera r are turned from it (C_o_l, C_o_r) and centred at 0
// and (b, 0, 0) in o; both lenses have barrel distortion and a longer focal length.
struct RawRig {
  cv::Size size;
  cv::Matx33d K_orig;  // the rectified pair's intrinsics (shared)
  cv::Matx33d K_l, K_r;
  cv::Mat D_l, D_r;
  cv::Matx33d C_o_l = rotation(0.4, -0.6, 0.3);
  cv::Matx33d C_o_r = rotation(-0.3, 0.5, -0.4);
  double b = 0.0;

  explicit RawRig(const StereoCamera& cam) : size(cam.width, cam.height), b(cam.baseline_m) {
    K_orig = cv::Matx33d(cam.fu, 0, cam.cu, 0, cam.fv, cam.cv, 0, 0, 1);
    K_l = cv::Matx33d(cam.fu * 1.12, 0, cam.cu + 4.0, 0, cam.fv * 1.12, cam.cv - 3.0, 0, 0, 1);
    K_r = cv::Matx33d(cam.fu * 1.13, 0, cam.cu - 5.0, 0, cam.fv * 1.13, cam.cv + 2.0, 0, 0, 1);
    D_l = (cv::Mat_<double>(1, 5) << -0.15, 0.04, 0.0008, -0.0006, 0.0);
    D_r = (cv::Mat_<double>(1, 5) << -0.13, 0.03, -0.0005, 0.0007, 0.0);
  }
  // p_r = C_r_l p_l + t_r_l.
  cv::Matx33d C_r_l() const { return C_o_r.t() * C_o_l; }
  cv::Vec3d t_r_l() const { return -(C_o_r.t() * cv::Vec3d(b, 0, 0)); }

  void writeOpenCvYaml(const std::string& path) const {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "K1" << cv::Mat(K_l) << "D1" << D_l << "K2" << cv::Mat(K_r) << "D2" << D_r;
    fs << "R" << cv::Mat(C_r_l()) << "T" << cv::Mat(t_r_l());
    fs << "image_width" << size.width << "image_height" << size.height;
  }

  // Where each raw pixel of one eye looks in the original rectified image: undistort, turn into
  // o's orientation (C_o_x), project with K_orig. Returns the share of raw pixels that fall
  // outside the original image.
  double unrectifyMaps(bool right, cv::Mat* map_x, cv::Mat* map_y) const {
    std::vector<cv::Point2f> raw;
    raw.reserve(static_cast<std::size_t>(size.area()));
    for (int v = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u)
        raw.emplace_back(static_cast<float>(u), static_cast<float>(v));
    }
    std::vector<cv::Point2f> orig;
    cv::undistortPoints(
        raw, orig, right ? K_r : K_l, right ? D_r : D_l, right ? C_o_r : C_o_l, K_orig,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-6));
    map_x->create(size, CV_32FC1);
    map_y->create(size, CV_32FC1);
    int outside = 0;
    for (int v = 0, i = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u, ++i) {
        const cv::Point2f p = orig[static_cast<std::size_t>(i)];
        map_x->at<float>(v, u) = p.x;
        map_y->at<float>(v, u) = p.y;
        if (p.x < 0 || p.y < 0 || p.x > size.width - 1 || p.y > size.height - 1) ++outside;
      }
    }
    return static_cast<double>(outside) / static_cast<double>(size.area());
  }
};

RoverConfig liveConfig(const std::string& calibration, const cv::Size& size) {
  RoverConfig c;
  c.source.type = SourceType::kV4l2;
  c.source.v4l2.left_device = "/dev/sunvo-left";
  c.source.v4l2.right_device = "/dev/sunvo-right";
  c.source.v4l2.calibration = calibration;
  c.trigger.type = TriggerType::kGpio;
  c.trigger.rate_hz = kRateHz;
  c.trigger.frame_delay_ms = static_cast<double>(kDelay) / 1e6;
  c.trigger.match_window_ms = 4.0;
  c.frames.width = size.width;
  c.frames.height = size.height;
  return c;
}

struct Fixture {
  testing::TempDir dir;
  testing::KittiFrames data;
  std::vector<cv::Mat> raw_left, raw_right;
  emulated::EmulatedV4l2 cameras;
  std::unique_ptr<V4l2FrameSource> source;

  void setUp() {
    auto loaded = testing::loadKittiFirstFrames();
    ASSERT_TRUE(loaded.hasValue()) << loaded.status().toString();
    data = std::move(*loaded);
    const RawRig rig(data.camera);
    cv::Mat lx, ly, rx, ry;
    const double out_l = rig.unrectifyMaps(false, &lx, &ly);
    const double out_r = rig.unrectifyMaps(true, &rx, &ry);
    // The raw cameras see (almost) only what the original images hold.
    EXPECT_LT(out_l, 0.01);
    EXPECT_LT(out_r, 0.01);
    for (const StereoFrame& f : data.frames) {
      cv::Mat l, r;
      cv::remap(f.left, l, lx, ly, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
      cv::remap(f.right, r, rx, ry, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
      raw_left.push_back(l);
      raw_right.push_back(r);
    }
    const std::string yaml = dir.file("rig.yaml");
    rig.writeOpenCvYaml(yaml);
    const cv::Size size = rig.size;
    ASSERT_TRUE(cameras
                    .addCamera({"/dev/sunvo-left", size.width, size.height, true, false, 0, 0,
                                emulated::imageSequence(raw_left)})
                    .isOk());
    ASSERT_TRUE(cameras
                    .addCamera({"/dev/sunvo-right", size.width, size.height, true, false, 0, 0,
                                emulated::imageSequence(raw_right)})
                    .isOk());
    auto s = V4l2FrameSource::open(liveConfig(yaml, size), cameras, 0);
    ASSERT_TRUE(s.hasValue()) << s.status().toString();
    source = std::move(*s);
    ASSERT_TRUE(source->rectifies());
  }

  // Exposure k: both cameras fire, the strobe of trigger k is handed to the source.
  Status grab(std::uint64_t k, runtime::FrameSlot& slot) {
    const TriggerEvent ev{k, kT0 + static_cast<TimeNs>(k) * kPeriod,
                          kT0 + static_cast<TimeNs>(k) * kPeriod};
    cameras.trigger(ev.mono_ns + kDelay);
    return source->grab(ev, slot);
  }
};

// VO over the frames; *lost counts the frames it lost (none expected on the live path).
std::vector<Isometry3> runVo(const StereoCamera& camera, const std::vector<StereoFrame>& frames,
                             int* lost) {
  pipeline::StereoImageOdometry vo;
  EXPECT_TRUE(vo.init(pipeline::PipelineOptions{}, camera).isOk());
  std::vector<Isometry3> T_w_c;
  *lost = 0;
  for (const StereoFrame& f : frames) {
    auto r = vo.process(f);
    EXPECT_TRUE(r.hasValue()) << r.status().toString();
    if (!r) break;
    if (r->vo.status == vo::TrackingStatus::kLost) ++*lost;
    T_w_c.push_back(r->vo.T_w_c);
  }
  return T_w_c;
}

// The largest relative difference of the per-frame translation lengths, b against a.
double worstLengthRatio(const std::vector<Isometry3>& a, const std::vector<Isometry3>& b) {
  double worst = 0.0;
  for (std::size_t k = 1; k < std::min(a.size(), b.size()); ++k) {
    const double la = (a[k - 1].inverse() * a[k]).translation().norm();
    const double lb = (b[k - 1].inverse() * b[k]).translation().norm();
    worst = std::max(worst, std::abs(lb / la - 1.0));
  }
  return worst;
}

TEST(RoverRectifiedVo, LivePathOnRawFramesMatchesVoOnTheRectifiedOriginals) {
  Fixture fx;
  fx.setUp();
  if (HasFatalFailure()) return;
  const StereoCamera& live = fx.source->camera();
  std::printf(
      "rectified camera: fu %.2f fv %.2f cu %.2f cv %.2f baseline %.4f m (original fu %.2f "
      "cu %.2f cv %.2f baseline %.4f m)\n",
      live.fu, live.fv, live.cu, live.cv, live.baseline_m, fx.data.camera.fu, fx.data.camera.cu,
      fx.data.camera.cv, fx.data.camera.baseline_m);
  EXPECT_NEAR(live.baseline_m, fx.data.camera.baseline_m, 1e-9);

  std::vector<StereoFrame> rectified;
  runtime::FrameSlot slot;
  for (std::uint64_t k = 0; k < fx.data.frames.size(); ++k) {
    ASSERT_TRUE(fx.grab(k, slot).isOk()) << "frame " << k;
    StereoFrame f;
    f.sequence = k;
    f.trigger_time_ns = fx.data.frames[k].trigger_time_ns;
    f.left = slot.frame.left.clone();
    f.right = slot.frame.right.clone();
    rectified.push_back(f);
  }
  int lost_orig = 0;
  int lost_live = 0;
  const std::vector<Isometry3> T_orig = runVo(fx.data.camera, fx.data.frames, &lost_orig);
  const std::vector<Isometry3> T_live = runVo(live, rectified, &lost_live);
  EXPECT_EQ(lost_orig, 0);
  EXPECT_EQ(lost_live, 0);
  ASSERT_EQ(T_orig.size(), fx.data.frames.size());
  ASSERT_EQ(T_live.size(), fx.data.frames.size());

  // The live camera c is the rectifier's frame; in o's axes: T_o = C_o_c T_c C_c_o with
  // C_o_c = C_o_l C_l_c = C_o_l C_c_l^T.
  const RawRig rig(fx.data.camera);
  Eigen::Matrix3d C_o_l;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) C_o_l(i, j) = rig.C_o_l(i, j);
  }
  const Eigen::Matrix3d C_o_c = C_o_l * fx.source->C_c_l().transpose();
  double worst_len = 0.0;
  double worst_rot = 0.0;
  double worst_dir = 0.0;
  for (std::size_t k = 1; k < T_orig.size(); ++k) {
    const Isometry3 a = T_orig[k - 1].inverse() * T_orig[k];
    const Isometry3 b = T_live[k - 1].inverse() * T_live[k];
    const Eigen::Vector3d t_b = C_o_c * b.translation();
    const Eigen::Matrix3d R_b = C_o_c * b.linear() * C_o_c.transpose();
    const double len = std::abs(t_b.norm() / a.translation().norm() - 1.0);
    const double rot = rotationAngle(a.linear().transpose() * R_b) / kDeg;
    const double dir =
        std::acos(std::clamp(a.translation().normalized().dot(t_b.normalized()), -1.0, 1.0)) / kDeg;
    std::printf(
        "pair %2zu: length %.4f m live %.4f m (%+.2f %%), rotation difference %.4f deg, "
        "direction difference %.3f deg\n",
        k, a.translation().norm(), t_b.norm(), 100.0 * (t_b.norm() / a.translation().norm() - 1.0),
        rot, dir);
    worst_len = std::max(worst_len, len);
    worst_rot = std::max(worst_rot, rot);
    worst_dir = std::max(worst_dir, dir);
  }
  const Eigen::Vector3d d_orig = (T_orig.front().inverse() * T_orig.back()).translation();
  const Eigen::Vector3d d_live = C_o_c * (T_live.front().inverse() * T_live.back()).translation();
  const double total = std::abs(d_live.norm() / d_orig.norm() - 1.0);
  const double end_gap = (d_live - d_orig).norm() / d_orig.norm();
  std::printf(
      "frames 0-10: displacement %.3f m, live %.3f m (%+.2f %%); end points %.3f m apart "
      "(%.2f %% of the displacement); worst pair: length %.2f %%, rotation %.4f deg, "
      "direction %.3f deg\n",
      d_orig.norm(), d_live.norm(), 100.0 * (d_live.norm() / d_orig.norm() - 1.0),
      (d_live - d_orig).norm(), 100.0 * end_gap, 100.0 * worst_len, worst_rot, worst_dir);
  // Drift against the ground truth (end-point error / GT path length, both trajectories in o's
  // axes from frame 0): the issue's criterion, live within 5 % of the original's. (Most of it is
  // KITTI's GT scale over these frames, see tests/pipeline/stereo_image_odometry_test.cpp.)
  auto gt = files::readKittiPoses(std::string(SUNVO_DATA_DIR) + "/kitti_odometry/00_gt_poses.txt");
  ASSERT_TRUE(gt.hasValue()) << gt.status().toString();
  const std::size_t last = T_orig.size() - 1;
  const Eigen::Vector3d d_gt = (gt->T_w_c[0].inverse() * gt->T_w_c[last]).translation();
  double gt_path = 0.0;
  for (std::size_t k = 1; k <= last; ++k) {
    gt_path += (gt->T_w_c[k - 1].inverse() * gt->T_w_c[k]).translation().norm();
  }
  const double drift_orig = (d_orig - d_gt).norm() / gt_path;
  const double drift_live = (d_live - d_gt).norm() / gt_path;
  std::printf("drift against GT over %.3f m: original %.3f %%, live %.3f %% (%+.2f %% of it)\n",
              gt_path, 100.0 * drift_orig, 100.0 * drift_live,
              100.0 * (drift_live / drift_orig - 1.0));
  EXPECT_LT(std::abs(drift_live / drift_orig - 1.0), 0.05);
  EXPECT_LT(worst_len, 0.05);
  EXPECT_LT(total, 0.05);
  EXPECT_LT(end_gap, 0.05);
  EXPECT_LT(worst_rot, 0.2);

  // The control: the raw frames without rectification, taken as an ideal pinhole pair with the
  // left lens's intrinsics and the true baseline, are well outside these bounds (or lost), so
  // the bounds above see the rectification.
  StereoCamera pinhole = fx.data.camera;
  pinhole.fu = rig.K_l(0, 0);
  pinhole.fv = rig.K_l(1, 1);
  pinhole.cu = rig.K_l(0, 2);
  pinhole.cv = rig.K_l(1, 2);
  std::vector<StereoFrame> raw;
  for (std::size_t k = 0; k < fx.raw_left.size(); ++k) {
    StereoFrame f;
    f.sequence = k;
    f.left = fx.raw_left[k];
    f.right = fx.raw_right[k];
    raw.push_back(f);
  }
  int lost_raw = 0;
  const std::vector<Isometry3> T_raw = runVo(pinhole, raw, &lost_raw);
  const double raw_len = worstLengthRatio(T_orig, T_raw);
  std::printf("control, raw frames unrectified: %d of %zu frames lost, worst pair length %.1f %%\n",
              lost_raw, raw.size(), 100.0 * raw_len);
  EXPECT_TRUE(lost_raw > 0 || raw_len > 0.05);
}

// YUYV cameras with source.v4l2.left_color: the left image reaches the slot in colour,
// rectified, and the colour Sun-CNN model (config/sun_cnn.onnx, 3 channels) runs on it; without
// left_color the model gets the grey image (its luma copied to the three channels).
TEST(RoverRectifiedVo, YuyvColourFeedsTheColourSunCnn) {
  testing::TempDir dir;
  auto data = testing::loadKittiFirstFrames();
  ASSERT_TRUE(data.hasValue()) << data.status().toString();
  StereoCamera cam = data->camera;
  cam.width = 1240;  // YUYV carries pixels in pairs
  const RawRig rig(cam);
  const std::string yaml = dir.file("rig.yaml");
  rig.writeOpenCvYaml(yaml);
  const cv::Rect even(0, 0, cam.width, cam.height);
  for (const bool colour : {false, true}) {
    emulated::EmulatedV4l2 cameras;
    ASSERT_TRUE(cameras
                    .addCamera({"/dev/sunvo-left", cam.width, cam.height, false, true, 0, 0,
                                emulated::imageSequence({data->frames[0].left(even).clone()})})
                    .isOk());
    ASSERT_TRUE(cameras
                    .addCamera({"/dev/sunvo-right", cam.width, cam.height, false, true, 0, 0,
                                emulated::imageSequence({data->frames[0].right(even).clone()})})
                    .isOk());
    RoverConfig config = liveConfig(yaml, rig.size);
    config.source.v4l2.pixel_format = v4l2::V4l2PixelFormat::kYuyv;
    config.source.v4l2.left_color = colour;
    config.sun.provider =
        SunProviderType::kSunCnn;  // colour is converted only for an image provider
    auto source = V4l2FrameSource::open(config, cameras, 0);
    ASSERT_TRUE(source.hasValue()) << source.status().toString();
    runtime::FrameSlot slot;
    const TriggerEvent ev{0, kT0, kT0};
    cameras.trigger(kT0 + kDelay);
    ASSERT_TRUE((*source)->grab(ev, slot).isOk());
    EXPECT_EQ(slot.frame.left_color.empty(), !colour);
    if (colour) {
      EXPECT_EQ(slot.frame.left_color.type(), CV_8UC3);
      EXPECT_EQ(slot.frame.left_color.size(), rig.size);
    }
    SunConfig sun;
    sun.provider = SunProviderType::kSunCnn;
    sun.model = std::string(SUNVO_SOURCE_DIR) + "/config/sun_cnn.onnx";
    auto provider = makeSunProvider(sun, (*source)->camera());
    ASSERT_TRUE(provider.hasValue()) << provider.status().toString();
    SunQuery q;
    q.images = &slot.frame;
    auto m = (*provider)->measure(q);  // the provider's path: no error, colour or grey
    ASSERT_TRUE(m.hasValue()) << "colour " << colour << ": " << m.status().toString();
    if (!colour) continue;
    // The colour image carries more than its luma to the network: its answer differs from the
    // grey image's (the emulator's chroma is not a sky's).
    auto cnn = sunestimators::makeSunEstimator("sun_cnn", sun.model);
    ASSERT_TRUE(cnn.hasValue()) << cnn.status().toString();
    const StereoCamera camera = (*source)->camera();
    auto from_colour = (*cnn)->estimate({slot.frame.left_color, camera, std::nullopt});
    auto from_grey = (*cnn)->estimate({slot.frame.left, camera, std::nullopt});
    ASSERT_TRUE(from_colour.hasValue()) << from_colour.status().toString();
    ASSERT_TRUE(from_grey.hasValue()) << from_grey.status().toString();
    std::printf("colour Sun-CNN azimuth: %.2f deg from the colour image, %.2f deg from grey\n",
                from_colour->azimuth_deg, from_grey->azimuth_deg);
    EXPECT_GT(std::abs(from_colour->azimuth_deg - from_grey->azimuth_deg), 0.01);
  }
}

// A PoseLink that keeps what RoverApp::create hands it before the stream starts.
class MountRecorder final : public PoseLink {
 public:
  Status sendPose(const PoseRecord&, TimeNs) override { return Status::ok(); }
  Status sendHeartbeat(TimeNs) override { return Status::ok(); }
  Status service(TimeNs) override { return Status::ok(); }
  bool drained() const override { return true; }
  TimeNs lastByteWrittenNs() const override { return 0; }
  std::string countersText() const override { return "mount recorder"; }
  void setCameraMount(const Isometry3& T_b_c) override {
    T_b_c_ = T_b_c;
    mounted_ = true;
  }
  Isometry3 T_b_c_ = Isometry3::Identity();
  bool mounted_ = false;
};

// The program's wiring (RoverApp::create from config/rover.yaml with a raw calibration): the
// estimator's camera is the rectified one, and the link gets T_b_c from body.* and the
// rectification's rotation.
TEST(RoverRectifiedVo, TheProgramRectifiesAndMountsTheCamera) {
  Fixture fx;
  fx.setUp();
  if (HasFatalFailure()) return;
  const std::string yaml = fx.dir.file("rig.yaml");
  emulated::EmulatedGpio gpio;
  ASSERT_TRUE(gpio.addChip("gpiochip0", 32).isOk());
  auto config = loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover.yaml",
                                {{"source.v4l2.calibration", yaml},
                                 {"frames.width", std::to_string(fx.data.camera.width)},
                                 {"frames.height", std::to_string(fx.data.camera.height)},
                                 {"body.camera_pitch_deg", "-15"},
                                 {"body.camera_x_m", "0.42"},
                                 {"body.camera_z_m", "-0.3"},
                                 {"serial.device", "\"\""},
                                 {"rt.lock_memory", "false"},
                                 {"rt.heap_reserve_mb", "0"},
                                 {"profiling.output_dir", fx.dir.file("out")}});
  ASSERT_TRUE(config.hasValue()) << config.status().toString();
  // The camera nodes are taken by the fixture's source: a second rig for the program.
  emulated::EmulatedV4l2 cameras;
  const cv::Size size(fx.data.camera.width, fx.data.camera.height);
  ASSERT_TRUE(cameras
                  .addCamera({"/dev/sunvo-left", size.width, size.height, true, false, 0, 0,
                              emulated::imageSequence(fx.raw_left)})
                  .isOk());
  ASSERT_TRUE(cameras
                  .addCamera({"/dev/sunvo-right", size.width, size.height, true, false, 0, 0,
                              emulated::imageSequence(fx.raw_right)})
                  .isOk());
  auto link = std::make_unique<MountRecorder>();
  MountRecorder* recorder = link.get();
  auto app = RoverApp::create(*config, std::move(link), RoverDevices{&cameras, &gpio});
  ASSERT_TRUE(app.hasValue()) << app.status().toString();
  ASSERT_TRUE(recorder->mounted_);
  const Isometry3 expected = bodyFromCamera(config->body, fx.source->C_c_l());
  EXPECT_TRUE(recorder->T_b_c_.isApprox(expected, 1e-12));
  EXPECT_TRUE(recorder->T_b_c_.translation().isApprox(Eigen::Vector3d(0.42, 0.0, -0.3)));
  // Not the unrectified mount: the rectification turned the camera.
  const Isometry3 raw_mount = bodyFromCamera(config->body, Eigen::Matrix3d::Identity());
  EXPECT_GT((recorder->T_b_c_.linear() - raw_mount.linear()).norm(), 1e-3);
  const std::string summary = (*app)->summary();
  char line[160];
  const StereoCamera& cam = fx.source->camera();
  std::snprintf(
      line, sizeof(line),
      "camera %dx%d: fu %.2f fv %.2f cu %.2f cv %.2f px, baseline %.4f m (rectified here)",
      cam.width, cam.height, cam.fu, cam.fv, cam.cu, cam.cv, cam.baseline_m);
  EXPECT_NE(summary.find(line), std::string::npos) << summary;
}

TEST(RoverRectifiedVo, RectifyingSourceAllocatesNothingPerFrame) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(runtime::allocCounterActive());
  Fixture fx;
  fx.setUp();
  if (HasFatalFailure()) return;
  runtime::FrameSlot slot;
  ASSERT_TRUE(fx.grab(0, slot).isOk());  // allocates the slot's Mats (the pool does it at start)
  std::uint64_t allocations = 0;
  for (std::uint64_t k = 1; k <= 50; ++k) {
    const TriggerEvent ev{k, kT0 + static_cast<TimeNs>(k) * kPeriod, 0};
    fx.cameras.trigger(ev.mono_ns + kDelay);  // the emulated kernel's work is not counted
    runtime::AllocationScope scope;
    const Status s = fx.source->grab(ev, slot);
    allocations += scope.count();
    ASSERT_TRUE(s.isOk()) << s.toString();
  }
  EXPECT_EQ(allocations, 0u);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::rover
