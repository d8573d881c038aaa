// sunvo_fusion_trace: why a sun source helps or not, measured. Runs the experiment's routes with
// pure VO and the chosen sun sources and, per run, compares what the fusion believes with the
// ground truth:
//  - the gate's decisions (accepted, refused by cosine / vertical / innovation gate);
//  - the attitude error e_w (C_w_c,gt = Exp(e_w) C_w_c) against the fusion's covariance P per
//    camera axis (x = pitch, y = yaw, z = roll for a KITTI camera) and as NEES e_w^T P^-1 e_w
//    (chi-square, 3 dof, mean 3 when P is consistent), per quarter of the route;
//  - each correction c_w of the base attitude: its size and how much it removed of the error
//    just before it, |e| - |e - c| (negative: it made the attitude worse).
// For pure VO it lists the frames where the attitude error jumped most. Per-frame CSV files go to
// --out (route_<id>_run<i>_trace.csv); the summary is printed as markdown.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/experiment/experiment.hpp"
#include "sunvo/files/trajectory_io.hpp"

namespace {

using sunvo::experiment::Route;
constexpr const char* kProgram = "sunvo_fusion_trace";
constexpr double kDeg = M_PI / 180.0;

std::vector<std::string> splitComma(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

struct FrameTrace {
  Eigen::Vector3d e_w = Eigen::Vector3d::Zero();      // attitude error, world axes, rad
  Eigen::Vector3d e_c = Eigen::Vector3d::Zero();      // attitude error, camera axes, rad
  Eigen::Vector3d sigma_c = Eigen::Vector3d::Zero();  // sqrt(diag(P)) in camera axes, rad
  double nees = 0.0;
  double drift_deg = 0.0;
  int decision = -1;  // GateResult of a measurement decided at this frame, else -1
  double nis = 0.0;
  double corr_deg = 0.0;                             // |c_w|, deg
  double gain_deg = 0.0;                             // |e_before| - |e_before - c_w|, deg
  Eigen::Vector3d corr_c = Eigen::Vector3d::Zero();  // c_w in camera axes, rad
};

// Records one run's trace through the experiment's frame observer.
struct Tracer {
  const Route* route = nullptr;
  std::vector<FrameTrace> frames;
  Eigen::Vector3d e_w_prev = Eigen::Vector3d::Zero();
  std::uint64_t corrections = 0, decided = 0;

  void operator()(std::size_t k, const sunvo::pipeline::SunAidedOdometry& odo) {
    const Eigen::Matrix3d C_w_c = odo.T_w_c().linear();
    const Eigen::Matrix3d C_w_gt = route->T_w_c_gt[k].linear();
    const Eigen::Vector3d e_w = sunvo::logSO3(C_w_gt * C_w_c.transpose());
    const Eigen::Matrix3d P_w = odo.attitudeCovariance();
    const Eigen::Matrix3d P_c = C_w_c.transpose() * P_w * C_w_c;
    FrameTrace f;
    f.e_w = e_w;
    f.e_c = C_w_c.transpose() * e_w;
    f.sigma_c = P_c.diagonal().cwiseMax(0.0).cwiseSqrt();
    f.nees = P_w.determinant() > 0.0 ? e_w.dot(P_w.ldlt().solve(e_w)) : 0.0;
    const auto& term = odo.sunTerm();
    f.drift_deg = term.driftDegPerFrame();
    if (odo.sunCounters().total() != decided) {
      decided = odo.sunCounters().total();
      f.decision = term.lastDecision() ? static_cast<int>(*term.lastDecision()) : -1;
      f.nis = term.lastInnovationNis();
    }
    if (term.numCorrections() != corrections) {
      corrections = term.numCorrections();
      const Eigen::Vector3d c_w = term.lastCorrection().dtheta_w;
      f.corr_deg = c_w.norm() / kDeg;
      f.gain_deg = (e_w_prev.norm() - (e_w_prev - c_w).norm()) / kDeg;
      f.corr_c = C_w_c.transpose() * c_w;
    }
    e_w_prev = e_w;
    frames.push_back(f);
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::string summarize(const std::string& id, const std::string& name, const Tracer& t,
                      const sunvo::sunfusion::GateCounters& g, bool sun) {
  char buf[1024];
  std::string out;
  const auto& fr = t.frames;
  const std::size_t n = fr.size();
  const Eigen::Vector3d e_end = fr.back().e_c / kDeg;
  // Mean tilt error: the part of e_w across the world's up axis (roll and pitch), deg.
  double tilt = 0.0;
  for (const FrameTrace& f : fr) {
    const Eigen::Vector3d up = t.route->world_up;
    tilt += (f.e_w - up * up.dot(f.e_w)).norm() / kDeg;
  }
  tilt /= static_cast<double>(n);
  if (!sun) {
    // The largest per-frame jumps of the attitude error (|e_w,k - e_w,k-1|, world axes), with
    // the frame's number of stereo observations.
    std::vector<std::pair<double, std::size_t>> jumps;
    std::vector<double> obs;
    for (const auto& f : t.route->frames) obs.push_back(static_cast<double>(f.observations.size()));
    double total = 0.0;
    for (std::size_t k = 1; k < n; ++k) {
      const double j = (fr[k].e_w - fr[k - 1].e_w).norm() / kDeg;
      total += j;
      jumps.push_back({j, k});
    }
    std::sort(jumps.rbegin(), jumps.rend());
    std::snprintf(
        buf, sizeof(buf),
        "| %s | %s | final error (pitch x, yaw y, roll z) %.2f, %.2f, %.2f deg; mean tilt "
        "error %.2f deg; sum of per-frame jumps %.2f deg; median observations per frame "
        "%.0f; largest:",
        id.c_str(), name.c_str(), e_end.x(), e_end.y(), e_end.z(), tilt, total, median(obs));
    out += buf;
    for (std::size_t i = 0; i < std::min<std::size_t>(5, jumps.size()); ++i) {
      std::snprintf(buf, sizeof(buf), " %zu (%.2f deg, %zu obs)", jumps[i].second, jumps[i].first,
                    t.route->frames[jumps[i].second].observations.size());
      out += buf;
    }
    return out + " |\n";
  }
  // NEES per quarter and per axis z^2 = e_i^2 / P_ii over the whole run.
  std::string quarters;
  for (int q = 0; q < 4; ++q) {
    double s = 0.0;
    std::size_t c = 0;
    for (std::size_t k = n * q / 4; k < n * (q + 1) / 4; ++k, ++c) s += fr[k].nees;
    std::snprintf(buf, sizeof(buf), "%s%.0f", q ? "/" : "", c ? s / static_cast<double>(c) : 0.0);
    quarters += buf;
  }
  Eigen::Vector3d z2 = Eigen::Vector3d::Zero();
  for (const FrameTrace& f : fr) {
    for (int i = 0; i < 3; ++i) {
      z2(i) += f.sigma_c(i) > 0.0 ? f.e_c(i) * f.e_c(i) / (f.sigma_c(i) * f.sigma_c(i)) : 0.0;
    }
  }
  z2 /= static_cast<double>(n);
  std::vector<double> corr;
  double sum_corr = 0.0, sum_gain = 0.0;
  int helped = 0;
  for (const FrameTrace& f : fr) {
    if (f.corr_deg <= 0.0) continue;
    corr.push_back(f.corr_deg);
    sum_corr += f.corr_deg;
    sum_gain += f.gain_deg;
    helped += f.gain_deg > 0.0 ? 1 : 0;
  }
  const Eigen::Vector3d s_end = fr.back().sigma_c / kDeg;
  std::snprintf(
      buf, sizeof(buf),
      "| %s | %s | %.2f | %llu / %llu / %llu / %llu / %llu | %s | %.0f, %.0f, %.0f | %.2f, %.2f, "
      "%.2f "
      "| %.2f, %.2f, %.2f | %zu | %.3f | %.2f | %+.2f | %d |\n",
      id.c_str(), name.c_str(), tilt, static_cast<unsigned long long>(g.accepted),
      static_cast<unsigned long long>(g.rejected_cosine),
      static_cast<unsigned long long>(g.rejected_vertical),
      static_cast<unsigned long long>(g.rejected_innovation),
      static_cast<unsigned long long>(g.rejected_correction), quarters.c_str(), z2.x(), z2.y(),
      z2.z(), s_end.x(), s_end.y(), s_end.z(), e_end.x(), e_end.y(), e_end.z(), corr.size(),
      median(corr), sum_corr, sum_gain, helped);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = SUNVO_DEFAULT_DATA_DIR;
  std::string out_dir = "fusion_trace";
  std::string routes_arg = "0020,00";
  std::string sources_arg = "1,2,3,4";
  int frames = 0, seed = 1;
  std::optional<double> drift_deg, initial_sigma_deg, max_drift_deg, evidence_sigmas,
      max_correction_deg, forgetting, zenith_bias_deg;
  bool fixed_drift = false, evidence = false;
  CLI::App app{"Traces the sun fusion's gate, covariance and corrections against ground truth.",
               kProgram};
  // The same VO as sunvo_experiment: the KITTI car's sideways row and the window's prior options.
  sunvo::experiment::ExperimentOptions options;
  sunvo::cli::setKittiCarVehicle(options.vo.window);  // the KITTI car's lever arm (cli.hpp)
  sunvo::cli::addWindowPriorOptions(app, options.vo.window);
  app.add_option("--data", data_dir, "folder of the real data (shared/data layout)");
  app.add_option("--out", out_dir, "output folder for the per-frame CSV files (created)");
  app.add_option("--routes", routes_arg, "comma-separated routes, as sunvo_experiment");
  app.add_option("--sources", sources_arg,
                 "comma-separated sun sources: 1 true vector, 2 Lalonde-like, 3 Lalonde-VO-like, "
                 "4 Sun-CNN-like");
  app.add_option("--frames", frames, "first N frames of each route (0 = all)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--seed", seed, "seed of the simulated tracks and the error models")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--drift-deg", drift_deg, "attitude random walk per frame, deg (start value)")
      ->check(CLI::Range(0.0, 5.0));
  app.add_flag("--fixed-drift", fixed_drift, "keep the random walk at --drift-deg");
  app.add_option("--initial-sigma-deg", initial_sigma_deg, "first pose's attitude sigma, deg")
      ->check(CLI::Range(0.0, 45.0));
  app.add_option("--max-drift-deg", max_drift_deg, "cap of the adapted random walk, deg/frame")
      ->check(CLI::Range(0.0, 5.0));
  app.add_flag("--evidence", evidence, "the evidence rule (covariance matching)");
  app.add_option("--evidence-sigmas", evidence_sigmas, "evidence rule: threshold in sigmas")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--forgetting", forgetting, "forgetting factor of the evidence sums")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--max-correction-deg", max_correction_deg, "correction gate, deg (0 = off)")
      ->check(CLI::Range(0.0, 180.0));
  app.add_option("--zenith-bias-deg", zenith_bias_deg,
                 "override the zenith bias of the Lalonde-like and Lalonde-VO-like models, deg")
      ->check(CLI::Range(-45.0, 45.0));
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return sunvo::cli::fail(kProgram, "cannot create '" + out_dir + "': " + ec.message());
  options.max_frames = frames;
  options.vo.window.max_solver_time_in_seconds = 60.0;
  if (drift_deg) options.fusion.attitude_drift_deg_per_frame = *drift_deg;
  if (fixed_drift) options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kFixed;
  if (initial_sigma_deg) options.fusion.initial_attitude_sigma_deg = *initial_sigma_deg;
  if (max_drift_deg) options.fusion.max_drift_deg_per_frame = *max_drift_deg;
  if (evidence) options.fusion.drift_adaptation = sunvo::sunfusion::DriftAdaptation::kEvidence;
  if (evidence_sigmas) options.fusion.evidence_sigmas = *evidence_sigmas;
  if (forgetting) options.fusion.persistence_forgetting = *forgetting;
  if (max_correction_deg) options.fusion.max_correction_deg = *max_correction_deg;
  if (auto s = options.validate(); !s.isOk()) return sunvo::cli::fail(kProgram, s);
  auto sources = sunvo::experiment::defaultSunSources(static_cast<std::uint32_t>(seed));
  if (zenith_bias_deg) {
    for (auto& src : sources) {
      if (src.model.zenith_bias_deg != 0.0) src.model.zenith_bias_deg = *zenith_bias_deg;
    }
  }

  std::string metrics =
      "| route | run | final drift [m] (change) | rot. ARMSE [1e-3] (change) "
      "|\n|---|---|---|---|\n";
  std::string pure = "| route | run | pure VO attitude error |\n|---|---|---|\n";
  std::string table =
      "| route | source | mean tilt error [deg] | accepted / cosine / vertical / innovation / "
      "correction | NEES by quarter "
      "| mean "
      "z^2 (x, y, z) | final sigma [deg] (x, y, z) | final error [deg] (x, y, z) | corrections "
      "| median corr [deg] | sum corr [deg] | sum gain [deg] | corrections that helped |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const std::string& spec : splitComma(routes_arg)) {
    sunvo::experiment::SimulatedRouteOptions sim;
    sim.seed = static_cast<std::uint32_t>(seed) + 6;
    auto route = sunvo::experiment::loadRoute(spec, data_dir, sim);
    if (!route)
      return sunvo::cli::fail(kProgram, "route " + spec + ": " + route.status().toString());
    sunvo::metrics::Table1Metrics base;
    std::vector<int> runs = {0};
    for (const std::string& s : splitComma(sources_arg)) runs.push_back(std::stoi(s));
    for (int i : runs) {
      if (i < 0 || i > static_cast<int>(sources.size())) {
        return sunvo::cli::fail(kProgram, "--sources: no source " + std::to_string(i));
      }
      std::optional<sunvo::experiment::SunSourceSpec> src;
      if (i > 0) src = sources[static_cast<std::size_t>(i - 1)];
      Tracer tracer;
      tracer.route = &*route;
      auto run = sunvo::experiment::runRoute(
          *route, src, options,
          [&tracer](std::size_t k, const sunvo::pipeline::SunAidedOdometry& o) { tracer(k, o); });
      if (!run) return sunvo::cli::fail(kProgram, run.status());
      std::string csv =
          "frame,e_x_deg,e_y_deg,e_z_deg,sigma_x_deg,sigma_y_deg,sigma_z_deg,nees,drift_deg,"
          "decision,nis,corr_deg,gain_deg,corr_x_deg,corr_y_deg,corr_z_deg\n";
      for (std::size_t k = 0; k < tracer.frames.size(); ++k) {
        const FrameTrace& f = tracer.frames[k];
        char line[512];
        std::snprintf(line, sizeof(line),
                      "%zu,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.4g,%.5f,%d,%.4g,%.5f,%.5f,%.5f,%.5f,"
                      "%.5f\n",
                      k, f.e_c.x() / kDeg, f.e_c.y() / kDeg, f.e_c.z() / kDeg, f.sigma_c.x() / kDeg,
                      f.sigma_c.y() / kDeg, f.sigma_c.z() / kDeg, f.nees, f.drift_deg, f.decision,
                      f.nis, f.corr_deg, f.gain_deg, f.corr_c.x() / kDeg, f.corr_c.y() / kDeg,
                      f.corr_c.z() / kDeg);
        csv += line;
      }
      const std::string id = std::filesystem::path(spec).filename().string();
      const std::string path = out_dir + "/route_" + id + "_run" + std::to_string(i) + "_trace.csv";
      if (auto s = sunvo::files::writeWholeFile(path, csv); !s.isOk()) {
        return sunvo::cli::fail(kProgram, s);
      }
      const auto& t1 = run->evaluation.table1;
      if (i == 0) base = t1;
      char m[256];
      std::snprintf(m, sizeof(m), "| %s | %s | %.2f (%+.0f %%) | %.2f (%+.0f %%) |\n", id.c_str(),
                    run->name.c_str(), t1.final_drift_m,
                    100.0 * (t1.final_drift_m / base.final_drift_m - 1.0), t1.rot_armse_rad * 1e3,
                    100.0 * (t1.rot_armse_rad / base.rot_armse_rad - 1.0));
      metrics += m;
      const std::string row = summarize(id, run->name, tracer, run->gate, i > 0);
      (i > 0 ? table : pure) += row;
      std::fprintf(stderr, "%s", row.c_str());
    }
  }
  std::printf("%s\n%s\n%s", metrics.c_str(), pure.c_str(), table.c_str());
  return 0;
}
