// Track folders: tracks.csv ("frame,landmark,uL,vL,uR,vR") for a few frames and the track
// calib.txt ("fu fv cu cv baseline_m"). The first input byte picks the number of frames (1..8);
// parsed observations must be finite and belong to the frames asked for.
#include <cmath>
#include <vector>

#include "fuzz_support.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/files/tracks_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  if (size == 0) return 0;
  const std::size_t frames = 1 + data[0] % 8;
  const std::string text(fuzz::asText(data + 1, size - 1));
  std::vector<TimeNs> times;
  for (std::size_t k = 0; k < frames; ++k) times.push_back(static_cast<TimeNs>(k) * 100'000'000);
  {
    auto f = files::TextFile::fromString("tracks.csv", text);
    if (auto t = files::parseTracks(f, times, 1226, 370)) {
      fuzz::check(t->size() == frames, "tracks: frame count");
      for (const auto& frame : *t) {
        for (const auto& o : frame.observations) {
          fuzz::check(std::isfinite(o.u_left) && std::isfinite(o.v_left) &&
                          std::isfinite(o.u_right) && std::isfinite(o.v_right),
                      "tracks: non-finite observation accepted");
        }
      }
    }
  }
  {
    auto f = files::TextFile::fromString("calib.txt", text);
    if (auto c = files::parseTrackCalib(f, 1226, 370)) {
      fuzz::check(std::isfinite(c->fu) && std::isfinite(c->baseline_m), "calib: non-finite");
    }
  }
  return 0;
}
