// Sun CSV ("frame,sx,sy,sz" with a header): parsed vectors must be finite and of unit length
// within the tolerance asked for.
#include <cmath>

#include "fuzz_support.hpp"
#include "sunvo/files/sun_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("sun_csv", data, size);
  if (auto s = files::readSunCsv(path, 0.01)) {
    for (const auto& v : s->sun_c) {
      fuzz::check(v.allFinite() && std::abs(v.norm() - 1.0) <= 0.01 + 1e-12,
                  "sun csv: non-unit vector accepted");
    }
  }
  return 0;
}
