// calib::readOpenCvStereo / readKalibrCamchain / detectFormat on small files written here: the
// values read back, the accepted spellings, and errors that name the file and the key.

#include "sunvo/calib/stereo_calibration.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "../support/temp_dir.hpp"

#ifdef SUNVO_HAVE_ALLOC_COUNTER
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::calib {
namespace {

using testing::TempDir;
using testing::writeText;

// A rig: right camera 0.12 m right of the left one, turned 1 deg about y.
const cv::Matx33d kK1(700, 0, 320, 0, 702, 240, 0, 0, 1);
const cv::Matx33d kK2(705, 0, 318, 0, 706, 243, 0, 0, 1);
const double kAngle = 1.0 * CV_PI / 180.0;
const cv::Matx33d kR(std::cos(kAngle), 0, std::sin(kAngle), 0, 1, 0, -std::sin(kAngle), 0,
                     std::cos(kAngle));
const cv::Vec3d kT(-0.12, 0.001, 0.002);

void writeOpenCv(const std::string& path, const char* k1_key, bool with_d2 = true) {
  cv::FileStorage fs(path, cv::FileStorage::WRITE);
  fs << k1_key << cv::Mat(kK1);
  fs << "D1" << (cv::Mat_<double>(1, 5) << -0.1, 0.02, 0.001, -0.002, 0.0);
  fs << "K2" << cv::Mat(kK2);
  if (with_d2) fs << "D2" << (cv::Mat_<double>(1, 5) << -0.11, 0.03, 0.0, 0.001, 0.0);
  fs << "R" << cv::Mat(kR) << "T" << cv::Mat(kT);
  fs << "image_width" << 640 << "image_height" << 480;
}

// YAML and JSON as cv::FileStorage writes them, read with yaml-cpp.
TEST(OpenCvStereo, ReadsWhatFileStorageWrote) {
  TempDir dir;
  for (const char* ext : {".yaml", ".json"}) {
    for (const char* key : {"K1", "M1", "cameraMatrix1"}) {
      const std::string path = dir.file(std::string("rig_") + key + ext);
      writeOpenCv(path, key);
      auto c = readOpenCvStereo(path);
      ASSERT_TRUE(c.hasValue()) << key << ext << ": " << c.status().toString();
      EXPECT_EQ(c->size, cv::Size(640, 480));
      EXPECT_EQ(c->model, DistortionModel::kRadTan);
      EXPECT_LT(cv::norm(c->K_left - kK1), 1e-12);
      EXPECT_LT(cv::norm(c->K_right - kK2), 1e-12);
      EXPECT_LT(cv::norm(c->C_r_l - kR), 1e-12);
      EXPECT_LT(cv::norm(c->t_r_l - kT), 1e-12);
      ASSERT_EQ(c->D_left.total(), 5u);
      EXPECT_DOUBLE_EQ(c->D_left.at<double>(0, 0), -0.1);
      EXPECT_DOUBLE_EQ(c->D_right.at<double>(0, 3), 0.001);
    }
  }
}

TEST(OpenCvStereo, ReadsHandWrittenListsAndFisheye) {
  TempDir dir;
  const std::string path = dir.file("rig.yml");
  writeText(path,  // no "%YAML" line: OpenCV alone would refuse it
            "M1: [700, 0, 320, 0, 702, 240, 0, 0, 1]\n"
            "D1: [0.01, -0.002, 0.0003, 0.0]\n"
            "M2: [705, 0, 318, 0, 706, 243, 0, 0, 1]\n"
            "D2: [0.02, -0.001, 0.0, 0.0001]\n"
            "R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
            "T: [-0.2, 0, 0]\n"
            "image_size: [1280, 720]\n"
            "distortion_model: fisheye\n");
  auto c = readOpenCvStereo(path);
  ASSERT_TRUE(c.hasValue()) << c.status().toString();
  EXPECT_EQ(c->size, cv::Size(1280, 720));
  EXPECT_EQ(c->model, DistortionModel::kEquidistant);
  EXPECT_DOUBLE_EQ(c->K_right(0, 2), 318.0);
  EXPECT_DOUBLE_EQ(c->t_r_l[0], -0.2);
  EXPECT_DOUBLE_EQ(c->D_right.at<double>(0, 3), 0.0001);
}

TEST(OpenCvStereo, ErrorsNameTheFileAndTheKey) {
  TempDir dir;
  const std::string missing = dir.file("no_d2.yaml");
  writeOpenCv(missing, "K1", /*with_d2=*/false);
  auto a = readOpenCvStereo(missing);
  ASSERT_FALSE(a.hasValue());
  EXPECT_NE(a.status().message().find("no_d2.yaml"), std::string::npos) << a.status().message();
  EXPECT_NE(a.status().message().find("D2"), std::string::npos) << a.status().message();

  const std::string base =
      "K1: [700, 0, 320, 0, 700, 240, 0, 0, 1]\n"
      "K2: [700, 0, 320, 0, 700, 240, 0, 0, 1]\n"
      "R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      "image_width: 640\nimage_height: 480\n";
  const std::string short_d = dir.file("short_d.yaml");
  writeText(short_d,
            "%YAML:1.0\n" + base + "D1: [0.1, 0.2, 0.3]\nD2: [0, 0, 0, 0, 0]\nT: [-0.1, 0, 0]\n");
  auto b = readOpenCvStereo(short_d);
  ASSERT_FALSE(b.hasValue());
  EXPECT_NE(
      b.status().message().find("short_d.yaml: D1: expected 4, 5, 8, 12 or 14 values, found 3"),
      std::string::npos)
      << b.status().message();

  const std::string mm = dir.file("mm.yaml");
  writeText(mm,
            "%YAML:1.0\n" + base + "D1: [0, 0, 0, 0, 0]\nD2: [0, 0, 0, 0, 0]\nT: [-120, 0, 0]\n");
  auto m = readOpenCvStereo(mm);
  ASSERT_FALSE(m.hasValue());
  EXPECT_NE(m.status().message().find("mm.yaml: T"), std::string::npos) << m.status().message();
  EXPECT_NE(m.status().message().find("millimetres"), std::string::npos);

  const std::string bad_r = dir.file("bad_r.yaml");
  writeText(bad_r, "%YAML:1.0\n" + std::string("K1: [700, 0, 320, 0, 700, 240, 0, 0, 1]\n") +
                       "K2: [700, 0, 320, 0, 700, 240, 0, 0, 1]\nR: [1, 0, 0, 0, 2, 0, 0, 0, 1]\n" +
                       "image_width: 640\nimage_height: 480\nD1: [0, 0, 0, 0]\nD2: [0, 0, 0, 0]\n" +
                       "T: [-0.1, 0, 0]\n");
  auto r = readOpenCvStereo(bad_r);
  ASSERT_FALSE(r.hasValue());
  EXPECT_NE(r.status().message().find("bad_r.yaml: R"), std::string::npos) << r.status().message();

  // A malformed matrix makes cv::FileStorage throw: an error, not an exception.
  const std::string bad_dt = dir.file("bad_dt.yaml");
  writeText(bad_dt,
            "%YAML:1.0\nK1: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: zz\n"
            "  data: [1, 2, 3]\n");
  auto dt = readOpenCvStereo(bad_dt);
  ASSERT_FALSE(dt.hasValue());
  EXPECT_NE(dt.status().message().find("bad_dt.yaml"), std::string::npos) << dt.status().message();

  auto none = readOpenCvStereo(dir.file("absent.yaml"));
  ASSERT_FALSE(none.hasValue());
  EXPECT_NE(none.status().message().find("absent.yaml"), std::string::npos);
}

std::string kalibrText(const std::string& cam1_intrinsics) {
  return "cam0:\n"
         "  camera_model: pinhole\n"
         "  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
         "  distortion_model: radtan\n"
         "  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"
         "  resolution: [752, 480]\n"
         "  rostopic: /cam0/image_raw\n"
         "cam1:\n"
         "  T_cn_cnm1:\n"
         "  - [0.9999972, -0.0023171, -0.0002343, -0.1100741]\n"
         "  - [0.0023174, 0.9999804, 0.0057808, 0.0003990]\n"
         "  - [0.0002209, -0.0057813, 0.9999832, -0.0008539]\n"
         "  - [0.0, 0.0, 0.0, 1.0]\n"
         "  camera_model: pinhole\n"
         "  intrinsics: " +
         cam1_intrinsics +
         "\n"
         "  distortion_model: radtan\n"
         "  distortion_coeffs: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]\n"
         "  resolution: [752, 480]\n";
}

TEST(KalibrCamchain, ReadsBothCamerasAndTheExtrinsics) {
  TempDir dir;
  const std::string path = dir.file("camchain.yaml");
  writeText(path, kalibrText("[457.587, 456.134, 379.999, 255.238]"));
  auto c = readKalibrCamchain(path);
  ASSERT_TRUE(c.hasValue()) << c.status().toString();
  EXPECT_EQ(c->size, cv::Size(752, 480));
  EXPECT_EQ(c->model, DistortionModel::kRadTan);
  EXPECT_DOUBLE_EQ(c->K_left(0, 0), 458.654);
  EXPECT_DOUBLE_EQ(c->K_left(1, 1), 457.296);
  EXPECT_DOUBLE_EQ(c->K_left(0, 2), 367.215);
  EXPECT_DOUBLE_EQ(c->K_right(1, 2), 255.238);
  EXPECT_DOUBLE_EQ(c->C_r_l(1, 2), 0.0057808);
  EXPECT_DOUBLE_EQ(c->t_r_l[0], -0.1100741);
  EXPECT_DOUBLE_EQ(c->t_r_l[2], -0.0008539);
  EXPECT_DOUBLE_EQ(c->D_right.at<double>(0, 1), 0.07451284);
  auto f = detectFormat(path, CalibrationFormat::kAuto);
  ASSERT_TRUE(f.hasValue());
  EXPECT_EQ(*f, CalibrationFormat::kKalibr);
  auto via = readRawStereoCalibration(path, CalibrationFormat::kAuto);
  ASSERT_TRUE(via.hasValue()) << via.status().toString();
  EXPECT_DOUBLE_EQ(via->K_right(0, 0), 457.587);
}

TEST(KalibrCamchain, ErrorsNameTheFileTheKeyAndTheLine) {
  TempDir dir;
  const std::string path = dir.file("short.yaml");
  writeText(path, kalibrText("[457.587, 456.134, 379.999]"));
  auto c = readKalibrCamchain(path);
  ASSERT_FALSE(c.hasValue());
  EXPECT_NE(c.status().message().find("short.yaml:15: cam1.intrinsics: expected 4 values, found 3"),
            std::string::npos)
      << c.status().message();
  const std::string no_cam1 = dir.file("mono.yaml");
  writeText(no_cam1, kalibrText("[1, 1, 1, 1]").substr(0, kalibrText("").find("cam1:")));
  auto m = readKalibrCamchain(no_cam1);
  ASSERT_FALSE(m.hasValue());
  EXPECT_NE(m.status().message().find("mono.yaml: cam1"), std::string::npos)
      << m.status().message();
}

// Whatever the file holds, both readers answer with a Status (no exception, no crash).
TEST(CalibrationReaders, GarbageIsAnErrorNotAnException) {
  TempDir dir;
  const std::string inputs[] = {
      "",
      "\x01\x02\xff\xfe binary",
      "- [1, 2]\n- 3\n",
      "%YAML:1.0\nK1: {a: 1}\n",
      "<?xml version=\"1.0\"?>\n<opencv_storage><K1>1 2",
      "cam0: [1, 2]\ncam1: 7\n",
      "cam0:\n  intrinsics: [a, b, c, d]\n",
      "{\"K1\": [1, 2, 3, 4, 5, 6, 7, 8, 9], \"D1\": \"x\"}",
      "%YAML:1.0\nK1: !!opencv-matrix\n  rows: 100000\n  cols: 100000\n  dt: d\n  data: [1]\n",
      // Found by fuzzing: FileStorage threw std::length_error out of the reader on this one,
      "%YAML:1.0\n---\nK0: !!opencv-matrix\n   rows: 3\n   cols: 3\n   :d td\n   data: [ ]\n"
      "K1: [ 0.02, -0.0003, 0.0002, 0.0]\nR: [1, 0, 0, 0, 11]\nimage_width: 64\n"
      "image_height: 48\n",
      // and its YAML parser never returned on bytes like these (not text: refused before it).
      "%YA\xb4\xff\xff\xff.0\n---\xff\xff\xff%YAML\xff\xff:1.0\n\xff\xff---\nK1: !!opencv-matrix\n"
      "   rows:\xff 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 322., 0., 501., 238., 0., 0., 1. "
      "]\n",
      // and on this one, whose only non-ASCII bytes are one well-formed UTF-8 character.
      "%Y5\n   dt:eAML:1.0\n--\n- K!1:!opencv-m., 0., 501. 5\n   dt:e_width: 64\xf2\x96\x92\x9e"
      "ge_height: 48\n ",
  };
  int k = 0;
  for (const std::string& text : inputs) {
    const std::string path = dir.file("garbage_" + std::to_string(k++) + ".yaml");
    writeText(path, text);
    auto a = readOpenCvStereo(path);
    auto b = readKalibrCamchain(path);
    EXPECT_FALSE(a.hasValue()) << text;
    EXPECT_FALSE(b.hasValue()) << text;
    EXPECT_NE(a.status().message().find("garbage_"), std::string::npos) << a.status().message();
    EXPECT_NE(b.status().message().find("garbage_"), std::string::npos) << b.status().message();
  }
}

// Found by fuzzing (fuzz_stereo_calibration, CI short run): in this file K1's header is damaged
// ("rows:distortio 3"), and OpenCV sized the matrix from it and asked for 48 GB (an
// out-of-memory abort under ASan). The reader now checks rows, cols and data before OpenCV reads
// the matrix. Without the allocation counter (sanitizer builds) the abort itself is the failure.
TEST(OpenCvStereo, ADamagedMatrixHeaderIsRefusedBeforeOpenCvSizesTheMatrix) {
  const std::string path =
      std::string(SUNVO_SOURCE_DIR) + "/tests/calib/data/fuzz_crash_matrix_header.yaml";
#ifdef SUNVO_HAVE_ALLOC_COUNTER
  const std::uint64_t before = runtime::allocatedBytes();
#endif
  const auto c = readOpenCvStereo(path);
  ASSERT_FALSE(c.hasValue());
  EXPECT_NE(c.status().message().find("fuzz_crash_matrix_header.yaml"), std::string::npos)
      << c.status().message();
#ifdef SUNVO_HAVE_ALLOC_COUNTER
  EXPECT_LT(runtime::allocatedBytes() - before, std::uint64_t{1} << 24);  // < 16 MiB
#endif
}

// Inputs on which OpenCV 4.6's YAML parser never returned (found by fuzzing, 2026-11-26): an
// indented first key followed by a line indented less, and a stream of "---" markers
// (tests/calib/data/fuzz_hang_document_markers.yaml). YAML no longer reaches that parser; each is
// an error naming the file. If it did, this test would hang and CTest's timeout would fail it.
TEST(OpenCvStereo, InputsThatMadeOpenCvsYamlParserLoopAreErrors) {
  TempDir dir;
  for (const char* text : {"%Y\n  A:1.0\n!-=\n\n--\n\n-.K1:1",
                           "%YAML:1.0\n---\n  A:1.0\n--\n\n-.K1:1", "  M1: [1, 0, 0]\nD1: [0]\n"}) {
    const std::string path = dir.file("loop.yml");
    writeText(path, text);
    const auto c = readOpenCvStereo(path);
    ASSERT_FALSE(c.hasValue()) << text;
    EXPECT_EQ(c.status().message().rfind("loop.yml: ", 0), 0u) << c.status().message();
  }
  const auto c = readOpenCvStereo(std::string(SUNVO_SOURCE_DIR) +
                                  "/tests/calib/data/fuzz_hang_document_markers.yaml");
  ASSERT_FALSE(c.hasValue());
  EXPECT_EQ(c.status().message().rfind("fuzz_hang_document_markers.yaml: line ", 0), 0u)
      << c.status().message();
}

// XML never reaches OpenCV's parser, which dereferenced a null pointer on a fuzzed file
// (tests/calib/data/fuzz_crash_xml_null_read.xml, 2026-11-26): an XML file, even one FileStorage
// wrote, is refused with a hint.
TEST(OpenCvStereo, AnXmlFileIsRefusedWithAHint) {
  TempDir dir;
  const std::string written = dir.file("rig.xml");
  writeOpenCv(written, "K1");
  for (const std::string& path : {written, std::string(SUNVO_SOURCE_DIR) +
                                               "/tests/calib/data/fuzz_crash_xml_null_read.xml"}) {
    const auto c = readOpenCvStereo(path);
    ASSERT_FALSE(c.hasValue()) << path;
    EXPECT_NE(c.status().message().find(": an OpenCV XML file; write the calibration as YAML"),
              std::string::npos)
        << c.status().message();
  }
}

// A YAML syntax error names the line of the file, counting OpenCV's "%YAML:1.0" line.
TEST(OpenCvStereo, AYamlSyntaxErrorNamesTheLine) {
  TempDir dir;
  const std::string path = dir.file("syntax.yaml");
  writeText(path, "%YAML:1.0\n---\nK1: [700, 0, 320, 0, 700, 240, 0, 0, 1]\nK2: [700, 0}\nR: 1\n");
  const auto c = readOpenCvStereo(path);
  ASSERT_FALSE(c.hasValue());
  EXPECT_EQ(c.status().message().rfind("syntax.yaml: line 4: ", 0), 0u) << c.status().message();
}

TEST(CalibrationFormat, DetectedByContent) {
  TempDir dir;
  const std::string kitti = dir.file("calib_cam_to_cam.txt");
  writeText(kitti, "calib_time: 09-Jan-2012 13:57:47\nP_rect_00: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  const std::string opencv = dir.file("stereo.yaml");
  writeOpenCv(opencv, "K1");
  EXPECT_EQ(*detectFormat(kitti, CalibrationFormat::kAuto), CalibrationFormat::kKitti);
  // The package's placeholder (config/debian/calib_cam_to_cam.txt) stays a KITTI file, so its
  // error is still the KITTI reader's.
  const std::string placeholder =
      std::string(SUNVO_SOURCE_DIR) + "/config/debian/calib_cam_to_cam.txt";
  EXPECT_EQ(*detectFormat(placeholder, CalibrationFormat::kAuto), CalibrationFormat::kKitti);
  EXPECT_EQ(*detectFormat(opencv, CalibrationFormat::kAuto), CalibrationFormat::kOpenCv);
  EXPECT_EQ(*detectFormat(opencv, CalibrationFormat::kKalibr), CalibrationFormat::kKalibr);
  auto raw = readRawStereoCalibration(kitti, CalibrationFormat::kAuto);
  ASSERT_FALSE(raw.hasValue());
  EXPECT_NE(raw.status().message().find("calib_cam_to_cam.txt"), std::string::npos);
}

}  // namespace
}  // namespace sunvo::calib
