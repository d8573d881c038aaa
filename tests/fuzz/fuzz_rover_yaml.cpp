// sunvo_rover's YAML configuration (yaml-cpp and the fields() walk of every option struct): any
// text is loaded or refused with a Status; a loaded configuration validates and describes itself.
#include "fuzz_support.hpp"
#include "sunvo/rover/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  const std::string& path = fuzz::writeInput("rover_yaml", data, size);
  if (auto c = rover::loadRoverConfig(path)) {
    fuzz::check(c->validate().isOk(), "rover yaml: loaded config does not validate");
    (void)c->describe();
  }
  return 0;
}
