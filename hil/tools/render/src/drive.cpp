#include "sunvo/render/drive.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "sunvo/kitti/oxts.hpp"
#include "sunvo/kitti/timestamps.hpp"
#include "sunvo/render/oxts_writer.hpp"
#include "sunvo/sun/spa.hpp"

namespace fs = std::filesystem;

namespace sunvo::render {
namespace {
constexpr double kPi = std::numbers::pi;

Status writeText(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) return ioError("cannot write " + path);
  f << text;
  if (!f) return ioError("write failed: " + path);
  return Status::ok();
}

std::optional<std::string> readText(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::nullopt;
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Writes a PNG under a temporary name and renames it: an image that exists is whole.
Status writePngAtomically(const std::string& path, const cv::Mat& img) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", img, bytes)) return ioError("cannot encode " + path);
  const std::string part = path + ".part";
  {
    std::ofstream f(part, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
    if (!f) return ioError("cannot write " + part);
  }
  std::error_code ec;
  fs::rename(part, path, ec);
  if (ec) return ioError("cannot rename " + part + " to " + path + ": " + ec.message());
  return Status::ok();
}

// The renderer's output format for a scenario: bump it with any change that renders the same
// scenario differently, so that a render is not resumed across it.
constexpr int kRenderFormat = 1;

// What a resumed render must share with the one it continues (renderDrive): the render format,
// the scenario's text, the camera and the render quality (the --frames override is not in it: a
// render may be extended).
std::string renderManifest(const Scenario& s) {
  char b[512];
  std::snprintf(b, sizeof b,
                "render format %d\ncamera %.9g %.9g %.9g %.9g %.9g %d %d\n"
                "quality %.9g %d %d\nscenario %zu bytes\n",
                kRenderFormat, s.camera.fu, s.camera.fv, s.camera.cu, s.camera.cv,
                s.camera.baseline_m, s.camera.width, s.camera.height, s.quality.antialias_threshold,
                s.quality.antialias_depth, s.quality.quality, s.source_text.size());
  return b + s.source_text;
}

std::string row3x4(const Isometry3& T) {
  std::string s;
  char b[32];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      std::snprintf(b, sizeof b, (r == 0 && c == 0) ? "%.9e" : " %.9e", T.matrix()(r, c));
      s += b;
    }
  s += "\n";
  return s;
}

}  // namespace

Isometry3 bodyFromCamera0() {
  Isometry3 T = Isometry3::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // columns: x_c = -y_b, y_c = -z_b, z_c = x_b
  T.translation() = Eigen::Vector3d(1.08, -0.32, 1.65);
  return T;
}

Isometry3 bodyFromVelodyne() {
  Isometry3 T = Isometry3::Identity();
  T.translation() = Eigen::Vector3d(0.81, -0.32, 1.73);
  return T;
}

FrameLighting computeLighting(const Eigen::Vector3d& sun_enu, const SkyOptions& sky,
                              double exposure_target) {
  FrameLighting f;
  const PerezSky model(sun_enu, sky);
  const double zs = std::acos(std::clamp(sun_enu.normalized().z(), -1.0, 1.0));
  Eigen::Vector3d E_sky_rgb;
  f.sky_illuminance_lux = model.horizontalIlluminanceLux(&E_sky_rgb);
  f.sun_normal_illuminance_lux = directSunIlluminanceLux(zs, sky.turbidity);
  // Auto-exposure: a Lambertian patch of albedo rho has radiance rho E / pi; the scale k makes
  // an albedo-0.25 patch lit by the sky and by the sun at an incidence of at most 60 deg
  // (E_ref = E_sky + E_sun max(cos z_s, 0.5)) read exposure_target (linear). The 60 deg floor
  // keeps a low sun from driving the exposure up until the sky saturates (facades facing a low
  // sun are lit almost normally).
  const double E_ref =
      f.sun_normal_illuminance_lux * std::max(std::cos(zs), 0.5) + f.sky_illuminance_lux;
  f.exposure_scale = exposure_target * kPi / (0.25 * std::max(E_ref, 1.0));
  // POV: colour = pigment (ambient_light + light cos); pigment = albedo rho, so the light colour
  // is k E_sun / pi and ambient k E_sky / pi. The ambient is the horizontal sky illuminance
  // times 0.8 (vertical faces see half the sky plus ground bounce; no radiosity).
  f.pov.sun_enu = sun_enu.normalized();
  f.pov.sun_rgb =
      f.exposure_scale * f.sun_normal_illuminance_lux / kPi * sunColour(zs, sky.turbidity);
  f.pov.ambient_rgb = 0.8 * f.exposure_scale * E_sky_rgb / kPi;
  f.sun_zenith_deg = zs * 180.0 / kPi;
  return f;
}

