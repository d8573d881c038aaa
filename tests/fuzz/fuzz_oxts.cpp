// One OXTS record (oxts/data/NNNNNNNNNN.txt: 30 numbers on one line); a parsed record must be
// finite.
#include <cmath>

#include "fuzz_support.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/kitti/oxts.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  auto file = files::TextFile::fromString("oxts.txt", std::string(fuzz::asText(data, size)));
  if (auto r = kitti::parseOxtsRecord(file)) {
    fuzz::check(std::isfinite(r->lat) && std::isfinite(r->lon) && std::isfinite(r->alt) &&
                    std::isfinite(r->roll) && std::isfinite(r->pitch) && std::isfinite(r->yaw),
                "oxts: non-finite record accepted");
  }
  return 0;
}
