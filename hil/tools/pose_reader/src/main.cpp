// sunvo_pose_reader: the other end of sunvo_rover's serial port, for whole-program replays.
//
//   sunvo_pose_reader --drive DIR --frames N [options] --
//                     sunvo_rover --config ... --set serial.device={pty} ...
//
// It opens a pseudo-terminal pair, starts the command with {pty} replaced by the slave's path,
// decodes the MAVLink stream on the master (drivers/mavlink's decoder: CRC, sequence numbers),
// stamps each ODOMETRY frame's arrival on the monotonic clock, and once N poses have arrived (or
// the timeout passed) sends SIGTERM to the program and waits for its clean exit. Then it
//  - converts each pose back to the camera in the ENU world (the inverse of the stream's
//    conventions) and evaluates it against the drive's ground truth (Table 1, estimator/metrics);
//  - joins the program's latency CSV (profiling.output_dir/final_latency.csv) with its arrival
//    times: trigger -> last byte written (the program's own stamp) and trigger -> byte received
//    here (both CLOCK_MONOTONIC on this machine);
//  - writes a JSON report and exits 0 only when every pose arrived once with good CRCs, the
//    program exited 0 after SIGTERM and printed its summary, and the accuracy bounds hold; 1
//    otherwise, 2 for a bad command line (firmware_app/cli).

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "sunvo/cli/cli.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/dataset/dataset.hpp"
#include "sunvo/files/text_file.hpp"
#include "sunvo/mavlink/conventions.hpp"
#include "sunvo/mavlink/mavlink.hpp"
#include "sunvo/metrics/metrics.hpp"

