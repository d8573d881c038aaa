#pragma once
// The command line of the Google Benchmark executables: sunvo's convention (firmware_app/cli) for
// their own options; what CLI11 does not know goes on to Google Benchmark (--benchmark_filter=,
// --benchmark_format=, ...), and what neither knows is a usage error (exit 2). Header-only: only
// the executables that link Google Benchmark include it.

#include <benchmark/benchmark.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sunvo/bench/bench_support.hpp"
#include "sunvo/cli/cli.hpp"
#include "sunvo/runtime/alloc_counter.hpp"

namespace sunvo::bench {

// sunvo::cli::parse with the leftovers handed to benchmark::Initialize. nullopt: go on; else the
// exit code (help, version, usage error).
inline std::optional<int> parseWithBenchmarkFlags(CLI::App& app, int argc, char** argv) {
  app.allow_extras();
  app.footer("Options --benchmark_*=VALUE go to Google Benchmark (e.g. --benchmark_format=json).");
  if (auto code = cli::parse(app, argc, argv)) return code;
  std::vector<std::string> rest = app.remaining();
  std::vector<char*> bench_argv{argv[0]};
  for (std::string& arg : rest) bench_argv.push_back(arg.data());
  int bench_argc = static_cast<int>(bench_argv.size());
  benchmark::Initialize(&bench_argc, bench_argv.data());
  if (benchmark::ReportUnrecognizedArguments(bench_argc, bench_argv.data())) {
    return cli::kExitUsage;
  }
  return std::nullopt;
}

// The start of every benchmark program, after its options were added to app (addBenchOptions
// and its own): parses the command line, pins to config.cpu, checks the allocation counter and
// loads config.data into *frames. nullopt: go on; else the exit code (usage, or the failure
// named on stderr).
inline std::optional<int> startBenchmark(CLI::App& app, int argc, char** argv, const char* program,
                                         const BenchConfig& config, KittiFrames* frames) {
  if (auto code = parseWithBenchmarkFlags(app, argc, argv)) return code;
  auto loaded = prepareBenchmark(config, runtime::allocCounterActive());
  if (!loaded) return cli::fail(program, loaded.status());
  *frames = std::move(*loaded);
  return std::nullopt;
}

// Registers fn(state, args...) as a benchmark of exactly `frames` timed iterations, reported in
// wall-clock milliseconds (every sunvo benchmark times a fixed number of frames).
template <class Fn, class... Args>
void registerFrames(const char* name, int frames, Fn&& fn, Args&&... args) {
  benchmark::RegisterBenchmark(name, std::forward<Fn>(fn), std::forward<Args>(args)...)
      ->Iterations(frames)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

}  // namespace sunvo::bench
