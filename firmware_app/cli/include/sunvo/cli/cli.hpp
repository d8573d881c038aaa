#pragma once
// One command-line convention for every sunvo program (CLI11 from Debian):
//   --help and --version answer on stdout and exit 0;
//   a usage error (unknown option, missing or mistyped value, value out of range) prints the
//   reason and a hint to stderr and exits 2;
//   a runtime failure (a file that does not parse, a device that fails) exits 1 (fail()).
//
//   CLI::App app{"what the program does", "sunvo_x"};
//   app.add_option("--frames", frames, "...")->check(CLI::Range(0, 1000000));
//   if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
//   ...
//   if (!status.isOk()) return sunvo::cli::fail("sunvo_x", status);

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "sunvo/core/status.hpp"

namespace sunvo::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // runtime failure
inline constexpr int kExitUsage = 2;    // bad command line

// Adds --version and parses. nullopt: go on; else the exit code (help, version, usage error).
std::optional<int> parse(CLI::App& app, int argc, char** argv);

// Prints "<program>: <status>" to stderr and returns kExitFailure.
int fail(const std::string& program, const Status& status);
int fail(const std::string& program, const std::string& message);

// The project version, e.g. "0.1.0".
const char* version();

}  // namespace sunvo::cli
