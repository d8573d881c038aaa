// Trajectory files: KITTI poses (12 numbers a line), TUM (t x y z qx qy qz qw), times.txt and the
// format detection; parsed poses must be finite, with as many times as poses where times exist.
#include "fuzz_support.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/trajectory_io.hpp"

namespace {
void checkTrajectory(const sunvo::files::Trajectory& t, bool with_times) {
  for (const auto& T : t.T_w_c) sunvo::fuzz::check(T.matrix().allFinite(), "non-finite pose");
  if (with_times) sunvo::fuzz::check(t.t_ns.size() == t.T_w_c.size(), "times != poses");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string text(fuzz::asText(data, size));
  {
    auto f = files::TextFile::fromString("poses.txt", text);
    if (auto t = files::parseKittiPoses(f)) checkTrajectory(*t, false);
  }
  {
    auto f = files::TextFile::fromString("poses_tum.txt", text);
    if (auto t = files::parseTumTrajectory(f)) checkTrajectory(*t, true);
  }
  {
    auto f = files::TextFile::fromString("times.txt", text);
    (void)files::parseTimes(f);
  }
  {
    auto f = files::TextFile::fromString("any.txt", text);
    (void)files::detectTrajectoryFormat(f);
  }
  return 0;
}
