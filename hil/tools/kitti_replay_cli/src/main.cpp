// sunvo_kitti_replay: reads a KITTI recording through KittiStereoSource and reports the rate.
//   sunvo_kitti_replay --root DIR [--layout auto|raw|odometry] [--utc-offset-s S]
//                      [--start-utc "YYYY-MM-DD HH:MM:SS[.f]"] [--color] [--paced]
//                      [--first N] [--last N] [--repeat R] [--list]
// --start-utc is the UTC time of times.txt's 0 (odometry layout); --utc-offset-s the zone offset of
// raw timestamps. Exit codes (firmware_app/cli): 0 ok, 2 a bad command line, 1 a recording that
// cannot be read.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/kitti/stereo_source.hpp"

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_kitti_replay";
  sunvo::kitti::KittiSourceOptions options;
  std::int64_t repeat = 1;
  std::int64_t utc_offset_s = 0;
  std::string layout = "auto";
  std::string start_utc;
  bool list = false;
  bool paced = false;
  CLI::App app{
      "Reads a KITTI recording (raw drive or odometry sequence) through the file-backed "
      "stereo source; lists the frames and measures the read rate.",
      kProgram};
  app.add_option("--root", options.root, "the drive or sequence folder")->required();
  app.add_option("--layout", layout, "folder layout (auto: by image_00/ or image_0/)")
      ->check(CLI::IsMember({"auto", "raw", "odometry"}));
  app.add_option("--utc-offset-s", utc_offset_s, "zone offset of raw timestamps to UTC, s")
      ->check(CLI::Range(-50400L, 50400L));
  app.add_option("--start-utc", start_utc,
                 "UTC time of times.txt's 0 (odometry layout), \"YYYY-MM-DD HH:MM:SS[.f]\"")
      ->check(CLI::Validator(
          [](std::string& text) {
            auto t = sunvo::parseCivilTime(text, 0);
            return t ? std::string() : t.status().message();
          },
          "UTC"));
  app.add_flag("--color", options.use_color, "read the colour cameras (image_02/03)");
  app.add_flag("--paced", paced, "deliver frames at the recorded rate");
  app.add_option("--first", options.first_frame, "first frame index")
      ->check(CLI::Range(0L, 100000000L));
  app.add_option("--last", options.last_frame, "last frame index, inclusive (-1: the last)")
      ->check(CLI::Range(-1L, 100000000L));
  app.add_option("--repeat", repeat, "read the recording this many times")
      ->check(CLI::Range(1L, 1000000L));
  app.add_flag("--list", list, "print index, UTC time and size of every frame");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  options.layout = layout == "raw"        ? sunvo::kitti::KittiLayout::kRaw
                   : layout == "odometry" ? sunvo::kitti::KittiLayout::kOdometry
                                          : sunvo::kitti::KittiLayout::kAuto;
  if (app.count("--utc-offset-s") > 0) options.utc_offset_s = utc_offset_s;
  if (!start_utc.empty()) options.odometry_start_time_ns = *sunvo::parseCivilTime(start_utc, 0);
  if (paced) options.pacing = sunvo::kitti::Pacing::kRecordedRate;
  if (const sunvo::Status s = options.validate(); !s.isOk()) {
    std::fprintf(stderr, "%s: %s\n", kProgram, s.message().c_str());
    return sunvo::cli::kExitUsage;
  }

  using Clock = std::chrono::steady_clock;
  std::vector<double> rates;
  std::vector<double> open_ms;
  sunvo::StereoFrame frame;  // reused across runs: buffers allocated once
  std::int64_t frames_per_run = 0;
  for (std::int64_t r = 0; r < repeat; ++r) {
    const auto t_open = Clock::now();
    auto source = sunvo::kitti::KittiStereoSource::open(options);
    if (!source) return sunvo::cli::fail(kProgram, source.status().message());
    const auto t_start = Clock::now();
    open_ms.push_back(std::chrono::duration<double, std::milli>(t_start - t_open).count());
    std::int64_t n = 0;
    while (true) {
      const sunvo::Status s = source->next(frame);
      if (!s) {
        if (source->finished()) break;
        return sunvo::cli::fail(kProgram, s.message());
      }
      if (list && r == 0) {
        std::printf("%llu %s %dx%d\n", static_cast<unsigned long long>(frame.sequence),
                    sunvo::formatUtcIso(frame.trigger_time_ns).c_str(), frame.left.cols,
                    frame.left.rows);
      }
      ++n;
    }
    const double s = std::chrono::duration<double>(Clock::now() - t_start).count();
    rates.push_back(static_cast<double>(n) / s);
    frames_per_run = n;
  }
  if (rates.empty()) return sunvo::cli::fail(kProgram, "no run");  // --repeat >= 1
  double mean = 0.0, lo = rates.front(), hi = rates.front(), open_mean = 0.0;
  for (double x : rates) {
    mean += x / static_cast<double>(rates.size());
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  for (double x : open_ms) open_mean += x / static_cast<double>(open_ms.size());
  std::printf(
      "frames/run %lld, runs %lld: %.1f frames/s mean (min %.1f, max %.1f); open %.2f ms "
      "mean\n",
      static_cast<long long>(frames_per_run), static_cast<long long>(repeat), mean, lo, hi,
      open_mean);
  return sunvo::cli::kExitOk;
}
