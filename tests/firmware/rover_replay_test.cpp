// The whole program on a rendered drive: sunvo_pose_reader opens a pseudo-terminal, starts
// sunvo_rover (config/rover_replay.yaml) writing its MAVLink stream into it, decodes every pose,
// stops the program with SIGTERM, and evaluates accuracy and latency. Compared with the
// sequential replay (sunvo_replay's chain) on the same frames.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "../support/recording_link.hpp"
#include "../support/render_once.hpp"
#include "../support/temp_dir.hpp"
#include "sunvo/metrics/metrics.hpp"
#include "sunvo/render/drive.hpp"
#include "sunvo/replay/replay.hpp"
#include "sunvo/rover/app.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/runtime/clock.hpp"

namespace sunvo {
namespace {

namespace fs = std::filesystem;

// The 100-frame CI drive when scripts/demo.sh has rendered it into this build's render cache;
// otherwise the first 20 frames of the same scenario, rendered once (as tests/replay does) and
// kept in test_render_cache/rover_20.
std::string findOrRenderDrive(int* frames) {
  const fs::path cache = fs::path(SUNVO_BINARY_DIR) / "render_cache" / "ci_short";
  if (fs::exists(cache)) {
    for (const auto& date : fs::directory_iterator(cache)) {
      if (!date.is_directory()) continue;
      for (const auto& d : fs::directory_iterator(date.path())) {
        if (d.path().filename().string().ends_with("_sync") &&
            fs::exists(d.path() / "gt" / "poses_cam0_enu.txt")) {
          *frames = 100;
          return d.path().string();
        }
      }
    }
  }
  auto scenario =
      render::loadScenario(std::string(SUNVO_SOURCE_DIR) + "/config/scenarios/ci_short.yaml");
  if (!scenario) return {};
  scenario->frames = 20;
  *frames = 20;
  // The tests of this file run in parallel under ctest -j: one renders, the others wait for it.
  return sunvo::testing::renderOnce(*scenario,
                                    fs::path(SUNVO_BINARY_DIR) / "test_render_cache" / "rover_20",
                                    "gt/poses_cam0_enu.txt");
}

double jsonNumber(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": ([-0-9.eE]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) {
    ADD_FAILURE() << "no " << key << " in " << json;
    return -1.0;
  }
  return std::atof(m[1].str().c_str());
}

struct ProgramRun {
  int rc = -1;
  std::string json;  // sunvo_pose_reader's evaluation
  std::string log;   // sunvo_rover's output (start-up lines and the final summary)
};

// sunvo_pose_reader runs sunvo_rover (config/rover_replay.yaml on `drive`, extra --set options
// appended) into a pty and evaluates what arrives; everything goes to test_out/<name>.
ProgramRun runProgram(const std::string& drive, int frames, const std::string& name,
                      const std::string& extra_sets) {
  const fs::path out = fs::path(SUNVO_BINARY_DIR) / "test_out" / name;
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string emu = SUNVO_TOOL_EMULATOR;
  const std::string bin = SUNVO_BINARY_DIR;
  const std::string cmd =
      emu + bin + "/bin/sunvo_pose_reader --drive " + drive + " --frames " +
      std::to_string(frames) + " --timeout-s 45 --json " + (out / "reader.json").string() +
      " --child-log " + (out / "rover.log").string() + " --latency-csv " +
      (out / "final_latency.csv").string() + " -- " + emu + bin + "/bin/sunvo_rover --config " +
      SUNVO_SOURCE_DIR + "/config/rover_replay.yaml --set source.kitti.drive_dir=" + drive +
      " --set sun.csv=" + drive +
      "/gt/sun_cam0.csv --set serial.device={pty} --set profiling.output_dir=" + out.string() +
      extra_sets + " > " + (out / "reader.txt").string() + " 2>&1";
  ProgramRun run;
  run.rc = std::system(cmd.c_str());
  std::stringstream json_text, log_text;
  json_text << std::ifstream(out / "reader.json").rdbuf();
  log_text << std::ifstream(out / "rover.log").rdbuf();
  run.json = json_text.str();
  run.log = log_text.str();
  std::printf("%s\n%s\n", run.log.c_str(), run.json.c_str());
  return run;
}

TEST(RoverReplay, WholeProgramIntoAPseudoTerminal) {
  int frames = 0;
  const std::string drive = findOrRenderDrive(&frames);
  ASSERT_FALSE(drive.empty()) << "no rendered drive";
  const fs::path out = fs::path(SUNVO_BINARY_DIR) / "test_out" / "rover_replay";
  const ProgramRun run = runProgram(drive, frames, "rover_replay", "");
  const int rc = run.rc;
  const std::string& json = run.json;
  std::stringstream log_text(run.log);
  EXPECT_EQ(rc, 0);
  // Every pose arrived once, CRCs good, clean shutdown on SIGTERM with the summary.
  EXPECT_EQ(jsonNumber(json, "odometry_received"), frames);
  EXPECT_EQ(jsonNumber(json, "missing"), 0);
  EXPECT_EQ(jsonNumber(json, "crc_errors"), 0);
  EXPECT_EQ(jsonNumber(json, "seq_gaps"), 0);
  EXPECT_GE(jsonNumber(json, "heartbeats"), 1);
  EXPECT_NE(json.find("\"clean_exit\": true"), std::string::npos);
  EXPECT_NE(json.find("\"summary_printed\": true"), std::string::npos);
  EXPECT_NE(log_text.str().find("queue frames"), std::string::npos);
  // Every frame went through the profiler; its latency reached the reader.
  EXPECT_EQ(jsonNumber(json, "n"), frames);
  EXPECT_TRUE(fs::exists(out / "final_trace.json"));

  // Accuracy close to the sequential replay of the same frames with the same true sun.
  replay::ReplayOptions ro;
  ro.dataset.path = drive;
  ro.dataset.last_frame = frames - 1;
  auto data = replay::openReplayDataset(ro);
  ASSERT_TRUE(data) << data.status().toString();
  auto seq = replay::replayDrive(*data, ro, experiment::defaultSunSources(1)[0]);
  ASSERT_TRUE(seq) << seq.status().toString();
  metrics::EvaluationOptions eo;
  eo.plane = metrics::HorizontalPlane::kEastNorth;
  auto ev = metrics::evaluate(data->groundTruth(), seq->T_w_c, eo);
  ASSERT_TRUE(ev);
  const double drift_rover = jsonNumber(json, "final_drift_m");
  const double rot_rover = jsonNumber(json, "rot_armse_rad");
  std::printf("final drift: program %.4f m, sequential replay %.4f m; rot ARMSE %.3g / %.3g rad\n",
              drift_rover, ev->table1.final_drift_m, rot_rover, ev->table1.rot_armse_rad);
  EXPECT_LT(std::abs(drift_rover - ev->table1.final_drift_m),
            0.02 + 0.5 * ev->table1.final_drift_m);
  EXPECT_LT(rot_rover, 2.0 * ev->table1.rot_armse_rad + 1e-3);
}

// sun.provider: sun_cnn with the repo's model: the program starts, the KITTI source delivers the
// left colour image, and the sun thread runs the CNN on every fifth frame (frames 5, 10, ...),
// each call answered without error, while every pose still arrives.
TEST(RoverReplay, SunCnnProviderEveryFifthFrame) {
  int frames = 0;
  const std::string drive = findOrRenderDrive(&frames);
  ASSERT_FALSE(drive.empty()) << "no rendered drive";
  const ProgramRun run = runProgram(drive, frames, "rover_sun_cnn",
                                    std::string(" --set sun.provider=sun_cnn --set sun.model=") +
                                        SUNVO_SOURCE_DIR + "/config/sun_cnn.onnx");
  EXPECT_EQ(run.rc, 0);
  EXPECT_EQ(jsonNumber(run.json, "odometry_received"), frames);
  const std::regex re(
      "sun \\(sun_cnn\\): requests ([0-9]+), measurements ([0-9]+), errors ([0-9]+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.log, m, re)) << run.log;
  const int expected_calls = (frames - 1) / 5;  // sequences 5, 10, ... below frames
  EXPECT_EQ(std::atoi(m[1].str().c_str()), expected_calls);
  EXPECT_EQ(std::atoi(m[3].str().c_str()), 0);  // no call lacked its colour image or failed
  const std::regex results("queue sun_results +cap [0-9]+: pushed ([0-9]+)");
  ASSERT_TRUE(std::regex_search(run.log, m, results)) << run.log;
  EXPECT_EQ(std::atoi(m[1].str().c_str()), expected_calls);  // every call answered
}

// estimator.vertical.enabled without a sun provider (config/rover.yaml's deployment setting): the
// cue runs in the sun thread on every fifth frame, every call is answered and its "up" reaches the
// fusion in time, the estimator thread allocates nothing after the warm-up (the cue does, in the
// sun thread), and every pose still arrives.
TEST(RoverReplay, VerticalCueInTheSunThread) {
  int frames = 0;
  const std::string drive = findOrRenderDrive(&frames);
  ASSERT_FALSE(drive.empty()) << "no rendered drive";
  const ProgramRun run = runProgram(drive, frames, "rover_vertical",
                                    " --set sun.provider=none --set estimator.vertical.enabled=true"
                                    " --set realtime.sun_wait_ms=60");
  EXPECT_EQ(run.rc, 0);
  EXPECT_EQ(jsonNumber(run.json, "odometry_received"), frames);
  const std::regex re(
      "vertical cue \\(sun thread\\): calls ([0-9]+), valid ([0-9]+), refused images ([0-9]+), "
      "accepted ([0-9]+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.log, m, re)) << run.log;
  const int expected_calls = (frames - 1) / 5;  // sequences 5, 10, ... below frames
  EXPECT_EQ(std::atoi(m[1].str().c_str()), expected_calls);
  EXPECT_EQ(std::atoi(m[3].str().c_str()), 0);
  EXPECT_GT(std::atoi(m[2].str().c_str()), expected_calls / 2);  // the CI drive: 39 of 39
  EXPECT_GT(std::atoi(m[4].str().c_str()), 0);
  const std::regex alloc("allocations after warm-up, estimator +([0-9]+) in");
  if (std::regex_search(run.log, m, alloc)) {
    EXPECT_EQ(std::atoi(m[1].str().c_str()), 0);
  }
}

// The start levelled from the cue's first three answers (config/rover.yaml's setting,
// docs/start_levelling.md): the answers of frames 5, 10 and 15 measure the
// start's tilt error, and the summary and the journal report it. The replay starts from the
// drive's OXTS pose, so the error is small, within the answers' noise, and left to the filter.
TEST(RoverReplay, StartLevelledFromTheCue) {
  int frames = 0;
  const std::string drive = findOrRenderDrive(&frames);
  ASSERT_FALSE(drive.empty()) << "no rendered drive";
  const ProgramRun run = runProgram(drive, frames, "rover_level",
                                    " --set sun.provider=none --set estimator.vertical.enabled=true"
                                    " --set realtime.sun_wait_ms=60"
                                    " --set estimator.fusion.world_up_alignment_frames=15"
                                    " --set estimator.fusion.world_up_alignment_use=start_tilt");
  EXPECT_EQ(run.rc, 0);
  EXPECT_EQ(jsonNumber(run.json, "odometry_received"), frames);
  std::smatch m;
  const std::regex level(
      "start tilt: ([0-9.]+) deg measured from ([0-9]+) cue answers \\(within their noise: left to "
      "the filter\\)");
  ASSERT_TRUE(std::regex_search(run.log, m, level)) << run.log;
  EXPECT_LT(std::atof(m[1].str().c_str()), 0.5);
  EXPECT_EQ(std::atoi(m[2].str().c_str()), 3);
  // The journal's event line (info priority), once.
  const std::regex event(
      "<6>sunvo_rover: start tilt: [0-9.]+ deg measured from 3 vertical-cue answers");
  EXPECT_TRUE(std::regex_search(run.log, m, event)) << run.log;
}

// A copy of the rendered drive's gray images, OXTS and calibration (no colour pair) with injected
// image faults: frame 3's left image missing, frame 4's right image truncated, frame 9's left
// image of the wrong size and frame 14's right image with three channels.
struct FaultyDrive {
  sunvo::testing::TempDir dir;
  std::string drive;
  std::vector<std::uint64_t> bad{3, 4, 9, 14};
};

void makeFaultyDrive(const std::string& rendered, FaultyDrive* out) {
  const fs::path src(rendered);
  const fs::path day = fs::path(out->dir.str()) / src.parent_path().filename();
  const fs::path drive = day / src.filename();
  fs::create_directories(drive);
  for (const auto& f : fs::directory_iterator(src.parent_path())) {
    if (f.is_regular_file()) fs::copy_file(f.path(), day / f.path().filename());
  }
  for (const char* sub : {"image_00", "image_01", "oxts"}) {
    fs::copy(src / sub, drive / sub, fs::copy_options::recursive);
  }
  out->drive = drive.string();
  const auto image = [&](int camera, int frame) {
    char name[64];
    std::snprintf(name, sizeof(name), "image_%02d/data/%010d.png", camera, frame);
    return (drive / name).string();
  };
  fs::remove(image(0, 3));
  fs::resize_file(image(1, 4), fs::file_size(image(1, 4)) / 3);
  ASSERT_TRUE(cv::imwrite(image(0, 9), cv::Mat(100, 200, CV_8UC1, cv::Scalar(90))));
  ASSERT_TRUE(cv::imwrite(image(1, 14), cv::Mat(375, 1242, CV_8UC3, cv::Scalar(90))));
}

struct InProcessRun {
  std::vector<rover::PoseRecord> poses;
  std::string summary;
  bool source_failed = false;
  bool finished = false;
};

// RoverApp in-process on config/rover_replay.yaml (pure VO, poses recorded, end: stop) until it
// finishes on its own (bounded).
InProcessRun runInProcess(const std::string& drive,
                          std::vector<std::pair<std::string, std::string>> sets) {
  InProcessRun run;
  sets.insert(
      sets.begin(),
      {{"source.kitti.drive_dir", drive},
       {"source.kitti.end", "stop"},
       {"sun.provider", "none"},
       {"serial.device", "\"\""},
       {"rt.lock_memory", "false"},
       {"rt.heap_reserve_mb", "0"},
       {"rt.threads",
        "{capture: {fifo_priority: 0, cpu: -1}, estimator: {fifo_priority: 0, cpu: -1}, "
        "sun: {fifo_priority: 0, cpu: -1}, telemetry: {fifo_priority: 0, cpu: -1}}"},
       {"realtime.warmup_frames", "0"},
       {"realtime.deadline_ms", "1000"},
       {"profiling.output_dir", std::string(SUNVO_BINARY_DIR) + "/test_out/rover_bad_frames"}});
  auto config =
      rover::loadRoverConfig(std::string(SUNVO_SOURCE_DIR) + "/config/rover_replay.yaml", sets);
  EXPECT_TRUE(config.hasValue()) << config.status().toString();
  if (!config) return run;
  auto link = std::make_unique<sunvo::testing::RecordingLink>();
  sunvo::testing::RecordingLink* recorder = link.get();
  auto app = rover::RoverApp::create(*config, std::move(link), rover::productionDevices());
  EXPECT_TRUE(app.hasValue()) << app.status().toString();
  if (!app) return run;
  (*app)->start();
  const TimeNs give_up = runtime::monotonicNs() + 60'000'000'000;
  while (!(*app)->finished() && runtime::monotonicNs() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  run.finished = (*app)->finished();
  run.source_failed = (*app)->sourceFailed();
  (*app)->requestStop();
  (*app)->join();
  run.poses = recorder->poses();
  run.summary = (*app)->summary();
  std::printf("%s", run.summary.c_str());
  return run;
}

std::uint64_t summaryCount(const std::string& summary, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(summary, m, std::regex(pattern))) {
    ADD_FAILURE() << "no '" << pattern << "' in " << summary;
    return 0;
  }
  return std::strtoull(m[1].str().c_str(), nullptr, 10);
}

// Bad images in the replay drive: each frame is dropped and counted as a grab error, VO goes on
// from the last good frame, with and without preload; a fault that persists past
// source.max_consecutive_bad_frames stops capture and marks the run failed.
TEST(RoverReplay, BadImagesAreDroppedCountedAndAPersistentFaultStops) {
  int frames = 0;
  const std::string rendered = findOrRenderDrive(&frames);
  ASSERT_FALSE(rendered.empty()) << "no rendered drive";
  frames = 20;  // the first 20 frames are enough
  FaultyDrive faulty;
  makeFaultyDrive(rendered, &faulty);
  if (HasFatalFailure()) return;
  replay::ReplayOptions ro;
  ro.dataset.path = rendered;
  ro.dataset.last_frame = frames - 1;
  auto truth = replay::openReplayDataset(ro);
  ASSERT_TRUE(truth) << truth.status().toString();

  for (const char* preload : {"true", "false"}) {
    SCOPED_TRACE(std::string("preload ") + preload);
    const InProcessRun run =
        runInProcess(faulty.drive, {{"source.kitti.preload", preload},
                                    {"source.kitti.last_frame", std::to_string(frames - 1)}});
    EXPECT_TRUE(run.finished);
    EXPECT_FALSE(run.source_failed);
    EXPECT_EQ(summaryCount(run.summary, "grab errors ([0-9]+)"), faulty.bad.size());
    EXPECT_EQ(summaryCount(run.summary, "grab errors in a row: at most ([0-9]+)"), 2u);
    ASSERT_EQ(run.poses.size(), static_cast<std::size_t>(frames) - faulty.bad.size());
    std::vector<std::uint64_t> expected;
    for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(frames); ++k) {
      if (std::find(faulty.bad.begin(), faulty.bad.end(), k) == faulty.bad.end()) {
        expected.push_back(k);
      }
    }
    std::vector<std::uint64_t> got;
    for (const rover::PoseRecord& p : run.poses) got.push_back(p.sequence);
    EXPECT_EQ(got, expected);
    // VO went on from the last good frame: the final position is still close to the truth.
    const rover::PoseRecord& last = run.poses.back();
    const Eigen::Vector3d p_w(last.p_w[0], last.p_w[1], last.p_w[2]);
    const double error_m = (p_w - truth->groundTruth()[last.sequence].translation()).norm();
    std::printf("final position error with %zu dropped frames: %.4f m\n", faulty.bad.size(),
                error_m);
    EXPECT_LT(error_m, 0.2);
  }
  // Frames 3 and 4 are bad in a row: a limit of 1 stops capture at frame 4.
  const InProcessRun stopped =
      runInProcess(faulty.drive, {{"source.max_consecutive_bad_frames", "1"},
                                  {"source.kitti.last_frame", std::to_string(frames - 1)},
                                  {"source.kitti.end", "hold"}});
  EXPECT_TRUE(stopped.finished);  // even with end: hold
  EXPECT_TRUE(stopped.source_failed);
  EXPECT_EQ(stopped.poses.size(), 3u);  // frames 0, 1, 2
  EXPECT_NE(stopped.summary.find("capture stopped, the source fault persisted"), std::string::npos);
}

// Random faults at the capture seams (source.faults): every injected fault shows in the health
// counter that must account for it, poses keep coming, none is NaN, and VO ends near the truth.
TEST(RoverReplay, RandomFaultsAreCountedByTheHealthCounters) {
  int frames = 0;
  const std::string rendered = findOrRenderDrive(&frames);
  ASSERT_FALSE(rendered.empty()) << "no rendered drive";
  frames = std::min(frames, 60);
  const InProcessRun run =
      runInProcess(rendered, {{"source.kitti.last_frame", std::to_string(frames - 1)},
                              {"source.faults.seed", "5"},
                              {"source.faults.missed_trigger_rate", "0.08"},
                              {"source.faults.bad_frame_rate", "0.08"},
                              {"source.faults.dark_frame_rate", "0.08"}});
  EXPECT_TRUE(run.finished);
  EXPECT_FALSE(run.source_failed);
  const std::uint64_t missed = summaryCount(run.summary, "missed triggers ([0-9]+)");
  const std::uint64_t bad = summaryCount(run.summary, "bad frames ([0-9]+)");
  const std::uint64_t dark = summaryCount(run.summary, "dark frames ([0-9]+)");
  EXPECT_GT(missed + bad + dark, 3u);  // 60 frames at 8 % each: about 14 expected
  EXPECT_EQ(summaryCount(run.summary, "missed ([0-9]+)"), missed);
  EXPECT_EQ(summaryCount(run.summary, "grab errors ([0-9]+)"), bad);
  // A black frame loses tracking once; the next good frame restarts it (measured: 2 dark frames,
  // 2 losses, 2 recoveries, 4 lost frames: the dark one and the restart).
  EXPECT_EQ(summaryCount(run.summary, "tracking: losses ([0-9]+)"), dark);
  EXPECT_EQ(summaryCount(run.summary, "recoveries ([0-9]+)"), dark);
  EXPECT_EQ(run.poses.size(), static_cast<std::size_t>(frames) - missed - bad);
  for (const rover::PoseRecord& p : run.poses) {
    ASSERT_TRUE(std::isfinite(p.p_w[0]) && std::isfinite(p.p_w[1]) && std::isfinite(p.p_w[2]));
  }
}

}  // namespace
}  // namespace sunvo
