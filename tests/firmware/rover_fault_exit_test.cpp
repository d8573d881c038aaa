// The whole sunvo_rover program ends itself when a fault lasts past health.fault_exit_s: a replay
// of a drive whose every image is flat gray (nothing to track) keeps the estimator lost on every
// frame; the program must exit 1 within a few seconds, with journal lines (<4> the fault, <3> the
// fault exit) on stderr, READY=1 sent to $NOTIFY_SOCKET first and STOPPING=1 last.

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 60;  // 6 s at 10 Hz: longer than the limit below

// A KITTI raw drive of flat gray stereo pairs at 10 Hz, with the sample rig's calibration.
std::string writeFlatDrive(const fs::path& root) {
  fs::remove_all(root);
  const fs::path date = root / "2011_09_26";
  const fs::path drive = date / "2011_09_26_drive_0001_sync";
  fs::create_directories(date);
  for (const char* calib :
       {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"}) {
    fs::copy_file(std::string(SUNVO_DATA_DIR) + "/kitti_raw_sample/2011_09_26/" + calib,
                  date / calib);
  }
  const cv::Mat gray(375, 1242, CV_8UC1, cv::Scalar(128));
  // A standing vehicle: one OXTS record per frame (lat, lon, alt, roll, pitch, yaw, then zeros up
  // to KITTI's 30 fields).
  fs::create_directories(drive / "oxts" / "data");
  for (int k = 0; k < kFrames; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.txt", k);
    std::ofstream rec(drive / "oxts" / "data" / name);
    rec << "49.0 8.4 115.0 0 0 0";
    for (int f = 6; f < 30; ++f) rec << (f >= 23 && f < 25 ? " 4" : " 0");
    rec << "\n";
  }
  for (const char* cam : {"image_00", "image_01", "oxts"}) {
    fs::create_directories(drive / cam / "data");
    std::ofstream stamps(drive / cam / "timestamps.txt");
    const bool image = std::string(cam) != "oxts";
    for (int k = 0; k < kFrames; ++k) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.png", k);
      if (image) {
        EXPECT_TRUE(cv::imwrite((drive / cam / "data" / name).string(), gray));
      }
      char stamp[64];
      std::snprintf(stamp, sizeof(stamp), "2011-09-26 13:02:%02d.%09d", 10 + k / 10,
                    (k % 10) * 100'000'000);
      stamps << stamp << "\n";
    }
  }
  return drive.string();
}

TEST(RoverFaultExit, LostOnEveryFrameEndsTheProgramWithExit1) {
  const fs::path out = fs::path(SUNVO_BINARY_DIR) / "test_out" / "rover_fault_exit";
  const std::string drive = writeFlatDrive(out / "drive");
  ASSERT_FALSE(drive.empty());

  const std::string sock = (out / "notify.sock").string();
  fs::remove(sock);
  const int listener = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, sock.c_str(), sizeof(addr.sun_path) - 1);
  ASSERT_EQ(bind(listener, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0) << sock;
  // Room for every datagram of the run (the kernel queues few by default; systemd reads as they
  // come, this test reads at the end).
  const int rcvbuf = 1 << 20;
  setsockopt(listener, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));

  const std::string err = (out / "stderr.txt").string();
  const std::string cmd =
      "NOTIFY_SOCKET=" + sock + " " + std::string(SUNVO_TOOL_EMULATOR) + SUNVO_BINARY_DIR +
      "/bin/sunvo_rover --config " + SUNVO_SOURCE_DIR +
      "/config/rover_replay.yaml --set source.kitti.drive_dir=" + drive +
      " --set world.init=config --set sun.provider=none --set serial.device='\"\"'"
      " --set rt.lock_memory=false --set rt.heap_reserve_mb=0"
      " --set rt.threads='{capture: {fifo_priority: 0, cpu: -1}, estimator: {fifo_priority: 0, "
      "cpu: -1}, sun: {fifo_priority: 0, cpu: -1}, telemetry: {fifo_priority: 0, cpu: -1}}'"
      " --set health.fault_exit_s=2 --set health.watchdog_pose_age_s=1"
      " --set profiling.output_dir=" +
      out.string() + " > " + (out / "stdout.txt").string() + " 2> " + err;
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << cmd;
  EXPECT_EQ(WEXITSTATUS(status), 1) << cmd;

  std::stringstream text;
  text << std::ifstream(err).rdbuf();
  const std::string lines = text.str();
  EXPECT_NE(lines.find("<6>sunvo_rover: ready"), std::string::npos) << lines;
  EXPECT_NE(lines.find("<4>sunvo_rover: fault: estimator lost on every frame"), std::string::npos)
      << lines;
  EXPECT_NE(lines.find("<3>sunvo_rover: fault exit (health.fault_exit_s exceeded): estimator "
                       "lost on every frame"),
            std::string::npos)
      << lines;
  EXPECT_NE(lines.find("<3>sunvo_rover: exit 1 (fault exit)"), std::string::npos) << lines;

  std::vector<std::string> datagrams;
  char buf[512];
  ssize_t n;
  while ((n = recv(listener, buf, sizeof(buf), MSG_DONTWAIT)) > 0) {
    datagrams.emplace_back(buf, static_cast<std::size_t>(n));
  }
  close(listener);
  ASSERT_GE(datagrams.size(), 2u);
  EXPECT_EQ(datagrams.front(), "READY=1");
  EXPECT_EQ(datagrams.back(), "STOPPING=1");
}

}  // namespace
