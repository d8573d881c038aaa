// sunvo_render: renders a scenario into the KITTI raw layout.
//   sunvo_render --scenario config/scenarios/ci_short.yaml --out <dir> [-j N] [--frames N]
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "sunvo/render/drive.hpp"

int main(int argc, char** argv) {
  std::string scenario, out;
  int jobs = static_cast<int>(std::thread::hardware_concurrency());
  int frames = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--scenario")
      scenario = next();
    else if (a == "--out")
      out = next();
    else if (a == "-j")
      jobs = std::atoi(next().c_str());
    else if (a == "--frames")
      frames = std::atoi(next().c_str());
    else {
      std::fprintf(stderr, "usage: %s --scenario FILE.yaml --out DIR [-j N] [--frames N]\n",
                   argv[0]);
      return 2;
    }
  }
  if (scenario.empty() || out.empty()) {
    std::fprintf(stderr, "usage: %s --scenario FILE.yaml --out DIR [-j N] [--frames N]\n", argv[0]);
    return 2;
  }
  auto s = sunvo::render::loadScenario(scenario);
  if (!s) {
    std::fprintf(stderr, "sunvo_render: %s\n", s.status().toString().c_str());
    return 1;
  }
  if (frames > 0) s->frames = frames;
  if (jobs < 1) jobs = 1;
  const auto t0 = std::chrono::steady_clock::now();
  auto r = sunvo::render::renderDrive(*s, out, jobs, [&](const sunvo::render::DriveProgress& p) {
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double eta =
        p.done > 0 ? el / static_cast<double>(p.done) * static_cast<double>(p.total - p.done) : 0.0;
    const int w = 30, filled = static_cast<int>(w * p.done / std::max<std::size_t>(p.total, 1));
    std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu renders  %.0fs elapsed  ETA %.0fs ", filled,
                 "##############################", w - filled, "", p.done, p.total, el, eta);
    if (p.done == p.total) std::fprintf(stderr, "\n");
  });
  if (!r) {
    std::fprintf(stderr, "\nsunvo_render: %s\n", r.status().toString().c_str());
    return 1;
  }
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "sunvo_render: %d frames in %.1f s (%.2f s/frame wall, -j %d) -> %s\n",
               s->frames, el, el / s->frames, jobs, r->c_str());
  return 0;
}
