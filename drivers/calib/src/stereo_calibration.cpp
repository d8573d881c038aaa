#include "sunvo/calib/stereo_calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

namespace sunvo::calib {
namespace {

std::string fileName(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// "<file>: <key>: <what>".
Status keyError(const std::string& path, const std::string& key, const std::string& what) {
  return parseError(fileName(path) + ": " + key + ": " + what);
}

std::string countList(std::initializer_list<int> counts) {
  std::string s;
  std::size_t i = 0;
  for (const int c : counts) {
    if (i > 0) s += (i + 1 == counts.size()) ? " or " : ", ";
    s += std::to_string(c);
    ++i;
  }
  return s;
}

bool allFinite(const std::vector<double>& v) {
  for (const double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

cv::Matx33d toMatx33(const std::vector<double>& v) {
  cv::Matx33d m;
  for (int i = 0; i < 9; ++i) m.val[i] = v[static_cast<std::size_t>(i)];
  return m;
}

// --- OpenCV stereo files --------------------------------------------------------------------
// Read with yaml-cpp, never with cv::FileStorage: fuzzing found OpenCV 4.6's YAML reading fail
// six ways (four endless loops: 0xFF bytes, a UTF-8 character, an indented first key, a stream
// of "---" markers; a damaged matrix header asking for 48 GB; an escaped std::length_error) and
// its XML parser dereferencing a null pointer (docs/hardening.md). A guard per shape never closes
// such a family, so no calibration text reaches those parsers. YAML and JSON are read; XML is
// refused.

// Offset of the first byte that is not printable ASCII, tab, CR or LF, or npos. Calibration files
// are ASCII.
std::size_t firstNonText(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x7F || (c < 0x20 && c != '\t' && c != '\r' && c != '\n')) return i;
  }
  return std::string::npos;
}

// A matrix is checked before its data is read: rows and cols in [1, 64] (a calibration matrix or
// distortion vector is far smaller; a damaged header once made OpenCV ask for 48 GB) and data of
// rows x cols numbers.
constexpr int kMaxMatrixSide = 64;

// Appends the number a scalar node holds; false (nothing appended) for anything else.
bool appendNumber(const YAML::Node& n, std::vector<double>* out) {
  double v = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v)) return false;
  out->push_back(v);
  return true;
}

bool asInteger(const YAML::Node& n, int* v) {
  return n && n.IsScalar() && YAML::convert<int>::decode(n, *v);
}

// The numbers of a node, row-major: an !!opencv-matrix map (rows, cols, dt, data), a list (nested
// at most two deep: [[fx, 0, cx], ...]) or one number. False if the node holds anything else.
bool numbersOf(const YAML::Node& n, int depth, std::vector<double>* out) {
  if (n.IsMap()) {
    int r = 0, c = 0;
    const YAML::Node data = n["data"];
    if (!asInteger(n["rows"], &r) || !asInteger(n["cols"], &c) || !data || !data.IsSequence() ||
        r < 1 || r > kMaxMatrixSide || c < 1 || c > kMaxMatrixSide ||
        data.size() != static_cast<std::size_t>(r) * static_cast<std::size_t>(c)) {
      return false;
    }
    // OpenCV's one-channel element types; a matrix of another type is not a calibration.
    if (const YAML::Node dt = n["dt"];
        dt && !(dt.IsScalar() && dt.Scalar().size() == 1 &&
                std::string_view("ucwsifd").find(dt.Scalar()[0]) != std::string_view::npos)) {
      return false;
    }
    for (const YAML::Node& e : data) {
      if (!appendNumber(e, out)) return false;
    }
    return true;
  }
  if (n.IsSequence()) {
    if (depth >= 2) return false;
    for (const YAML::Node& e : n) {
      if (!numbersOf(e, depth + 1, out)) return false;
    }
    return true;
  }
  return appendNumber(n, out);
}

// The first of `names` present in root; empty if none.
std::string firstKey(const YAML::Node& root, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (root[n]) return n;
  }
  return {};
}

std::string spellings(std::initializer_list<const char*> names) {
  std::string s;
  for (const char* n : names) s += (s.empty() ? "" : " | ") + std::string(n);
  return s;
}

// Reads one of `names` with one of `counts` numbers.
Status readNumbers(const YAML::Node& root, const std::string& path,
                   std::initializer_list<const char*> names, std::initializer_list<int> counts,
                   std::vector<double>* out) {
  const std::string key = firstKey(root, names);
  if (key.empty()) return keyError(path, spellings(names), "missing");
  out->clear();
  if (!numbersOf(root[key], 0, out)) return keyError(path, key, "expected numbers");
  bool count_ok = false;
  for (const int c : counts) count_ok = count_ok || static_cast<int>(out->size()) == c;
  if (!count_ok) {
    return keyError(
        path, key,
        "expected " + countList(counts) + " values, found " + std::to_string(out->size()));
  }
  if (!allFinite(*out)) return keyError(path, key, "not finite");
  return Status::ok();
}

