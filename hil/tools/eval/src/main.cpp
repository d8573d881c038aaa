// sunvo_eval: compares estimated trajectories with a ground truth and prints the paper's
// Table 1 plus the KITTI/APE/RPE metrics; optionally writes JSON, markdown and a top-view PNG.
//
//   sunvo_eval --gt GT [--gt-times T] --est NAME=FILE [--est NAME=FILE ...]
//              [--plane xz|en] [--json out.json] [--md out.md] [--plot out.png]
//
// Trajectory files are KITTI (12 numbers per line) or TUM (8), detected from their first pose
// line; poses are associated by index, so every estimate must have as many poses as the ground
// truth. Exit codes: 0 success, 2 bad arguments or an unreadable/malformed/mismatched file or an
// output that cannot be written.

#include <cstdio>
#include <exception>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "sunvo/files/trajectory_io.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/report/report.hpp"
#include "sunvo/report/trajectory_plot.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;

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
  bool help = false;
};

constexpr const char* kUsage =
    "usage: sunvo_eval --gt GT [--gt-times T] --est NAME=FILE [--est NAME=FILE ...]\n"
    "                  [--plane xz|en] [--json out.json] [--md out.md] [--plot out.png]\n"
    "  --gt FILE        ground truth, KITTI (12 fields/line) or TUM (8 fields/line)\n"
    "  --gt-times FILE  times of a KITTI ground truth, one number of seconds per line\n"
    "  --est NAME=FILE  an estimate (same format rules, same number of poses as the ground truth)\n"
    "  --plane xz|en    horizontal plane of the in-plane rows and the plot: camera x-z (KITTI,\n"
    "                   default) or East-North of an ENU world frame\n"
    "  --json FILE      write every metric of every estimate as JSON\n"
    "  --md FILE        write the tables as markdown\n"
    "  --plot FILE      write a top-view PNG of the ground truth and the estimates\n";

sunvo::Expected<Args> parseArgs(int argc, char** argv) {
  Args args;
  std::set<std::string> names;
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (flag == "-h" || flag == "--help") {
      args.help = true;
      return args;
    }
    const bool known = flag == "--gt" || flag == "--gt-times" || flag == "--est" ||
                       flag == "--plane" || flag == "--json" || flag == "--md" || flag == "--plot";
    if (!known) return sunvo::invalidArgument("unknown argument '" + std::string(flag) + "'");
    if (i + 1 >= argc) return sunvo::invalidArgument(std::string(flag) + " needs a value");
    const std::string value = argv[++i];
    if (value.empty()) return sunvo::invalidArgument(std::string(flag) + " has an empty value");
    auto set_once = [&](std::string& slot) -> sunvo::Status {
      if (!slot.empty()) return sunvo::invalidArgument(std::string(flag) + " given twice");
      slot = value;
      return sunvo::Status::ok();
    };
    if (flag == "--gt") {
      SUNVO_RETURN_IF_ERROR(set_once(args.gt));
    } else if (flag == "--gt-times") {
      SUNVO_RETURN_IF_ERROR(set_once(args.gt_times));
    } else if (flag == "--json") {
      SUNVO_RETURN_IF_ERROR(set_once(args.json));
    } else if (flag == "--md") {
      SUNVO_RETURN_IF_ERROR(set_once(args.md));
    } else if (flag == "--plot") {
      SUNVO_RETURN_IF_ERROR(set_once(args.plot));
    } else if (flag == "--plane") {
      if (value == "xz") {
        args.plane = sunvo::metrics::HorizontalPlane::kCameraXZ;
      } else if (value == "en") {
        args.plane = sunvo::metrics::HorizontalPlane::kEastNorth;
      } else {
        return sunvo::invalidArgument("--plane must be 'xz' or 'en', got '" + value + "'");
      }
    } else {  // --est NAME=FILE
      const std::size_t eq = value.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == value.size()) {
        return sunvo::invalidArgument("--est expects NAME=FILE, got '" + value + "'");
      }
      EstimateArg e{value.substr(0, eq), value.substr(eq + 1)};
      if (e.name.find_first_of("|\n") != std::string::npos) {
        return sunvo::invalidArgument("--est name '" + e.name + "' must not contain '|'");
      }
      if (!names.insert(e.name).second) {
        return sunvo::invalidArgument("--est name '" + e.name + "' given twice");
      }
      args.estimates.push_back(std::move(e));
    }
  }
  if (args.gt.empty()) return sunvo::invalidArgument("--gt is required");
  if (args.estimates.empty()) return sunvo::invalidArgument("at least one --est is required");
  return args;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "sunvo_eval: %s\n", message.c_str());
  return kExitUsage;
}

