// KITTI timestamps: raw image_0x/timestamps.txt and oxts/timestamps.txt (civil time with ns),
// odometry times.txt (seconds); parsed times are finite by type, this checks the parsers do not
// crash, overflow (UBSan) or read out of bounds on any text.
#include "fuzz_support.hpp"
#include "sunvo/kitti/timestamps.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("kitti_timestamps", data, size);
  if (auto t = kitti::readRawTimestamps(path, 7200)) {
    (void)t->size();
  }
  if (auto t = kitti::readOdometryTimes(path, 1'000'000'000)) {
    (void)t->size();
  }
  return 0;
}