Status readImageSize(const YAML::Node& root, const std::string& path, cv::Size* size) {
  for (const auto& [w, h] :
       {std::pair<const char*, const char*>{"image_width", "image_height"}, {"width", "height"}}) {
    if (!root[w] && !root[h]) continue;
    int width = 0, height = 0;
    if (!asInteger(root[w], &width)) return keyError(path, w, "expected an integer");
    if (!asInteger(root[h], &height)) return keyError(path, h, "expected an integer");
    *size = cv::Size(width, height);
    return Status::ok();
  }
  std::vector<double> wh;
  const Status s = readNumbers(
      root, path,
      {"image_size", "imageSize", "size", "image_width + image_height", "width + height"}, {2},
      &wh);
  if (!s.isOk()) return s;
  *size = cv::Size(static_cast<int>(std::lround(wh[0])), static_cast<int>(std::lround(wh[1])));
  return Status::ok();
}

Status readModel(const std::string& path, const std::string& key, const std::string& name,
                 DistortionModel* model) {
  if (name == "radtan" || name == "plumb_bob" || name == "pinhole" ||
      name == "rational_polynomial") {
    *model = DistortionModel::kRadTan;
  } else if (name == "equidistant" || name == "fisheye") {
    *model = DistortionModel::kEquidistant;
  } else {
    return keyError(
        path, key, "'" + name + "' is not one of radtan, plumb_bob, pinhole, equidistant, fisheye");
  }
  return Status::ok();
}

cv::Mat rowOf(const std::vector<double>& v) {
  return cv::Mat(1, static_cast<int>(v.size()), CV_64F, const_cast<double*>(v.data())).clone();
}

// Every key of an OpenCV stereo file into c (may throw YAML::Exception).
Status readOpenCvFields(const YAML::Node& root, const std::string& path, RawStereoCalibration* c) {
  std::vector<double> v;
  SUNVO_RETURN_IF_ERROR(
      readNumbers(root, path, {"K1", "M1", "cameraMatrix1", "camera_matrix_left"}, {9}, &v));
  c->K_left = toMatx33(v);
  SUNVO_RETURN_IF_ERROR(
      readNumbers(root, path, {"K2", "M2", "cameraMatrix2", "camera_matrix_right"}, {9}, &v));
  c->K_right = toMatx33(v);
  if (const YAML::Node m = root["distortion_model"]; m) {
    if (!m.IsScalar()) return keyError(path, "distortion_model", "expected a name");
    SUNVO_RETURN_IF_ERROR(readModel(path, "distortion_model", m.Scalar(), &c->model));
  }
  SUNVO_RETURN_IF_ERROR(
      readNumbers(root, path, {"D1", "distCoeffs1", "dist_coeffs_left"}, {4, 5, 8, 12, 14}, &v));
  c->D_left = rowOf(v);
  SUNVO_RETURN_IF_ERROR(
      readNumbers(root, path, {"D2", "distCoeffs2", "dist_coeffs_right"}, {4, 5, 8, 12, 14}, &v));
  c->D_right = rowOf(v);
  SUNVO_RETURN_IF_ERROR(readNumbers(root, path, {"R"}, {9}, &v));
  c->C_r_l = toMatx33(v);
  SUNVO_RETURN_IF_ERROR(readNumbers(root, path, {"T"}, {3}, &v));
  c->t_r_l = cv::Vec3d(v[0], v[1], v[2]);
  return readImageSize(root, path, &c->size);
}

// --- Kalibr (yaml-cpp) -------------------------------------------------------------------------

std::string line(const YAML::Node& n) {
  return std::to_string(n.Mark().line + 1);
}

Status kalibrNumbers(const YAML::Node& cam, const std::string& path, const std::string& cam_name,
                     const char* key, std::size_t count, std::vector<double>* out) {
  const std::string full = cam_name + "." + key;
  const YAML::Node n = cam[key];
  if (!n) return keyError(path, full, "missing");
  out->clear();
  bool ok = n.IsSequence();
  for (std::size_t i = 0; ok && i < n.size(); ++i) {
    const YAML::Node e = n[i];
    if (e.IsSequence()) {
      for (std::size_t j = 0; ok && j < e.size(); ++j) ok = appendNumber(e[j], out);
    } else {
      ok = appendNumber(e, out);
    }
  }
  const std::string where = fileName(path) + ":" + line(n) + ": " + full;
  if (!ok) return parseError(where + ": expected a list of numbers");
  if (out->size() != count) {
    return parseError(where + ": expected " + std::to_string(count) + " values, found " +
                      std::to_string(out->size()));
  }
  if (!allFinite(*out)) return parseError(where + ": not finite");
  return Status::ok();
}

