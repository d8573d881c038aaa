#pragma once
// sunvo_rover's running program: four threads around bounded SPSC rings and one frame pool.
//
//   trigger + source --capture--> [frames ring, drop-oldest] --estimator--> [poses ring]
//   --telemetry--> port
//                        |                                        ^
//                        +--> [sun requests] --sun--> [sun results]
//
// One class per stage (src/stages.hpp); RoverApp only wires them and owns their threads.
// capture:   waits for a trigger, takes a free pool slot, grabs the stereo pair into it, queues
//            the slot index; every n-th frame also queues a sun request (frame time, index).
// estimator: pipeline::SunAidedOdometry. Before each frame it hands over the sun results that
//            arrived; for a sun frame it waits at most realtime.sun_wait_ms for that frame's
//            result (the window, size 2, keeps the frame's rotation free only while it is the
//            newest). The solver's time budget shrinks when the frame is late:
//              budget = clamp(deadline - age - (front end + RANSAC, running mean) - margin,
//                             min_solver_time, max_solver_time),  age = dequeue - trigger.
// sun:       NREL SPA at the configured position and frame UTC -> sun in the ENU world; the
//            provider's measurement in the camera; both back to the estimator. Off the critical
//            path (low priority; a late result is counted and dropped by the window).
// telemetry: each pose -> PoseLink (MAVLink ODOMETRY), HEARTBEAT at heartbeat_hz; the time the
//            frame's last byte left is the frame's publish stamp; trigger -> last byte above
//            realtime.deadline_ms is a deadline miss.
// Every buffer is allocated in create(); the capture and telemetry loops allocate nothing per
// frame (measured by the allocation meters when the executable installs a probe).

#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/gpio/gpio_api.hpp"
#include "sunvo/rover/config.hpp"
#include "sunvo/rover/health_watch.hpp"
#include "sunvo/rover/pose_link.hpp"
#include "sunvo/rover/sources.hpp"
#include "sunvo/rover/sun_provider.hpp"
#include "sunvo/sysio/sysio.hpp"

namespace sunvo::rover {

// The kernel seams the V4L2 source and the GPIO trigger use (source.type v4l2, trigger.type
// gpio). On the rover: sysio::linuxSysIo() and gpio::libgpiodApi(); tests pass the emulated
// devices of hil/sim/emulated_devices. Both must outlive the RoverApp.
struct RoverDevices {
  sysio::SysIo* io = nullptr;
  gpio::GpioApi* gpio = nullptr;
};
// linuxSysIo() and libgpiodApi().
RoverDevices productionDevices();

class RoverApp {
 public:
  // Opens the source, the trigger and the sun provider, sizes every buffer, initialises the
  // estimator. link may be null (no pose stream: publish = dequeue by telemetry). devices are
  // used by source.type v4l2 / trigger.type gpio only.
  static Expected<std::unique_ptr<RoverApp>> create(const RoverConfig& config,
                                                    std::unique_ptr<PoseLink> link,
                                                    const RoverDevices& devices);
  ~RoverApp();
  RoverApp(const RoverApp&) = delete;
  RoverApp& operator=(const RoverApp&) = delete;

  // Starts the four threads. Warnings (rt settings not permitted) are returned, one per line.
  std::vector<std::string> start();
  // Asks every thread to finish: capture stops, queued frames are dropped, queued poses are sent.
  void requestStop();
  // True once the telemetry thread has finished: after requestStop(), or when a replay with
  // end: stop has published its last pose (never for end: hold before a stop), or when capture
  // stopped on a persistent source fault (sourceFailed()).
  bool finished() const;
  // Waits for the threads (after requestStop() or finished()).
  void join();

  // Latency CSV, Chrome trace and stage summary into profiling.output_dir, named <tag>_*.
  // Returns the stage summary text. Safe while running (SIGUSR1).
  Expected<std::string> writeProfile(const std::string& tag) const;
  // True when capture stopped because the frame source failed more than
  // source.max_consecutive_bad_frames times in a row (the run then ends as a replay's end does).
  bool sourceFailed() const;
  // Frames the estimator has processed so far (any thread).
  std::uint64_t framesProcessed() const;
  // The health counters at `now` (monotonic), for HealthWatch (any thread, no allocation).
  HealthSample healthSample(TimeNs now) const;
  // The frame source in words: the V4L2 device(s), or "replay <drive_dir>".
  std::string cameraName() const;

  // Final summary: frames, drops per queue, deadline misses, tracking, sun, serial, latency.
  std::string summary() const;

  struct Impl;

 private:
  explicit RoverApp(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sunvo::rover
