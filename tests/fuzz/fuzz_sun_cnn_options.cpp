// The Sun-CNN model's JSON (suncnn::loadSunCnnOptions, read beside every model): whatever the file
// holds, an answer without an exception or a crash, and options that pass their own validation.
#include "fuzz_support.hpp"
#include "sunvo/suncnn/sun_cnn_estimator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("sun_cnn_options", data, size);
  if (auto o = suncnn::loadSunCnnOptions(path)) {
    fuzz::check(o->validate().isOk(), "sun_cnn options: invalid options accepted");
  }
  return 0;
}