struct KalibrCamera {
  cv::Matx33d K = cv::Matx33d::eye();
  cv::Mat D;
  cv::Size size;
  DistortionModel model = DistortionModel::kRadTan;
};

Status readKalibrCamera(const YAML::Node& root, const std::string& path, const char* name,
                        KalibrCamera* out) {
  const YAML::Node cam = root[name];
  if (!cam || !cam.IsMap()) return keyError(path, name, "missing (or not a map)");
  const std::string prefix = std::string(name) + ".";
  if (const YAML::Node m = cam["camera_model"]; m) {
    if (!m.IsScalar() || m.as<std::string>() != "pinhole") {
      return keyError(path, prefix + "camera_model", "only pinhole is supported");
    }
  }
  std::vector<double> v;
  SUNVO_RETURN_IF_ERROR(kalibrNumbers(cam, path, name, "intrinsics", 4, &v));
  out->K = cv::Matx33d(v[0], 0, v[2], 0, v[1], v[3], 0, 0, 1);
  const YAML::Node model = cam["distortion_model"];
  if (!model || !model.IsScalar()) return keyError(path, prefix + "distortion_model", "missing");
  SUNVO_RETURN_IF_ERROR(
      readModel(path, prefix + "distortion_model", model.as<std::string>(), &out->model));
  SUNVO_RETURN_IF_ERROR(kalibrNumbers(cam, path, name, "distortion_coeffs", 4, &v));
  out->D = rowOf(v);
  SUNVO_RETURN_IF_ERROR(kalibrNumbers(cam, path, name, "resolution", 2, &v));
  out->size = cv::Size(static_cast<int>(std::lround(v[0])), static_cast<int>(std::lround(v[1])));
  return Status::ok();
}

}  // namespace

std::span<const std::string_view> enumNames(DistortionModel) {
  static constexpr std::string_view kNames[] = {"radtan", "equidistant"};
  return kNames;
}

std::span<const std::string_view> enumNames(CalibrationFormat) {
  static constexpr std::string_view kNames[] = {"auto", "kitti", "opencv", "kalibr"};
  return kNames;
}

Status RawStereoCalibration::validate() const {
  const std::string f = fileName(file);
  if (size.width < 16 || size.height < 16 || size.width > 8192 || size.height > 8192) {
    return invalidArgument(f + ": image size " + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + " is outside [16, 8192] px");
  }
  for (const auto* K : {&K_left, &K_right}) {
    const char* which = K == &K_left ? "left" : "right";
    if (!((*K)(0, 0) > 0.0 && (*K)(1, 1) > 0.0) || !cv::checkRange(cv::Mat(*K))) {
      return invalidArgument(f + ": " + which +
                             " intrinsics: focal lengths must be > 0 and finite");
    }
  }
  for (const cv::Mat* D : {&D_left, &D_right}) {
    const char* which = D == &D_left ? "left" : "right";
    const int n = static_cast<int>(D->total());
    const bool ok = model == DistortionModel::kEquidistant
                        ? n == 4
                        : (n == 4 || n == 5 || n == 8 || n == 12 || n == 14);
    if (!ok || !cv::checkRange(*D)) {
      return invalidArgument(
          f + ": " + which + " distortion: " + std::to_string(n) + " values is not a " +
          std::string(enumNames(model)[static_cast<int>(model)]) + " model (or not finite)");
    }
  }
  const cv::Matx33d should_be_eye = C_r_l * C_r_l.t();
  if (cv::norm(should_be_eye - cv::Matx33d::eye()) > 1e-4 || cv::determinant(C_r_l) < 0.0) {
    return invalidArgument(f + ": R: not a rotation matrix");
  }
  const double b = cv::norm(t_r_l);
  if (!(b > 1e-3 && b < 10.0)) {
    return invalidArgument(f + ": T: baseline " + std::to_string(b) +
                           " is outside (0.001, 10) m (millimetres? the file must give metres)");
  }
  return Status::ok();
}

