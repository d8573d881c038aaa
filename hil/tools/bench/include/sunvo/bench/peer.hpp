#pragma once
// Peer visual odometry libraries timed on the same frames as sunvo's pipeline
// (sunvo_bench_vo --peer NAME). A peer is built outside this tree and never vendored: its adapter
// is compiled only when CMake is pointed at that build (libviso2: -DSUNVO_LIBVISO2_DIR=<dir>,
// docs/benchmarks.md "Peer: libviso2"). Without it, asking for the peer is a usage error.

#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "sunvo/bench/bench_support.hpp"
#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::bench {

// One peer odometry, fed stereo pairs in order.
class PeerOdometry {
 public:
  virtual ~PeerOdometry() = default;
  // One rectified pair, 8-bit grey of equal size (a colour pair is converted inside the call).
  // False when the peer's motion estimate failed for this pair.
  virtual bool process(const cv::Mat& left, const cv::Mat& right) = 0;
  virtual int matches() const = 0;          // matches the last motion estimate used
  virtual int inliers() const = 0;          // of which inliers
  virtual double translationM() const = 0;  // |t| of the last frame-to-frame motion, m
};

// The peers this build can run ("libviso2" when SUNVO_LIBVISO2_DIR was configured).
std::vector<std::string> availablePeers();

// Why `name` cannot run in this build; names the CMake variable that enables it.
std::string peerUnavailableMessage(const std::string& name);

// A fresh peer for `camera` (fu, cu, cv, baseline); kFailedPrecondition when not built in.
Expected<std::unique_ptr<PeerOdometry>> makePeer(const std::string& name,
                                                 const StereoCamera& camera);

// Per timed frame of one peer run.
struct PeerRun {
  std::string name;
  std::vector<double> wall_ms;        // steady clock around the peer's per-frame call
  std::vector<double> cpu_ms;         // thread CPU time around the same call
  std::vector<double> matches;        // matches the peer's motion estimate used
  std::vector<double> inliers;        // of which inliers
  std::vector<double> translation_m;  // |t| of the frame-to-frame motion (sanity, not accuracy)
  int failures = 0;                   // frames whose motion estimate failed
};

// Times one call of peer.process on frame `index` of the pingPong order and records it in run.
void timePeerFrame(PeerOdometry& peer, const KittiFrames& data, std::size_t index, PeerRun& run);

// Runs peer `name` over data.frames in the order sunvo_bench_vo uses (pingPong): config.warmup
// untimed frames, then config.frames timed ones, on the calling thread (so on the CPU the
// process was pinned to).
Expected<PeerRun> runPeer(const std::string& name, const KittiFrames& data,
                          const BenchConfig& config);

}  // namespace sunvo::bench