Eigen::Vector3d rightCameraErrorDeg(const RigErrorOptions& o, double progress) {
  const double t = std::clamp(progress, 0.0, 1.0);
  auto lerp = [t](double a, double b) { return a + t * (b - a); };
  return {lerp(o.right_roll_start_deg, o.right_roll_end_deg),
          lerp(o.right_pitch_start_deg, o.right_pitch_end_deg),
          lerp(o.right_yaw_start_deg, o.right_yaw_end_deg)};
}

Eigen::Matrix3d rightCameraTurn(const Eigen::Vector3d& roll_pitch_yaw_deg) {
  const Eigen::Vector3d rad = roll_pitch_yaw_deg * (kPi / 180.0);
  return (Eigen::AngleAxisd(rad.x(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rad.y(), Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(rad.z(), Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

Isometry3 rightCameraError(const RigErrorOptions& o, double progress) {
  Isometry3 T_c1nom_c1 = Isometry3::Identity();
  T_c1nom_c1.linear() = rightCameraTurn(rightCameraErrorDeg(o, progress));
  return T_c1nom_c1;
}

Status writeKittiCalibration(const std::string& dir, const StereoCamera& cam,
                             const CalibErrorOptions& err) {
  const double f_u = cam.fu * err.focal_scale, f_v = cam.fv * err.focal_scale;
  const double cu = cam.cu + err.cu_offset_px, cvv = cam.cv + err.cv_offset_px;
  const double b = cam.baseline_m * err.baseline_scale;
  char buf[512];
  std::string s = "calib_time: 01-Jan-2026 00:00:00\ncorner_dist: 9.950000e-02\n";
  for (int i = 0; i < 4; ++i) {
    // Cameras 2/3 (colour) are rendered from the same centres as 0/1 (documented).
    const double bi = (i == 1 || i == 3) ? b : 0.0;
    std::snprintf(buf, sizeof buf, "S_%02d: %.6e %.6e\n", i, static_cast<double>(cam.width),
                  static_cast<double>(cam.height));
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "K_%02d: %.6e 0.000000e+00 %.6e 0.000000e+00 %.6e %.6e 0.000000e+00 0.000000e+00 "
                  "1.000000e+00\n",
                  i, f_u, cu, f_v, cvv);
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "D_%02d: 0.000000e+00 0.000000e+00 0.000000e+00 0.000000e+00 0.000000e+00\n", i);
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "R_%02d: 1.000000e+00 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 "
                  "0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00\n",
                  i);
    s += buf;
    std::snprintf(buf, sizeof buf, "T_%02d: %.6e 0.000000e+00 0.000000e+00\n", i, -bi);
    s += buf;
    std::snprintf(buf, sizeof buf, "S_rect_%02d: %.6e %.6e\n", i, static_cast<double>(cam.width),
                  static_cast<double>(cam.height));
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "R_rect_%02d: 1.000000e+00 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 "
                  "0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00\n",
                  i);
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "P_rect_%02d: %.6e 0.000000e+00 %.6e %.6e 0.000000e+00 %.6e %.6e 0.000000e+00 "
                  "0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n",
                  i, f_u, cu, -f_u * bi, f_v, cvv);
    s += buf;
  }
  SUNVO_RETURN_IF_ERROR(writeText(dir + "/calib_cam_to_cam.txt", s));
  // calib_imu_to_velo: p_velo = R p_imu + T; IMU frame = body frame shifted to the IMU
  // (0.93 m above ground), axes equal.
  const Isometry3 T_b_v = bodyFromVelodyne(), T_b_c = bodyFromCamera0();
  Isometry3 T_b_imu = Isometry3::Identity();
  T_b_imu.translation() = Eigen::Vector3d(0, 0, 0.93);
  auto rt = [](const Isometry3& T) {
    std::string o = "R:";
    char b2[32];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        std::snprintf(b2, sizeof b2, " %.6e", T.linear()(r, c));
        o += b2;
      }
    o += "\nT:";
    for (int r = 0; r < 3; ++r) {
      std::snprintf(b2, sizeof b2, " %.6e", T.translation()(r));
      o += b2;
    }
    return o + "\n";
  };
  SUNVO_RETURN_IF_ERROR(
      writeText(dir + "/calib_imu_to_velo.txt",
                "calib_time: 01-Jan-2026 00:00:00\n" + rt(T_b_v.inverse() * T_b_imu)));
  SUNVO_RETURN_IF_ERROR(
      writeText(dir + "/calib_velo_to_cam.txt",
                "calib_time: 01-Jan-2026 00:00:00\n" + rt(T_b_c.inverse() * T_b_v) +
                    "delta_f: 0.000000e+00 0.000000e+00\ndelta_c: 0.000000e+00 0.000000e+00\n"));
  return Status::ok();
}

