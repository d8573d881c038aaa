// sunvo_kitti_replay: reads a KITTI recording through KittiStereoSource and reports the rate.
//   sunvo_kitti_replay --root DIR [--layout auto|raw|odometry] [--utc-offset-s S]
//                      [--start-utc "YYYY-MM-DD HH:MM:SS[.f]"] [--color] [--paced]
//                      [--first N] [--last N] [--repeat R] [--list]
// --start-utc is the UTC time of times.txt's 0 (odometry layout); --utc-offset-s the zone offset of
// raw timestamps. Exit codes: 0 ok, 2 bad arguments or bad input.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "sunvo/kitti/stereo_source.hpp"

namespace {

constexpr const char* kUsage =
    "usage: sunvo_kitti_replay --root DIR [--layout auto|raw|odometry] [--utc-offset-s S]\n"
    "         [--start-utc \"YYYY-MM-DD HH:MM:SS[.f]\"] [--color] [--paced] [--first N]\n"
    "         [--last N] [--repeat R] [--list]\n";

bool parseInt64(const char* text, std::int64_t& out) {
  char* end = nullptr;
  const long long v = std::strtoll(text, &end, 10);
  if (end == text || *end != '\0') return false;
  out = v;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  sunvo::kitti::KittiSourceOptions options;
  std::int64_t repeat = 1;
  bool list = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool has_value = i + 1 < argc;
    std::int64_t v = 0;
    if (arg == "--root" && has_value) {
      options.root = argv[++i];
    } else if (arg == "--layout" && has_value) {
      const std::string_view l = argv[++i];
      if (l == "auto") {
        options.layout = sunvo::kitti::KittiLayout::kAuto;
      } else if (l == "raw") {
        options.layout = sunvo::kitti::KittiLayout::kRaw;
      } else if (l == "odometry") {
        options.layout = sunvo::kitti::KittiLayout::kOdometry;
      } else {
        std::fprintf(stderr, "--layout: '%s' is not auto, raw or odometry\n", argv[i]);
        return 2;
      }
    } else if (arg == "--utc-offset-s" && has_value && parseInt64(argv[i + 1], v)) {
      options.utc_offset_s = v;
      ++i;
    } else if (arg == "--start-utc" && has_value) {
      auto t = sunvo::parseCivilTime(argv[++i], 0);
      if (!t) {
        std::fprintf(stderr, "--start-utc: %s\n", t.status().message().c_str());
        return 2;
      }
      options.odometry_start_time_ns = *t;
    } else if (arg == "--first" && has_value && parseInt64(argv[i + 1], v)) {
      options.first_frame = v;
      ++i;
    } else if (arg == "--last" && has_value && parseInt64(argv[i + 1], v)) {
      options.last_frame = v;
      ++i;
    } else if (arg == "--repeat" && has_value && parseInt64(argv[i + 1], v) && v >= 1) {
      repeat = v;
      ++i;
    } else if (arg == "--color") {
      options.use_color = true;
    } else if (arg == "--paced") {
      options.pacing = sunvo::kitti::Pacing::kRecordedRate;
    } else if (arg == "--list") {
      list = true;
    } else {
      std::fprintf(stderr, "bad argument '%s'\n%s", argv[i], kUsage);
      return 2;
    }
  }

  using Clock = std::chrono::steady_clock;
  std::vector<double> rates;
  std::vector<double> open_ms;
  sunvo::StereoFrame frame;  // reused across runs: buffers allocated once
  std::int64_t frames_per_run = 0;
  for (std::int64_t r = 0; r < repeat; ++r) {
    const auto t_open = Clock::now();
    auto source = sunvo::kitti::KittiStereoSource::open(options);
    if (!source) {
      std::fprintf(stderr, "sunvo_kitti_replay: %s\n", source.status().message().c_str());
      return 2;
    }
    const auto t_start = Clock::now();
    open_ms.push_back(std::chrono::duration<double, std::milli>(t_start - t_open).count());
    std::int64_t n = 0;
    while (true) {
      const sunvo::Status s = source->next(frame);
      if (!s) {
        if (source->finished()) break;
        std::fprintf(stderr, "sunvo_kitti_replay: %s\n", s.message().c_str());
        return 2;
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
  return 0;
}
