// Dispatch of sunvo_bench_vo --peer: which peers this build has (see peer.hpp).
#include "sunvo/bench/peer.hpp"

namespace sunvo::bench {

#ifdef SUNVO_HAVE_LIBVISO2
// peer_libviso2.cpp, compiled only when SUNVO_LIBVISO2_DIR is set.
Expected<PeerRun> runLibviso2(const KittiFrames& data, const BenchConfig& config);
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

Expected<PeerRun> runPeer(const std::string& name, const KittiFrames& data,
                          const BenchConfig& config) {
#ifdef SUNVO_HAVE_LIBVISO2
  if (name == "libviso2") return runLibviso2(data, config);
#else
  (void)data;
  (void)config;
#endif
  return Status(StatusCode::kFailedPrecondition, peerUnavailableMessage(name));
}

}  // namespace sunvo::bench
