// sunvo_render: renders a scenario into the KITTI raw layout.
//   sunvo_render --scenario config/scenarios/ci_short.yaml --out <dir> [-j N] [--frames N]
//                [--resume]
// Exit codes (firmware_app/cli): 0 ok, 2 a bad command line, 1 a scenario or render failure.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "sunvo/cli/cli.hpp"
#include "sunvo/render/drive.hpp"

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_render";
  std::string scenario, out;
  int jobs = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  int frames = -1;
  CLI::App app{"Renders a scenario (POV-Ray, physical sky, SPA sun) into the KITTI raw layout.",
               kProgram};
  app.add_option("--scenario", scenario, "the scenario YAML (config/scenarios/)")->required();
  app.add_option("--out", out, "output folder")->required();
  app.add_option("-j,--jobs", jobs, "parallel povray processes (default: the number of cores)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--frames", frames, "render only the first N frames of the scenario")
      ->check(CLI::Range(1, 10000000));
  bool resume = false;
  app.add_flag("--resume", resume,
               "continue a render that stopped part-way into the same --out: frames whose images "
               "exist and whose scene is unchanged are kept (the folder's render_manifest.txt must "
               "match the scenario; a drive not rendered yet is rendered whole)");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  auto s = sunvo::render::loadScenario(scenario);
  if (!s) return sunvo::cli::fail(kProgram, s.status());
  if (frames > 0) s->frames = frames;
  const auto t0 = std::chrono::steady_clock::now();
  bool told = false;
  auto r = sunvo::render::renderDrive(
      *s, out, jobs,
      [&](const sunvo::render::DriveProgress& p) {
        if (resume && !told) {
          std::fprintf(stderr, "sunvo_render: resuming: %zu of %d frames already rendered\n",
                       p.kept_frames, s->frames);
          told = true;
        }
        const double el =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double eta =
            p.done > 0 ? el / static_cast<double>(p.done) * static_cast<double>(p.total - p.done)
                       : 0.0;
        const int w = 30, filled = static_cast<int>(w * p.done / std::max<std::size_t>(p.total, 1));
        std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu renders  %.0fs elapsed  ETA %.0fs ", filled,
                     "##############################", w - filled, "", p.done, p.total, el, eta);
        if (p.done == p.total) std::fprintf(stderr, "\n");
      },
      resume);
  if (!r) {
    std::fputc('\n', stderr);
    return sunvo::cli::fail(kProgram, r.status());
  }
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "sunvo_render: %d frames in %.1f s (%.2f s/frame wall, -j %d) -> %s\n",
               s->frames, el, el / s->frames, jobs, r->c_str());
  return sunvo::cli::kExitOk;
}
