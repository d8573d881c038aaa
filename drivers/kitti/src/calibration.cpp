#include "sunvo/kitti/calibration.hpp"

#include <cmath>
#include <string_view>
#include <vector>

#include "sunvo/files/text_file.hpp"

namespace sunvo::kitti {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// One expected key of a "key: v1 v2 ..." calibration file.
struct KeySpec {
  std::string name;
  int count = 0;  // number of numeric values; -1 = free text (rest of the line)
  bool required = true;
  bool seen = false;
  std::array<double, 12> v{};  // the values, row-major
  std::string text;            // for count == -1
};

class KeyFile {
 public:
  void add(std::string name, int count, bool required = true) {
    KeySpec s;
    s.name = std::move(name);
    s.count = count;
    s.required = required;
    specs_.push_back(std::move(s));
  }

  // Parses every line; unknown keys (delta_f, delta_c, ...) are ignored, known keys must carry
  // exactly their number of values and appear once; required keys must be present.
  Status parse(files::TextFile& f) {
    std::string_view line;
    while (f.nextLine(line)) {
      if (files::isBlank(line)) continue;
      const std::size_t colon = line.find(':');
      if (colon == std::string_view::npos) return f.lineError("expected 'key: values'");
      const std::string_view key = trim(line.substr(0, colon));
      KeySpec* spec = find(key);
      if (spec == nullptr) continue;
      if (spec->seen) return f.error(key, "duplicate key");
      spec->seen = true;
      const std::string_view rest = line.substr(colon + 1);
      if (spec->count < 0) {
        spec->text = std::string(trim(rest));
        continue;
      }
      const auto fields = files::splitFields(rest);
      if (fields.size() != static_cast<std::size_t>(spec->count)) {
        return f.error(key, "expected " + std::to_string(spec->count) + " values, found " +
                                std::to_string(fields.size()));
      }
      for (std::size_t i = 0; i < fields.size(); ++i) {
        auto value = f.parseDouble(fields[i], spec->name + "[" + std::to_string(i) + "]");
        if (!value) return value.status();
        spec->v[i] = *value;
      }
    }
    for (const KeySpec& s : specs_) {
      if (s.required && !s.seen) return parseError(f.path() + ": missing key '" + s.name + "'");
    }
    return Status::ok();
  }

  // The spec named `name` (an empty one for a name never added).
  const KeySpec& get(std::string_view name) const {
    for (const KeySpec& s : specs_) {
      if (s.name == name) return s;
    }
    static const KeySpec kNone;
    return kNone;
  }

  template <int R, int C>
  Eigen::Matrix<double, R, C> matrix(std::string_view name) const {
    // Row-major in the file.
    Eigen::Matrix<double, R, C> M;
    const KeySpec& s = get(name);
    for (int r = 0; r < R; ++r) {
      for (int c = 0; c < C; ++c) M(r, c) = s.v[static_cast<std::size_t>(r * C + c)];
    }
    return M;
  }

 private:
  KeySpec* find(std::string_view name) {
    for (KeySpec& s : specs_) {
      if (s.name == name) return &s;
    }
    return nullptr;
  }
  std::vector<KeySpec> specs_;
};

// "P<i>" of an odometry calib.txt (appended, not operator+, to keep GCC 12's -Wrestrict quiet).
std::string projectionKey(int i) {
  std::string key("P");
  key.append(std::to_string(i));
  return key;
}

std::string cameraKey(const char* base, int camera) {
  return std::string(base) + (camera < 10 ? "_0" : "_") + std::to_string(camera);
}

// Both projections of a rectified pair map rectified cam0 coordinates to pixels:
// P_i = K_rect [I | t_i] with K_rect shared, so P_i(0,3) = fu * t_i.x. The right camera sits at
// +b along x of the left one, so t_right.x = t_left.x - b and b = (P_l(0,3) - P_r(0,3)) / fu.
Expected<StereoCamera> stereoFromProjections(const Matrix34& P_l, const Matrix34& P_r, int width,
                                             int height, const std::string& what) {
  const Eigen::Matrix3d K_l = P_l.leftCols<3>();
  const Eigen::Matrix3d K_r = P_r.leftCols<3>();
  if ((K_l - K_r).cwiseAbs().maxCoeff() > 1e-6 * std::max(1.0, K_l.cwiseAbs().maxCoeff())) {
    return invalidArgument(what +
                           ": left and right projections have different intrinsics; not a "
                           "rectified pair");
  }
  StereoCamera cam;
  cam.fu = P_l(0, 0);
  cam.fv = P_l(1, 1);
  cam.cu = P_l(0, 2);
  cam.cv = P_l(1, 2);
  cam.baseline_m = (P_l(0, 3) - P_r(0, 3)) / cam.fu;
  cam.width = width;
  cam.height = height;
  Status s = cam.validate();
  if (!s) return invalidArgument(what + ": " + s.message());
  return cam;
}

}  // namespace

Isometry3 RigidCalibration::transform() const {
  Matrix34 Rt;
  Rt.leftCols<3>() = R;
  Rt.col(3) = T;
  return isometryFrom3x4(Rt);
}

