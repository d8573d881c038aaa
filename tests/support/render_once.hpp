#pragma once
// A rendered drive shared by the tests of one build folder (test helper). ctest -j runs every
// test case in its own process: the first to get here renders, the others wait on an exclusive
// lock until it returns; `out/complete` names the drive once it is whole, so a later process (or
// run) takes it as it is.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "sunvo/render/drive.hpp"

namespace sunvo::testing {

// The drive's folder under `out` (rendered with 2 jobs), or empty when it could not be rendered.
// `probe`: a file inside the drive whose presence says a cached drive is still whole.
inline std::string renderOnce(const render::Scenario& scenario, const std::filesystem::path& out,
                              const std::string& probe) {
  namespace fs = std::filesystem;
  const fs::path done = out / "complete";
  fs::create_directories(out.parent_path());
  const int lock_fd = ::open((out.string() + ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock_fd < 0) return {};
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }  // closing releases the lock
  } unlock{lock_fd};
  if (::flock(lock_fd, LOCK_EX) != 0) return {};
  if (fs::exists(done)) {
    std::ifstream in(done);
    std::string drive;
    std::getline(in, drive);
    if (fs::exists(fs::path(drive) / probe)) return drive;
  }
  fs::remove_all(out);
  auto drive = render::renderDrive(scenario, out.string(), 2, {});
  if (!drive) return {};
  std::ofstream(done) << *drive << "\n";
  return *drive;
}

}  // namespace sunvo::testing
