// KITTI calibration files: calib_cam_to_cam.txt (raw), calib_imu_to_velo/velo_to_cam (rigid) and
// the odometry calib.txt, each parser on the same input; a parsed file must give finite matrices,
// and a stereo camera built from it must be usable or refused with an error.
#include <cmath>

#include "fuzz_support.hpp"
#include "sunvo/kitti/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("kitti_calibration", data, size);
  if (auto c = kitti::readCamToCam(path)) {
    for (const auto& cam : c->cameras) {
      fuzz::check(cam.P_rect.allFinite() && cam.R_rect.allFinite() && cam.K.allFinite(),
                  "cam_to_cam: non-finite matrix");
    }
    for (int left : {0, 2}) {
      if (auto s = kitti::rawStereoCamera(*c, left, left + 1)) {
        fuzz::check(std::isfinite(s->fu) && std::isfinite(s->baseline_m) && s->width > 0,
                    "rawStereoCamera: unusable camera accepted");
      }
    }
  }
  if (auto r = kitti::readRigidCalibration(path)) {
    fuzz::check(r->R.allFinite() && r->T.allFinite(), "rigid: non-finite");
    fuzz::check(r->transform().matrix().allFinite(), "rigid: non-finite transform");
  }
  if (auto o = kitti::readOdometryCalibration(path)) {
    if (auto s = kitti::odometryStereoCamera(*o, 0, 1, 1241, 376)) {
      fuzz::check(std::isfinite(s->fu) && std::isfinite(s->baseline_m),
                  "odometryStereoCamera: non-finite camera accepted");
    }
  }
  return 0;
}
