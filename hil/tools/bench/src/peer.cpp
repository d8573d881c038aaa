// sunvo_bench_vo --peer: which peers this build has, and the timing loop they share.
#include "sunvo/bench/peer.hpp"

#include <chrono>

namespace sunvo::bench {

#ifdef SUNVO_HAVE_LIBVISO2
// peer_libviso2.cpp, compiled only when SUNVO_LIBVISO2_DIR is set.
std::unique_ptr<PeerOdometry> makeLibviso2(const StereoCamera& camera);
#endif

std::vector<std::string> availablePeers() {
#ifdef SUNVO_HAVE_LIBVISO2
  return {"libviso2"};
#else
  return {};
#endif
}

std::string peerUnavailableMessage(const std::string& name) {
  if (name == "libviso2") {
    return "peer 'libviso2' is not built in: configure with -DSUNVO_LIBVISO2_DIR=<dir> (a "
           "libviso2 build made outside the tree by scripts/build_libviso2_peer.sh, holding "
           "include/viso_stereo.h and lib/libviso2.a; docs/benchmarks.md \"Peer: libviso2\")";
  }
  return "unknown peer '" + name + "' (known: libviso2)";
}

Expected<std::unique_ptr<PeerOdometry>> makePeer(const std::string& name,
                                                 const StereoCamera& camera) {
#ifdef SUNVO_HAVE_LIBVISO2
  if (name == "libviso2") return makeLibviso2(camera);
#else
  (void)camera;
#endif
  return Status(StatusCode::kFailedPrecondition, peerUnavailableMessage(name));
}

void timePeerFrame(PeerOdometry& peer, const KittiFrames& data, std::size_t index, PeerRun& run) {
  const StereoFrame& f = data.frames[pingPong(index, data.frames.size())];
  const double cpu0 = threadCpuMs();
  const auto t0 = std::chrono::steady_clock::now();
  const bool ok = peer.process(f.left, f.right);
  const auto t1 = std::chrono::steady_clock::now();
  const double cpu1 = threadCpuMs();
  run.wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  run.cpu_ms.push_back(cpu1 - cpu0);
  run.matches.push_back(peer.matches());
  run.inliers.push_back(peer.inliers());
  if (ok) {
    run.translation_m.push_back(peer.translationM());
  } else {
    ++run.failures;
  }
}

Expected<PeerRun> runPeer(const std::string& name, const KittiFrames& data,
                          const BenchConfig& config) {
  if (data.frames.size() < 2)
    return Status(StatusCode::kInvalidArgument, "peer: needs >= 2 frames");
  auto peer = makePeer(name, data.camera);
  if (!peer) return peer.status();
  PeerRun run;
  run.name = name;
  std::size_t i = 0;
  for (int w = 0; w < config.warmup; ++w, ++i) {
    const StereoFrame& f = data.frames[pingPong(i, data.frames.size())];
    (void)(*peer)->process(f.left, f.right);
  }
  for (int k = 0; k < config.frames; ++k, ++i) timePeerFrame(**peer, data, i, run);
  return run;
}

}  // namespace sunvo::bench
