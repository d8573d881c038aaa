// The MAVLink v2 stream decoder as sunvo_pose_reader uses it: bytes in, frames out (push, then
// next until false), ODOMETRY / HEARTBEAT payloads decoded. A decoded ODOMETRY re-encodes to a
// frame that decodes to the same message.
#include <cstring>

#include "fuzz_support.hpp"
#include "sunvo/mavlink/mavlink.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sunvo;
  mavlink::Decoder decoder;
  std::uint64_t frames = 0;
  for (std::size_t i = 0; i < size; ++i) {
    mavlink::Frame f;
    if (!decoder.push(data[i], &f)) continue;
    do {
      ++frames;
      mavlink::Odometry odo;
      mavlink::Heartbeat hb;
      if (mavlink::decodeOdometry(f, &odo)) {
        std::uint8_t buf[mavlink::kMaxFrameBytes];
        const std::size_t n =
            mavlink::encodeOdometry(odo, {f.system_id, f.component_id}, f.seq, buf);
        mavlink::Decoder again;
        mavlink::Frame g;
        bool got = false;
        for (std::size_t j = 0; j < n && !got; ++j) got = again.push(buf[j], &g);
        mavlink::Odometry odo2;
        fuzz::check(got && mavlink::decodeOdometry(g, &odo2), "odometry: re-encode lost");
        fuzz::check(
            std::memcmp(&odo.x, &odo2.x, sizeof(float)) == 0 && odo.time_usec == odo2.time_usec,
            "odometry: re-encode changed the message");
      } else {
        (void)mavlink::decodeHeartbeat(f, &hb);
      }
    } while (decoder.next(&f));
  }
  fuzz::check(decoder.counters().frames_ok == frames, "decoder: frames_ok != frames returned");
  return 0;
}