int run(int argc, char** argv) {
  auto args = parseArgs(argc, argv);
  if (!args) {
    std::fprintf(stderr, "sunvo_eval: %s\n%s", args.status().message().c_str(), kUsage);
    return kExitUsage;
  }
  if (args->help) {
    std::fputs(kUsage, stdout);
    return kExitOk;
  }
  auto gt = sunvo::files::loadTrajectory(args->gt, args->gt_times);
  if (!gt) return fail("ground truth: " + gt.status().message());

  sunvo::metrics::EvaluationOptions options;
  options.plane = args->plane;
  sunvo::report::ReportInput input;
  input.gt_path = args->gt;
  input.num_poses = gt->size();
  input.gt_duration_s = sunvo::toSeconds(gt->t_ns.back() - gt->t_ns.front());
  if (!args->gt_times.empty()) {
    input.gt_times_source = "times file " + args->gt_times;
  } else {
    auto probe = sunvo::files::TextFile::open(args->gt);
    bool tum = false;
    if (probe) {
      const auto format = sunvo::files::detectTrajectoryFormat(*probe);
      tum = format && *format == sunvo::files::TrajectoryFormat::kTum;
    }
    input.gt_times_source = tum ? "TUM file" : "nominal 10 Hz (KITTI file without times)";
  }
  input.plane = args->plane;
  std::vector<sunvo::report::PlotSeries> series;
  for (const EstimateArg& e : args->estimates) {
    auto est = sunvo::files::loadTrajectory(e.path);
    if (!est) return fail("estimate '" + e.name + "': " + est.status().message());
    if (est->size() != gt->size()) {
      return fail("estimate '" + e.name + "' (" + e.path + ") has " + std::to_string(est->size()) +
                  " poses, the ground truth (" + args->gt + ") has " + std::to_string(gt->size()) +
                  "; poses are associated by index");
    }
    auto ev = sunvo::metrics::evaluate(gt->T_w_c, est->T_w_c, options);
    if (!ev) return fail("estimate '" + e.name + "': " + ev.status().message());
    input.estimates.push_back({e.name, e.path, std::move(*ev)});
    if (!args->plot.empty()) series.push_back({e.name, std::move(est->T_w_c)});
  }

  const std::string table1 = sunvo::report::table1Markdown(input);
  const std::string extra = sunvo::report::extraMetricsMarkdown(input);
  char header[512];
  std::snprintf(header, sizeof header,
                "Ground truth: %s (%zu poses, %.3f m), in-plane rows: %s\n\n", args->gt.c_str(),
                gt->size(), input.estimates.front().evaluation.table1.gt_path_length_m,
                sunvo::metrics::planeName(args->plane));
  std::printf("%s%s\n%s", header, table1.c_str(), extra.c_str());

  if (!args->md.empty()) {
    const std::string md = "# Trajectory evaluation\n\n" + std::string(header) +
                           "## ARMSE and final drift (paper Table 1)\n\n" + table1 +
                           "\n## KITTI segments, APE, RPE\n\n" + extra;
    const sunvo::Status s = sunvo::files::writeWholeFile(args->md, md);
    if (!s) return fail(s.message());
  }
  if (!args->json.empty()) {
    const sunvo::Status s =
        sunvo::files::writeWholeFile(args->json, sunvo::report::evaluationJson(input));
    if (!s) return fail(s.message());
  }
  if (!args->plot.empty()) {
    auto img = sunvo::report::renderTopView(gt->T_w_c, series, args->plane);
    if (!img) return fail("plot: " + img.status().message());
    const sunvo::Status s = sunvo::report::writePng(args->plot, *img);
    if (!s) return fail(s.message());
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // e.g. std::bad_alloc on a huge file
    return fail(std::string("unexpected error: ") + e.what());
  }
}