std::string kittiTimestamp(TimeNs t) {
  std::string s = formatUtcIso(t);  // YYYY-MM-DDTHH:MM:SS.fffffffffZ
  if (!s.empty() && s.back() == 'Z') s.pop_back();
  if (s.size() > 10 && s[10] == 'T') s[10] = ' ';
  return s;
}

Expected<std::string> renderDrive(const Scenario& s, const std::string& out_root, int jobs,
                                  const std::function<void(const DriveProgress&)>& progress,
                                  bool resume) {
  SUNVO_RETURN_IF_ERROR(s.validate());
  const DriveLook drive_look = drawDriveLook(s.style, s.city);
  const City city = generateCity(drive_look.city, s.seed, drive_look.city_look);
  auto route = generateRoute(city, s.route, s.frames, s.seed);
  if (!route) return route.status();
  const std::vector<MovingCar> traffic = generateTraffic(city, s.traffic, s.seed);
  const std::string iso = formatUtcIso(s.start_utc);
  const std::string date = iso.substr(0, 4) + "_" + iso.substr(5, 2) + "_" + iso.substr(8, 2);
  char drive_name[64];
  std::snprintf(drive_name, sizeof drive_name, "_drive_%04d_sync", s.drive_number);
  const std::string date_dir = out_root + "/" + date;
  const std::string drive_dir = date_dir + "/" + date + drive_name;
  const std::string pov_dir = drive_dir + "/pov", gt_dir = drive_dir + "/gt";
  std::error_code ec;
  const std::string manifest_path = drive_dir + "/render_manifest.txt";
  const std::string manifest = renderManifest(s);
  // Nothing to continue: a resumed render into a folder without this drive is a fresh one (a
  // script may always pass --resume).
  if (resume && !fs::exists(drive_dir, ec)) resume = false;
  ec.clear();
  if (resume) {
    const std::optional<std::string> old = readText(manifest_path);
    if (!old) {
      return failedPrecondition(drive_dir +
                                ": no render_manifest.txt, not a render this program can resume "
                                "(render it without resuming)");
    }
    if (*old != manifest) {
      return failedPrecondition(manifest_path +
                                ": another scenario, camera, quality or render format; render it "
                                "without resuming, or into another folder");
    }
  } else {
    // A fresh render: no image or scene of an earlier one may stay behind.
    for (int c = 0; c < 4; ++c) fs::remove_all(drive_dir + "/image_0" + std::to_string(c), ec);
    fs::remove_all(pov_dir, ec);
    fs::remove(manifest_path, ec);
    ec.clear();
  }
  for (int c = 0; c < 4; ++c)
    fs::create_directories(drive_dir + "/image_0" + std::to_string(c) + "/data", ec);
  fs::create_directories(pov_dir, ec);
  fs::create_directories(gt_dir, ec);
  if (ec) return ioError("cannot create " + drive_dir + ": " + ec.message());
  SUNVO_RETURN_IF_ERROR(writeText(manifest_path, manifest));
  SUNVO_RETURN_IF_ERROR(writeKittiCalibration(date_dir, s.camera, s.calib_error));
  SUNVO_RETURN_IF_ERROR(writeText(pov_dir + "/city.inc", povSceneBody(city.scene)));

  sun::SpaOptions spa;
  spa.latitude_deg = s.latitude_deg;
  spa.longitude_deg = s.longitude_deg;
  spa.elevation_m = s.altitude_m;
  const Isometry3 T_b_c0 = bodyFromCamera0();
  Isometry3 T_c0_c1 = Isometry3::Identity();
  T_c0_c1.translation() = Eigen::Vector3d(s.camera.baseline_m, 0, 0);
  const TimeNs dt_ns = static_cast<TimeNs>(std::llround(1e9 / s.route.rate_hz));
  // The city, the route and the POV-Ray scene live in the grid frame g (streets along x_g and
  // y_g, z up); the grid lies on the ground turned by place.grid_heading_deg from east:
  // T_enu_g = Rz(heading). The sun is turned into g for the lighting and the sky; everything
  // written (poses, sun in the camera, body states, OXTS) is in ENU.
  const double heading_rad = s.grid_heading_deg * kPi / 180.0;
  Isometry3 T_enu_g = Isometry3::Identity();
  T_enu_g.linear() = Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::string ts, poses, poses_enu,
      sun_c_csv = "frame,sx,sy,sz\n", sun_enu_csv = "frame,zenith_deg,azimuth_deg,e,n,u\n",
      body_csv = "frame,utc_ns,e,n,u,roll_rad,pitch_rad,yaw_rad,ve,vn,vu\n",
      rig_csv = "frame,right_roll_deg,right_pitch_deg,right_yaw_deg\n";
  std::vector<RenderJob> render_jobs;
  std::vector<int> job_frame;  // the frame of each render job
  std::size_t kept_frames = 0;
  std::vector<double> gains;
  std::vector<SensorOptions> frame_sensor;  // the look of each frame's camera
  FrameLook look;
  int look_period = -1;
  std::mt19937_64 exp_rng(s.seed * 7919 + 17);
  std::normal_distribution<double> N01(0.0, 1.0);
  double log_gain = 0.0;
  Isometry3 T_enu_c0_first = Isometry3::Identity();
  // The IMU: the body frame shifted 0.93 m up, axes equal (as calib_imu_to_velo.txt says).
  Isometry3 T_b_imu = Isometry3::Identity();
  T_b_imu.translation() = Eigen::Vector3d(0, 0, 0.93);
  std::vector<Isometry3> T_enu_imu_all;
  std::vector<Eigen::Vector3d> v_enu_all;
  std::vector<TimeNs> times_all;
  char buf[256];
  for (int k = 0; k < s.frames; ++k) {
    const VehicleState& vs = (*route)[static_cast<std::size_t>(k)];
    const TimeNs t = s.start_utc + k * dt_ns;
    auto sp = sun::computeSolarPosition(t, spa);
    if (!sp) return sp.status();
    const Isometry3& T_g_b = vs.T_enu_b;  // the route is generated in the grid frame
    const Isometry3 T_g_c0 = T_g_b * T_b_c0;
    const Isometry3 T_enu_c0 = T_enu_g * T_g_c0;
    const double drive_fraction = s.frames > 1 ? static_cast<double>(k) / (s.frames - 1) : 0.0;
    const Isometry3 T_g_c1 = T_g_c0 * T_c0_c1 * rightCameraError(s.rig_error, drive_fraction);
    const Eigen::Vector3d sun_g = T_enu_g.linear().transpose() * sp->sun_enu;
    if (k == 0) T_enu_c0_first = T_enu_c0;
    const int period = s.style.frames_per_look > 0 ? k / s.style.frames_per_look : 0;
    if (k == 0 || period != look_period) {
      look = drawFrameLook(s.style, period, s.sky, s.sensor);
      look_period = period;
    }
    frame_sensor.push_back(look.sensor);
    FrameLighting fl = computeLighting(sun_g, look.sky, look.sensor.exposure_target);
    fl.pov.sun_rgb = fl.pov.sun_rgb.cwiseProduct(look.sun_tint);
    fl.pov.ambient_rgb = look.ambient_scale * fl.pov.ambient_rgb.cwiseProduct(look.sky_tint);
    fl.pov.materials = look.materials;
    char name[64];
    std::snprintf(name, sizeof name, "sky_%06d.hdr", k);
    fl.pov.sky_image = name;
    const PerezSky sky(sun_g, look.sky);
    cv::Mat sky_img = sky.equirectangular(s.sky_image_width, s.sky_image_width / 2,
                                          fl.exposure_scale, Eigen::Vector3d(1500, 1500, 1500));
    if (s.style.seed != 0) {  // BGR channel order
      cv::multiply(sky_img, cv::Scalar(look.sky_tint.z(), look.sky_tint.y(), look.sky_tint.x()),
                   sky_img);
      styleSky(sky_img, look);
      addSunGlow(sky_img, sun_g, look, look.sensor.exposure_target);
    }
    if (!cv::imwrite(pov_dir + "/" + name, sky_img))
      return ioError("cannot write sky image " + std::string(name));
    std::snprintf(name, sizeof name, "frame_%06d.pov", k);
    const std::string pov_text =
        povFrame({s.camera, s.camera}, {T_g_c0, T_g_c1}, fl.pov, "city.inc", nullptr) +
        povPrimitives(trafficAt(traffic, vs.t_s, T_g_b.translation().head<2>(), s.traffic,
                                drive_look.city_look));
    // Resuming: a frame whose four images exist and whose scene is this one is kept.
    bool keep = resume && readText(pov_dir + "/" + name) == pov_text;
    for (int c = 0; c < 4 && keep; ++c) {
      std::snprintf(buf, sizeof buf, "/image_0%d/data/%010d.png", c, k);
      keep = fs::exists(drive_dir + buf, ec);
    }
    if (keep) ++kept_frames;
    if (!keep) SUNVO_RETURN_IF_ERROR(writeText(pov_dir + "/" + name, pov_text));
    for (int c = 0; c < 2 && !keep; ++c) {
      RenderJob j;
      j.work_dir = pov_dir;
      j.pov_file = name;
      char out[64];
      std::snprintf(out, sizeof out, "raw_%06d_%d.png", k, c);
      j.output_png = out;
      j.log_file = std::string(out) + ".log";
      j.width = s.camera.width;
      j.height = s.camera.height;
      j.cam_index = c;
      render_jobs.push_back(j);
      job_frame.push_back(k);
    }
    if (k > 0) log_gain = 0.9 * log_gain + s.sensor.exposure_sigma * N01(exp_rng);
    gains.push_back(std::exp(log_gain));
    ts += kittiTimestamp(t) + "\n";
    poses += row3x4(T_enu_c0_first.inverse() * T_enu_c0);
    poses_enu += row3x4(T_enu_c0);
    const Eigen::Vector3d sun_c = T_enu_c0.linear().transpose() * sp->sun_enu;
    std::snprintf(buf, sizeof buf, "%d,%.6f,%.6f,%.6f\n", k, sun_c.x(), sun_c.y(), sun_c.z());
    sun_c_csv += buf;
    std::snprintf(buf, sizeof buf, "%d,%.6f,%.6f,%.6f,%.6f,%.6f\n", k, sp->zenith_deg,
                  sp->azimuth_deg, sp->sun_enu.x(), sp->sun_enu.y(), sp->sun_enu.z());
    sun_enu_csv += buf;
    const Eigen::Vector3d p_imu = T_enu_g * T_g_b * Eigen::Vector3d(0, 0, 0.93);
    T_enu_imu_all.push_back(T_enu_g * T_g_b * T_b_imu);
    const Eigen::Vector3d v_enu = T_enu_g.linear() * vs.v_enu;
    v_enu_all.push_back(v_enu);
    const double yaw_enu = vs.yaw_rad + heading_rad;
    times_all.push_back(t);
    std::snprintf(buf, sizeof buf, "%d,%lld,%.4f,%.4f,%.4f,%.7f,%.7f,%.7f,%.4f,%.4f,%.4f\n", k,
                  static_cast<long long>(t), p_imu.x(), p_imu.y(), p_imu.z(), vs.roll_rad,
                  vs.pitch_rad, yaw_enu, v_enu.x(), v_enu.y(), v_enu.z());
    body_csv += buf;
    {
      const Eigen::Vector3d err_deg = rightCameraErrorDeg(s.rig_error, drive_fraction);
      std::snprintf(buf, sizeof buf, "%d,%.6f,%.6f,%.6f\n", k, err_deg.x(), err_deg.y(),
                    err_deg.z());
      rig_csv += buf;
    }
  }
  for (int c = 0; c < 4; ++c)
    SUNVO_RETURN_IF_ERROR(
        writeText(drive_dir + "/image_0" + std::to_string(c) + "/timestamps.txt", ts));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/poses_cam0.txt", poses));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/poses_cam0_enu.txt", poses_enu));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/sun_cam0.csv", sun_c_csv));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/sun_enu.csv", sun_enu_csv));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/body_enu.csv", body_csv));
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/rig_error.csv", rig_csv));
  std::snprintf(buf, sizeof buf, "%.9f %.9f %.3f\n", s.latitude_deg, s.longitude_deg, s.altitude_m);
  SUNVO_RETURN_IF_ERROR(writeText(gt_dir + "/origin.txt", buf));
  // OXTS records, as the GPS/INS of a KITTI drive would write them (times in UTC).
  {
    const geodesy::GeodeticPoint origin{s.latitude_deg, s.longitude_deg, s.altitude_m};
    auto records =
        oxtsFromEnuPoses(origin, T_enu_imu_all, v_enu_all, static_cast<double>(dt_ns) * 1e-9);
    if (!records) return records.status();
    std::filesystem::create_directories(drive_dir + "/oxts/data");
    for (std::size_t k = 0; k < records->size(); ++k) {
      SUNVO_RETURN_IF_ERROR(kitti::writeOxtsRecord(
          kitti::oxtsRecordPath(drive_dir, static_cast<std::int64_t>(k)), (*records)[k]));
    }
    SUNVO_RETURN_IF_ERROR(
        kitti::writeRawTimestamps(drive_dir + "/oxts/timestamps.txt", times_all, 0));
  }

  DriveProgress prog{0, render_jobs.size(), kept_frames};
  if (progress) progress(prog);
  Status post;
  const Status st =
      runPovrayJobs(render_jobs, s.quality, jobs, [&](std::size_t i, const Status& js) {
        ++prog.done;
        if (js.isOk() && post.isOk()) {
          const RenderJob& j = render_jobs[i];
          const int k = job_frame[i], c = j.cam_index;
          const std::string raw = j.work_dir + "/" + j.output_png;
          const cv::Mat img = cv::imread(raw, cv::IMREAD_COLOR);
          if (img.empty()) {
            post = ioError("cannot read povray output " + raw);
          } else {
            const cv::Mat sens = applySensor(
                img, frame_sensor[static_cast<std::size_t>(k)], gains[static_cast<std::size_t>(k)],
                s.camera.fu, s.camera.cu, s.camera.cv,
                s.seed * 1000003ULL + static_cast<std::uint64_t>(2 * k + c));
            cv::Mat gray;
            cv::cvtColor(sens, gray, cv::COLOR_BGR2GRAY);
            char fn[32];
            std::snprintf(fn, sizeof fn, "/data/%010d.png", k);
            post = writePngAtomically(drive_dir + "/image_0" + std::to_string(c) + fn, gray);
            if (post.isOk()) {
              post = writePngAtomically(drive_dir + "/image_0" + std::to_string(c + 2) + fn, sens);
            }
            fs::remove(raw, ec);
          }
        }
        if (progress) progress(prog);
      });
  SUNVO_RETURN_IF_ERROR(st);
  SUNVO_RETURN_IF_ERROR(post);
  return drive_dir;
}

}  // namespace sunvo::render