Expected<CamToCamCalibration> readCamToCam(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  KeyFile keys;
  keys.add("calib_time", -1);
  keys.add("corner_dist", 1);
  for (int c = 0; c < 4; ++c) {
    keys.add(cameraKey("S", c), 2);
    keys.add(cameraKey("K", c), 9);
    keys.add(cameraKey("D", c), 5);
    keys.add(cameraKey("R", c), 9);
    keys.add(cameraKey("T", c), 3);
    keys.add(cameraKey("S_rect", c), 2);
    keys.add(cameraKey("R_rect", c), 9);
    keys.add(cameraKey("P_rect", c), 12);
  }
  SUNVO_RETURN_IF_ERROR(keys.parse(*file));
  CamToCamCalibration out;
  out.calib_time = keys.get("calib_time").text;
  out.corner_dist = keys.get("corner_dist").v[0];
  for (int c = 0; c < 4; ++c) {
    RawCameraCalibration& cam = out.cameras[static_cast<std::size_t>(c)];
    cam.S = keys.matrix<2, 1>(cameraKey("S", c));
    cam.K = keys.matrix<3, 3>(cameraKey("K", c));
    cam.D = keys.matrix<5, 1>(cameraKey("D", c));
    cam.R = keys.matrix<3, 3>(cameraKey("R", c));
    cam.T = keys.matrix<3, 1>(cameraKey("T", c));
    cam.S_rect = keys.matrix<2, 1>(cameraKey("S_rect", c));
    cam.R_rect = keys.matrix<3, 3>(cameraKey("R_rect", c));
    cam.P_rect = keys.matrix<3, 4>(cameraKey("P_rect", c));
  }
  return out;
}

Expected<RigidCalibration> readRigidCalibration(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  KeyFile keys;
  keys.add("calib_time", -1, /*required=*/false);
  keys.add("R", 9);
  keys.add("T", 3);
  SUNVO_RETURN_IF_ERROR(keys.parse(*file));
  RigidCalibration out;
  out.calib_time = keys.get("calib_time").text;
  out.R = keys.matrix<3, 3>("R");
  out.T = keys.matrix<3, 1>("T");
  const double det = out.R.determinant();
  if (std::abs(det - 1.0) > 1e-3 ||
      (out.R * out.R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3) {
    return parseError(path + ": key 'R' is not a rotation matrix");
  }
  return out;
}

Expected<RawCalibration> readRawCalibration(const std::string& dir) {
  RawCalibration out;
  auto c2c = readCamToCam(dir + "/calib_cam_to_cam.txt");
  if (!c2c) return c2c.status();
  out.cam_to_cam = std::move(*c2c);
  auto imu = readRigidCalibration(dir + "/calib_imu_to_velo.txt");
  if (!imu) return imu.status();
  out.imu_to_velo = std::move(*imu);
  auto velo = readRigidCalibration(dir + "/calib_velo_to_cam.txt");
  if (!velo) return velo.status();
  out.velo_to_cam = std::move(*velo);
  return out;
}

Expected<StereoCamera> rawStereoCamera(const CamToCamCalibration& calib, int left, int right) {
  if (left < 0 || left > 3 || right < 0 || right > 3 || left == right) {
    return invalidArgument("rawStereoCamera: camera indices must be two different values in 0..3");
  }
  const RawCameraCalibration& l = calib.cameras[static_cast<std::size_t>(left)];
  const RawCameraCalibration& r = calib.cameras[static_cast<std::size_t>(right)];
  const double w = l.S_rect.x();
  const double h = l.S_rect.y();
  if (w < 1.0 || h < 1.0 || w != std::floor(w) || h != std::floor(h) || w > 1e5 || h > 1e5) {
    return invalidArgument(cameraKey("S_rect", left) + ": not a valid image size");
  }
  return stereoFromProjections(l.P_rect, r.P_rect, static_cast<int>(w), static_cast<int>(h),
                               cameraKey("P_rect", left) + "/" + cameraKey("P_rect", right));
}

Expected<OdometryCalibration> readOdometryCalibration(const std::string& path) {
  auto file = files::TextFile::open(path);
  if (!file) return file.status();
  KeyFile keys;
  for (int i = 0; i < 4; ++i) keys.add(projectionKey(i), 12);
  keys.add("Tr", 12, /*required=*/false);
  SUNVO_RETURN_IF_ERROR(keys.parse(*file));
  OdometryCalibration out;
  for (std::size_t i = 0; i < 4; ++i)
    out.P[i] = keys.matrix<3, 4>(projectionKey(static_cast<int>(i)));
  if (keys.get("Tr").seen) out.T_cam0_velo = isometryFrom3x4(keys.matrix<3, 4>("Tr"));
  return out;
}

Expected<StereoCamera> odometryStereoCamera(const OdometryCalibration& calib, int left, int right,
                                            int width, int height) {
  if (left < 0 || left > 3 || right < 0 || right > 3 || left == right) {
    return invalidArgument(
        "odometryStereoCamera: camera indices must be two different values in 0..3");
  }
  return stereoFromProjections(calib.P[static_cast<std::size_t>(left)],
                               calib.P[static_cast<std::size_t>(right)], width, height,
                               projectionKey(left) + "/" + projectionKey(right));
}

}  // namespace sunvo::kitti
