// sunvo_eval: compares estimated trajectories with a ground truth and prints the paper's
// Table 1 plus the KITTI/APE/RPE metrics; optionally writes JSON, markdown and a top-view PNG.
//
//   sunvo_eval --gt GT [--gt-times T] --est NAME=FILE [--est NAME=FILE ...]
//              [--plane xz|en] [--json out.json] [--md out.md] [--plot out.png]
//
// Trajectory files are KITTI (12 numbers per line) or TUM (8), detected from their first pose
// line; poses are associated by index, so every estimate must have as many poses as the ground
// truth. Exit codes (firmware_app/cli): 0 success, 2 a bad command line, 1 an unreadable,
// malformed or mismatched file or an output that cannot be written.

#include <cstdio>
#include <exception>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/report/report.hpp"
#include "sunvo/report/trajectory_plot.hpp"

namespace {

constexpr const char* kProgram = "sunvo_eval";

struct EstimateArg {
  std::string name;
  std::string path;
};

struct Args {
  std::string gt;
  std::string gt_times;
  std::vector<EstimateArg> estimates;
  sunvo::metrics::HorizontalPlane plane = sunvo::metrics::HorizontalPlane::kCameraXZ;
  std::string json;
  std::string md;
  std::string plot;
};

// "NAME=FILE" -> the estimate; "" if well formed, else why not.
std::string splitEstimate(const std::string& value, EstimateArg* out) {
  const std::size_t eq = value.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == value.size()) {
    return "expects NAME=FILE, got '" + value + "'";
  }
  EstimateArg e{value.substr(0, eq), value.substr(eq + 1)};
  if (e.name.find_first_of("|\n") != std::string::npos) {
    return "name '" + e.name + "' must not contain '|'";
  }
  if (out != nullptr) *out = std::move(e);
  return "";
}

// nullopt: go on with `args`; else the exit code.
std::optional<int> parseArgs(int argc, char** argv, Args& args) {
  CLI::App app{
      "Compares estimated trajectories with a ground truth: the paper's Table 1, KITTI segment "
      "errors, APE and RPE. Trajectory files are KITTI (12 fields per line) or TUM (8); poses "
      "are associated by index.",
      kProgram};
  std::vector<std::string> estimates;
  std::string plane = "xz";
  app.add_option("--gt", args.gt, "ground truth, KITTI or TUM")->required();
  app.add_option("--gt-times", args.gt_times,
                 "times of a KITTI ground truth, one number of seconds per line");
  app.add_option("--est", estimates,
                 "an estimate NAME=FILE (same format rules, as many poses as the ground truth)")
      ->required()
      ->check(CLI::Validator([](std::string& value) { return splitEstimate(value, nullptr); },
                             "NAME=FILE"));
  app.add_option("--plane", plane,
                 "horizontal plane of the in-plane rows and the plot: camera x-z (KITTI) or "
                 "East-North of an ENU world frame")
      ->check(CLI::IsMember({"xz", "en"}));
  app.add_option("--json", args.json, "write every metric of every estimate as JSON");
  app.add_option("--md", args.md, "write the tables as markdown");
  app.add_option("--plot", args.plot, "write a top-view PNG of the ground truth and the estimates");
  if (auto code = sunvo::cli::parse(app, argc, argv)) return code;
  args.plane = plane == "en" ? sunvo::metrics::HorizontalPlane::kEastNorth
                             : sunvo::metrics::HorizontalPlane::kCameraXZ;
  std::set<std::string> names;
  for (const std::string& value : estimates) {
    EstimateArg e;
    splitEstimate(value, &e);
    if (!names.insert(e.name).second) {
      std::fprintf(stderr, "%s: --est name '%s' given twice\n", kProgram, e.name.c_str());
      return sunvo::cli::kExitUsage;
    }
    args.estimates.push_back(std::move(e));
  }
  return std::nullopt;
}

int fail(const std::string& message) {
  return sunvo::cli::fail(kProgram, message);
}

int run(int argc, char** argv) {
  Args args;
  if (auto code = parseArgs(argc, argv, args)) return *code;
  auto gt = sunvo::files::loadTrajectory(args.gt, args.gt_times);
  if (!gt) return fail("ground truth: " + gt.status().message());

  sunvo::metrics::EvaluationOptions options;
  options.plane = args.plane;
  sunvo::report::ReportInput input;
  input.gt_path = args.gt;
  input.num_poses = gt->size();
  input.gt_duration_s = sunvo::toSeconds(gt->t_ns.back() - gt->t_ns.front());
  if (!args.gt_times.empty()) {
    input.gt_times_source = "times file " + args.gt_times;
  } else {
    auto probe = sunvo::files::TextFile::open(args.gt);
    bool tum = false;
    if (probe) {
      const auto format = sunvo::files::detectTrajectoryFormat(*probe);
      tum = format && *format == sunvo::files::TrajectoryFormat::kTum;
    }
    input.gt_times_source = tum ? "TUM file" : "nominal 10 Hz (KITTI file without times)";
  }
  input.plane = args.plane;
  std::vector<sunvo::report::PlotSeries> series;
  for (const EstimateArg& e : args.estimates) {
    auto est = sunvo::files::loadTrajectory(e.path);
    if (!est) return fail("estimate '" + e.name + "': " + est.status().message());
    if (est->size() != gt->size()) {
      return fail("estimate '" + e.name + "' (" + e.path + ") has " + std::to_string(est->size()) +
                  " poses, the ground truth (" + args.gt + ") has " + std::to_string(gt->size()) +
                  "; poses are associated by index");
    }
    auto ev = sunvo::metrics::evaluate(gt->T_w_c, est->T_w_c, options);
    if (!ev) return fail("estimate '" + e.name + "': " + ev.status().message());
    input.estimates.push_back({e.name, e.path, std::move(*ev)});
    if (!args.plot.empty()) series.push_back({e.name, std::move(est->T_w_c)});
  }

  const std::string table1 = sunvo::report::table1Markdown(input);
  const std::string extra = sunvo::report::extraMetricsMarkdown(input);
  char header[512];
  std::snprintf(header, sizeof header,
                "Ground truth: %s (%zu poses, %.3f m), in-plane rows: %s\n\n", args.gt.c_str(),
                gt->size(), input.estimates.front().evaluation.table1.gt_path_length_m,
                sunvo::metrics::planeName(args.plane));
  std::printf("%s%s\n%s", header, table1.c_str(), extra.c_str());

  if (!args.md.empty()) {
    const std::string md = "# Trajectory evaluation\n\n" + std::string(header) +
                           "## ARMSE and final drift (paper Table 1)\n\n" + table1 +
                           "\n## KITTI segments, APE, RPE\n\n" + extra;
    const sunvo::Status s = sunvo::files::writeWholeFile(args.md, md);
    if (!s) return fail(s.message());
  }
  if (!args.json.empty()) {
    const sunvo::Status s =
        sunvo::files::writeWholeFile(args.json, sunvo::report::evaluationJson(input));
    if (!s) return fail(s.message());
  }
  if (!args.plot.empty()) {
    auto img = sunvo::report::renderTopView(gt->T_w_c, series, args.plane);
    if (!img) return fail("plot: " + img.status().message());
    const sunvo::Status s = sunvo::report::writePng(args.plot, *img);
    if (!s) return fail(s.message());
  }
  return sunvo::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // e.g. std::bad_alloc on a huge file
    return fail(std::string("unexpected error: ") + e.what());
  }
}
