// Raw stereo calibrations (drivers/calib): the OpenCV stereo reader and the Kalibr camchain
// reader (both yaml-cpp) on the same input. Neither may throw or crash; a file either reader
// accepts must be finite and give a usable rectified camera or a refusal.
#include <cmath>
#include <filesystem>

#include "fuzz_support.hpp"
#include "sunvo/calib/rectifier.hpp"
#include "sunvo/calib/stereo_calibration.hpp"

namespace {

void checkAccepted(const sunvo::calib::RawStereoCalibration& c) {
  using sunvo::fuzz::check;
  check(cv::checkRange(cv::Mat(c.K_left)) && cv::checkRange(cv::Mat(c.K_right)) &&
            cv::checkRange(c.D_left) && cv::checkRange(c.D_right) &&
            cv::checkRange(cv::Mat(c.C_r_l)) && cv::checkRange(cv::Mat(c.t_r_l)),
        "raw calibration: non-finite value accepted");
  // Rectifying is costly for big images; the readers' own checks are what is fuzzed.
  if (c.size.area() > 640 * 480) return;
  if (auto r = sunvo::calib::StereoRectifier::create(c)) {
    const sunvo::StereoCamera& cam = (*r)->camera();
    check(std::isfinite(cam.fu) && cam.fu > 0.0 && std::isfinite(cam.baseline_m) &&
              cam.baseline_m > 0.0,
          "rectifier: unusable camera accepted");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("stereo_calibration", data, size);
  if (auto c = calib::readOpenCvStereo(path)) checkAccepted(*c);
  if (auto c = calib::readKalibrCamchain(path)) checkAccepted(*c);
  (void)calib::detectFormat(path, calib::CalibrationFormat::kAuto);
  return 0;
}