namespace {

using sunvo::TimeNs;

TimeNs monoNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

struct Options {
  std::string drive;
  std::int64_t utc_offset_s = 0;
  int frames = 0;
  double timeout_s = 60.0;
  std::string json;
  std::string child_log;
  std::string latency_csv;          // the program's final_latency.csv
  double max_final_drift_m = -1.0;  // < 0: not checked
  double max_rot_armse_rad = -1.0;
  std::vector<std::string> command;
};

struct Received {
  sunvo::mavlink::Odometry odo;
  TimeNs recv_mono_ns = 0;
};

// The camera pose in the ENU world from an ODOMETRY message in MAV_FRAME_LOCAL_NED with the
// camera-forward body: t_w = C_l_w^T p_l, C_w_c = C_l_w^T C_l_b C_b_c.
sunvo::Isometry3 poseFromOdometry(const sunvo::mavlink::Odometry& m) {
  const Eigen::Matrix3d C_b_c = sunvo::mavlink::cameraForwardC_b_c();
  const Eigen::Matrix3d C_l_w =
      sunvo::mavlink::worldToLocal(sunvo::mavlink::WorldConvention::kEnu, C_b_c);
  const Eigen::Quaterniond q_l_b(m.q[0], m.q[1], m.q[2], m.q[3]);
  sunvo::Isometry3 T = sunvo::Isometry3::Identity();
  T.translation() = C_l_w.transpose() * Eigen::Vector3d(m.x, m.y, m.z);
  T.linear() =
      sunvo::orthonormalize(C_l_w.transpose() * q_l_b.normalized().toRotationMatrix() * C_b_c);
  return T;
}

double percentileMs(std::vector<double> v, double q) {
  return v.empty() ? 0.0 : sunvo::metrics::percentile(std::move(v), q);
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kProgram = "sunvo_pose_reader";
  Options opt;
  CLI::App app{
      "The other end of sunvo_rover's serial port: starts COMMAND on a pseudo-terminal ({pty} in "
      "it is replaced by the terminal's path), decodes its MAVLink poses, stops it after N poses "
      "and evaluates accuracy and latency against the drive.",
      kProgram};
  app.add_option("--drive", opt.drive, "the drive the program replays (ground truth)")->required();
  app.add_option("--frames", opt.frames, "poses to wait for")
      ->required()
      ->check(CLI::Range(1, 100000000));
  app.add_option("--timeout-s", opt.timeout_s, "give up after this many seconds")
      ->check(CLI::PositiveNumber);
  app.add_option("--json", opt.json, "write the evaluation as JSON");
  app.add_option("--child-log", opt.child_log, "the program's stdout and stderr go here");
  app.add_option("--latency-csv", opt.latency_csv, "the program's final_latency.csv");
  app.add_option("--max-final-drift-m", opt.max_final_drift_m,
                 "fail above this final drift, m (< 0: not checked)");
  app.add_option("--max-rot-armse-rad", opt.max_rot_armse_rad,
                 "fail above this rotation ARMSE, rad (< 0: not checked)");
  app.add_option("--utc-offset-s", opt.utc_offset_s, "the drive's offset to UTC, s")
      ->check(CLI::Range(-50400L, 50400L));
  app.add_option("command", opt.command, "after --: the program and its arguments")->required();
  if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
  sunvo::dataset::DatasetOptions dopt;
  dopt.path = opt.drive;
  dopt.utc_offset_s = opt.utc_offset_s;
  auto truth = sunvo::dataset::Dataset::open(dopt);
  if (!truth) return sunvo::cli::fail(kProgram, truth.status().message());
  // A looped replay (more frames than the drive) is evaluated on its first pass, whose frame
  // times are the drive's; later passes carry later times.
  const int truth_frames = std::min(opt.frames, static_cast<int>(truth->size()));

  // The pseudo-terminal: the program writes the slave, we read the master. We keep a slave fd
  // open too, so the master does not see a hang-up before the program opens its end.
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
    std::perror("sunvo_pose_reader: posix_openpt");
    return 1;
  }
  const std::string slave_path = ptsname(master);
  const int keep_slave = open(slave_path.c_str(), O_RDWR | O_NOCTTY);
  termios tio{};
  tcgetattr(keep_slave, &tio);
  cfmakeraw(&tio);
  tcsetattr(keep_slave, TCSANOW, &tio);
  fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);

  std::vector<std::string> args;
  for (std::string a : opt.command) {
    for (std::size_t p; (p = a.find("{pty}")) != std::string::npos;) a.replace(p, 5, slave_path);
    args.push_back(a);
  }
  const pid_t child = fork();
  if (child == 0) {
    if (!opt.child_log.empty()) {
      const int fd = open(opt.child_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
      }
    }
    std::vector<char*> cargv;
    for (std::string& a : args) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    execvp(cargv[0], cargv.data());
    std::perror("sunvo_pose_reader: exec");
    _exit(127);
  }
  std::printf("sunvo_pose_reader: %s started (pid %d) writing %s\n", args[0].c_str(), child,
              slave_path.c_str());
  std::fflush(stdout);

  sunvo::mavlink::Decoder decoder;
  std::vector<Received> poses;
  poses.reserve(static_cast<std::size_t>(opt.frames) + 16);
  std::uint64_t heartbeats = 0, duplicates = 0, unknown_times = 0;
  std::map<std::uint64_t, int> times_seen;     // time_usec -> count
  std::map<std::uint64_t, int> index_of_time;  // time_usec -> frame index
  for (std::size_t k = 0; k < truth->size(); ++k) {
    index_of_time[static_cast<std::uint64_t>(truth->timesNs()[k] / 1000)] = static_cast<int>(k);
  }
  std::vector<int> seen(truth->size(), 0);
  const TimeNs start = monoNs();
  const auto timeout_ns = static_cast<TimeNs>(opt.timeout_s * 1e9);
  bool term_sent = false, child_exited = false;
  int child_status = 0;
  TimeNs term_at = 0;
  std::uint8_t buf[4096];
  for (;;) {
    pollfd pfd{master, POLLIN, 0};
    poll(&pfd, 1, 20);
    const TimeNs now = monoNs();
    for (;;) {
      const ssize_t n = read(master, buf, sizeof(buf));
      if (n <= 0) break;
      const TimeNs t_recv = monoNs();
      for (ssize_t i = 0; i < n; ++i) {
        sunvo::mavlink::Frame f;
        if (!decoder.push(buf[i], &f)) continue;
        do {
          sunvo::mavlink::Odometry odo;
          sunvo::mavlink::Heartbeat hb;
          if (sunvo::mavlink::decodeOdometry(f, &odo)) {
            poses.push_back({odo, t_recv});
            if (times_seen[odo.time_usec]++ > 0) ++duplicates;
            auto it = index_of_time.find(odo.time_usec);
            if (it == index_of_time.end()) {
              ++unknown_times;
            } else {
              ++seen[static_cast<std::size_t>(it->second)];
            }
          } else if (sunvo::mavlink::decodeHeartbeat(f, &hb)) {
            ++heartbeats;
          }
        } while (decoder.next(&f));
      }
    }
    if (!child_exited) {
      const pid_t w = waitpid(child, &child_status, WNOHANG);
      if (w == child) child_exited = true;
    }
    const bool have_all = poses.size() >= static_cast<std::size_t>(opt.frames);
    if (!term_sent && !child_exited && (have_all || now - start > timeout_ns)) {
      kill(child, SIGTERM);
      term_sent = true;
      term_at = now;
    }
    if (child_exited) break;
    if (term_sent && now - term_at > 10'000'000'000) {  // no clean exit within 10 s
      kill(child, SIGKILL);
      waitpid(child, &child_status, 0);
      child_exited = true;
      std::fprintf(stderr, "sunvo_pose_reader: the program did not stop within 10 s of SIGTERM\n");
      break;
    }
  }
  close(keep_slave);
  close(master);
  const bool clean_exit = term_sent && WIFEXITED(child_status) && WEXITSTATUS(child_status) == 0;

  // The program's summary (in its log).
  bool summary_printed = false;
  if (!opt.child_log.empty()) {
    std::stringstream ss;
    ss << std::ifstream(opt.child_log).rdbuf();
    const std::string log = ss.str();
    summary_printed = log.find("sunvo_rover: stopped (SIGTERM)") != std::string::npos &&
                      log.find("summary (") != std::string::npos &&
                      log.find("trigger_to_serial") != std::string::npos;
  }

  // Accuracy: one pose per frame 0..N-1, in frame order.
  std::vector<sunvo::Isometry3> est, gt;
  std::map<std::uint64_t, TimeNs> recv_of_time;  // time_usec -> arrival
  for (const Received& r : poses) recv_of_time[r.odo.time_usec] = r.recv_mono_ns;
  std::vector<sunvo::Isometry3> by_frame(truth->size());
  std::vector<bool> have(truth->size(), false);
  for (const Received& r : poses) {
    auto it = index_of_time.find(r.odo.time_usec);
    if (it == index_of_time.end()) continue;
    by_frame[static_cast<std::size_t>(it->second)] = poseFromOdometry(r.odo);
    have[static_cast<std::size_t>(it->second)] = true;
  }
  int missing = opt.frames - static_cast<int>(times_seen.size());
  for (int k = 0; k < truth_frames; ++k) {
    if (!have[static_cast<std::size_t>(k)]) continue;  // counted in `missing`
    est.push_back(by_frame[static_cast<std::size_t>(k)]);
    gt.push_back(truth->groundTruth()[static_cast<std::size_t>(k)]);
  }
  sunvo::metrics::Table1Metrics t1;
  bool evaluated = false;
  if (est.size() == static_cast<std::size_t>(truth_frames) && est.size() >= 2) {
    sunvo::metrics::EvaluationOptions eo;
    eo.plane = sunvo::metrics::HorizontalPlane::kEastNorth;
    auto ev = sunvo::metrics::evaluate(gt, est, eo);
    if (ev) {
      t1 = ev->table1;
      evaluated = true;
    } else {
      std::fprintf(stderr, "sunvo_pose_reader: evaluation: %s\n", ev.status().message().c_str());
    }
  }

  // Latency: the program's CSV (utc_ns, trigger_ns, last_byte_ns) joined with our arrivals.
  std::vector<double> to_written_ms, to_received_ms;
  if (!opt.latency_csv.empty()) {
    auto file = sunvo::files::TextFile::open(opt.latency_csv);
    std::string_view line;
    if (file && file->nextLine(line)) {  // header
      while (file->nextLine(line)) {
        const auto f = sunvo::files::splitFields(line, ',');
        if (f.size() < 14) continue;
        const TimeNs utc = std::atoll(std::string(f[1]).c_str());
        const TimeNs trig = std::atoll(std::string(f[2]).c_str());
        const TimeNs last = std::atoll(std::string(f[11]).c_str());
        if (trig > 0 && last >= trig)
          to_written_ms.push_back(static_cast<double>(last - trig) * 1e-6);
        auto it = recv_of_time.find(static_cast<std::uint64_t>(utc / 1000));
        if (it == recv_of_time.end()) continue;
        const TimeNs recv = it->second;
        if (trig > 0 && recv >= trig)
          to_received_ms.push_back(static_cast<double>(recv - trig) * 1e-6);
      }
    } else {
      std::fprintf(stderr, "sunvo_pose_reader: %s: not readable\n", opt.latency_csv.c_str());
    }
  }

  const auto& dc = decoder.counters();
  const bool expect_unknown = opt.frames > truth_frames;  // later passes of a loop
  const bool poses_ok = missing == 0 && duplicates == 0 && (expect_unknown || unknown_times == 0) &&
                        dc.crc_errors == 0 && poses.size() == static_cast<std::size_t>(opt.frames);
  bool accuracy_ok = evaluated;
  if (opt.max_final_drift_m >= 0) accuracy_ok &= t1.final_drift_m <= opt.max_final_drift_m;
  if (opt.max_rot_armse_rad >= 0) accuracy_ok &= t1.rot_armse_rad <= opt.max_rot_armse_rad;
  const bool latency_ok = opt.latency_csv.empty() || !to_received_ms.empty();
  const bool ok = poses_ok && clean_exit && (opt.child_log.empty() || summary_printed) &&
                  accuracy_ok && latency_ok;

  char json[4096];
  std::snprintf(
      json, sizeof(json),
      "{\n  \"frames_expected\": %d,\n  \"odometry_received\": %zu,\n  \"missing\": %d,\n"
      "  \"duplicates\": %" PRIu64 ",\n  \"unknown_times\": %" PRIu64
      ",\n"
      "  \"heartbeats\": %" PRIu64 ",\n  \"crc_errors\": %" PRIu64 ",\n  \"seq_gaps\": %" PRIu64
      ",\n  \"frames_ok\": %" PRIu64
      ",\n  \"clean_exit\": %s,\n  \"summary_printed\": %s,\n"
      "  \"evaluated\": %s,\n  \"trans_armse_m\": %.6f,\n  \"rot_armse_rad\": %.8f,\n"
      "  \"final_drift_m\": %.6f,\n  \"final_drift_pct\": %.4f,\n  \"path_length_m\": %.4f,\n"
      "  \"trigger_to_written_ms\": {\"n\": %zu, \"p50\": %.3f, \"p95\": %.3f, \"p99\": %.3f, "
      "\"max\": %.3f},\n"
      "  \"trigger_to_received_ms\": {\"n\": %zu, \"p50\": %.3f, \"p95\": %.3f, \"p99\": %.3f, "
      "\"max\": %.3f},\n  \"ok\": %s\n}\n",
      opt.frames, poses.size(), missing, duplicates, unknown_times, heartbeats, dc.crc_errors,
      dc.seq_gaps, dc.frames_ok, clean_exit ? "true" : "false", summary_printed ? "true" : "false",
      evaluated ? "true" : "false", t1.trans_armse_m, t1.rot_armse_rad, t1.final_drift_m,
      t1.final_drift_pct, t1.gt_path_length_m, to_written_ms.size(),
      percentileMs(to_written_ms, 0.5), percentileMs(to_written_ms, 0.95),
      percentileMs(to_written_ms, 0.99),
      to_written_ms.empty() ? 0.0 : *std::max_element(to_written_ms.begin(), to_written_ms.end()),
      to_received_ms.size(), percentileMs(to_received_ms, 0.5), percentileMs(to_received_ms, 0.95),
      percentileMs(to_received_ms, 0.99),
      to_received_ms.empty() ? 0.0
                             : *std::max_element(to_received_ms.begin(), to_received_ms.end()),
      ok ? "true" : "false");
  std::printf("%s", json);
  if (!opt.json.empty()) std::ofstream(opt.json) << json;
  return ok ? 0 : 1;
}
