#pragma once
// Shared pieces of the libFuzzer harnesses (tests/fuzz, built with SUNVO_FUZZ=ON, preset fuzz).
// The parsers that read a path get the input through a file of their own in /dev/shm (tmpfs, so
// an execution costs no disk I/O); the others get it through files::TextFile::fromString.
// A harness checks what a parser promises on success (finite numbers, sizes) and traps when a
// promise is broken, so libFuzzer reports it as a crash like a sanitizer finding.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace sunvo::fuzz {

inline std::string_view asText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Writes the input into this process's file for `name` and returns its path.
inline const std::string& writeInput(const char* name, const std::uint8_t* data, std::size_t size) {
  static const std::string path = [name] {
    const std::filesystem::path dir = std::filesystem::exists("/dev/shm")
                                          ? std::filesystem::path("/dev/shm")
                                          : std::filesystem::temp_directory_path();
    return (dir / ("sunvo_fuzz_" + std::string(name) + "_" + std::to_string(::getpid()))).string();
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

// A broken promise of a parser: stops the run with the reason on stderr.
inline void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "sunvo fuzz: broken promise: %s\n", what);
    __builtin_trap();
  }
}

}  // namespace sunvo::fuzz