Expected<RawStereoCalibration> readOpenCvStereo(const std::string& path) {
  RawStereoCalibration c;
  c.file = path;
  std::ifstream in(path, std::ios::binary);
  if (!in) return ioError(path + ": cannot open");
  std::ostringstream whole;
  whole << in.rdbuf();
  std::string text = whole.str();
  if (const std::size_t bad = firstNonText(text); bad != std::string::npos) {
    return parseError(fileName(path) + ": byte " + std::to_string(bad) +
                      " is not ASCII text (OpenCV calibration files are ASCII)");
  }
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text.compare(first, 5, "<?xml") == 0) {
    return parseError(fileName(path) +
                      ": an OpenCV XML file; write the calibration as YAML or JSON (the same keys; "
                      "cv::FileStorage writes YAML for a .yaml name)");
  }
  // OpenCV writes "%YAML:1.0", which is not a YAML directive; it becomes a comment, so line
  // numbers stay those of the file. A file without it is read the same way.
  if (first != std::string::npos && text.compare(first, 6, "%YAML:") == 0) text[first] = '#';
  try {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
      return parseError(fileName(path) + ": line " + std::to_string(e.mark.line + 1) +
                        ": not a readable OpenCV YAML file: " + e.msg);
    }
    if (!root.IsMap()) {
      return parseError(fileName(path) + ": not an OpenCV stereo file (no map of keys)");
    }
    SUNVO_RETURN_IF_ERROR(readOpenCvFields(root, path, &c));
  } catch (const std::exception& e) {
    // yaml-cpp's exceptions derive from std::runtime_error.
    return parseError(fileName(path) + ": not a readable OpenCV YAML file: " + e.what());
  }
  const Status s = c.validate();
  if (!s.isOk()) return s;
  return c;
}

Expected<RawStereoCalibration> readKalibrCamchain(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return ioError(path + ": cannot open");
  } catch (const YAML::Exception& e) {
    return parseError(fileName(path) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) return parseError(fileName(path) + ": not a Kalibr camchain (no map)");
  KalibrCamera left;
  KalibrCamera right;
  std::vector<double> T;
  try {
    SUNVO_RETURN_IF_ERROR(readKalibrCamera(root, path, "cam0", &left));
    SUNVO_RETURN_IF_ERROR(readKalibrCamera(root, path, "cam1", &right));
    SUNVO_RETURN_IF_ERROR(kalibrNumbers(root["cam1"], path, "cam1", "T_cn_cnm1", 16, &T));
  } catch (const YAML::Exception& e) {
    return parseError(fileName(path) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  } catch (const std::exception& e) {
    return parseError(fileName(path) + ": not a readable Kalibr camchain: " + e.what());
  }
  if (left.model != right.model) {
    return keyError(path, "cam1.distortion_model", "differs from cam0's");
  }
  if (left.size != right.size) return keyError(path, "cam1.resolution", "differs from cam0's");
  if (std::abs(T[12]) + std::abs(T[13]) + std::abs(T[14]) > 1e-9 || std::abs(T[15] - 1.0) > 1e-9) {
    return keyError(path, "cam1.T_cn_cnm1", "last row must be [0, 0, 0, 1]");
  }
  RawStereoCalibration c;
  c.file = path;
  c.size = left.size;
  c.model = left.model;
  c.K_left = left.K;
  c.K_right = right.K;
  c.D_left = left.D;
  c.D_right = right.D;
  c.C_r_l = cv::Matx33d(T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10]);
  c.t_r_l = cv::Vec3d(T[3], T[7], T[11]);
  const Status s = c.validate();
  if (!s.isOk()) return s;
  return c;
}

Expected<CalibrationFormat> detectFormat(const std::string& path, CalibrationFormat format) {
  if (format != CalibrationFormat::kAuto) return format;
  std::ifstream in(path);
  if (!in) return ioError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  const bool txt = path.size() >= 4 && path.compare(path.size() - 4, 4, ".txt") == 0;
  if (txt || s.find("P_rect_00") != std::string::npos) return CalibrationFormat::kKitti;
  const bool top_cam0 = s.rfind("cam0:", 0) == 0 || s.find("\ncam0:") != std::string::npos;
  if (top_cam0 && s.find("intrinsics") != std::string::npos) return CalibrationFormat::kKalibr;
  return CalibrationFormat::kOpenCv;
}

Expected<RawStereoCalibration> readRawStereoCalibration(const std::string& path,
                                                        CalibrationFormat format) {
  auto f = detectFormat(path, format);
  if (!f) return f.status();
  switch (*f) {
    case CalibrationFormat::kOpenCv:
      return readOpenCvStereo(path);
    case CalibrationFormat::kKalibr:
      return readKalibrCamchain(path);
    case CalibrationFormat::kKitti:
    case CalibrationFormat::kAuto:
      break;
  }
  return invalidArgument(path +
                         ": a KITTI calib_cam_to_cam.txt holds rectified cameras, not a raw "
                         "calibration");
}

}  // namespace sunvo::calib
