// sunvo_rig_truth_images: a rendered drive with its right camera's injected turn taken out of the
// right images (an oracle for diagnosis, issue 15; see rig_truth_images.hpp). Then
// `sunvo_replay --drive OUT ...` runs on the rectified drive.

#include <cstdio>
#include <sstream>
#include <string>

#include "sunvo/cli/cli.hpp"
#include "sunvo/rig_truth_images/rig_truth_images.hpp"

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_rig_truth_images";
  CLI::App app{"A rendered drive with the right camera's injected turn taken out of its images.",
               kProgram};
  std::string drive;
  std::string out;
  std::string axes_text = "roll,pitch,yaw";
  app.add_option("--drive", drive, "the drive (sunvo_render output)")->required();
  app.add_option("--out", out, "the folder to write (the drive's layout; must not hold the drive)")
      ->required();
  app.add_option("--axes", axes_text, "the angles to take out, comma separated (roll,pitch,yaw)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  sunvo::rigtruth::Axes axes{false, false, false};
  std::stringstream ss(axes_text);
  for (std::string a; std::getline(ss, a, ',');) {
    if (a == "roll") {
      axes.roll = true;
    } else if (a == "pitch") {
      axes.pitch = true;
    } else if (a == "yaw") {
      axes.yaw = true;
    } else {
      std::fprintf(stderr, "%s: --axes: '%s' is not roll, pitch or yaw\n", kProgram, a.c_str());
      return sunvo::cli::kExitUsage;
    }
  }
  int frames = 0;
  const sunvo::Status s = sunvo::rigtruth::writeNominalDrive(drive, out, axes, &frames);
  if (!s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.toString().c_str());
    return sunvo::cli::kExitFailure;
  }
  std::printf("wrote %s: %d frames, %s taken out of the right images\n", out.c_str(), frames,
              axes_text.c_str());
  return sunvo::cli::kExitOk;
}
