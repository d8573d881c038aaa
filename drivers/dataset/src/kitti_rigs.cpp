#include "sunvo/dataset/kitti_rigs.hpp"

#include <cstdlib>
#include <string>

namespace sunvo::dataset {

StereoCamera KittiRig::camera() const {
  StereoCamera c;
  c.fu = fu;
  c.fv = fu;
  c.cu = cu;
  c.cv = cv;
  c.baseline_m = -p1_tx / fu;
  c.width = width;
  c.height = height;
  return c;
}

namespace {
// 0..10 for "00".."10" (or "0".."10"); -1 otherwise.
int sequenceNumber(const std::string& sequence) {
  if (sequence.empty() || sequence.size() > 2) return -1;
  for (const char c : sequence) {
    if (c < '0' || c > '9') return -1;
  }
  const int n = std::atoi(sequence.c_str());
  return n <= 10 ? n : -1;
}
}  // namespace

std::optional<std::string> kittiOdometryDrive(const std::string& sequence) {
  static const char* const kDrives[11] = {
      "2011_10_03_drive_0027", "2011_10_03_drive_0042", "2011_10_03_drive_0034",
      "2011_09_26_drive_0067", "2011_09_30_drive_0016", "2011_09_30_drive_0018",
      "2011_09_30_drive_0020", "2011_09_30_drive_0027", "2011_09_30_drive_0028",
      "2011_09_30_drive_0033", "2011_09_30_drive_0034"};
  const int n = sequenceNumber(sequence);
  if (n < 0) return std::nullopt;
  return std::string(kDrives[n]);
}

namespace {
const KittiRig k1003{"2011_10_03", 718.856, 607.1928, 185.2157, -386.1448, 1241, 376};
const KittiRig k0926{"2011_09_26", 721.5377, 609.5593, 172.854, -387.5744, 1242, 375};
const KittiRig k0930{"2011_09_30", 707.0912, 601.8873, 183.1104, -379.8145, 1226, 370};
}  // namespace

std::optional<KittiRig> kittiRigOfDay(const std::string& name) {
  for (const KittiRig* rig : {&k1003, &k0926, &k0930}) {
    if (name.rfind(rig->date, 0) == 0) return *rig;
  }
  return std::nullopt;
}

std::optional<KittiRig> kittiOdometryRig(const std::string& sequence) {
  const int n = sequenceNumber(sequence);
  if (n >= 0 && n <= 2) return k1003;
  if (n == 3) return k0926;
  if (n >= 4 && n <= 10) return k0930;
  return std::nullopt;
}

}  // namespace sunvo::dataset
