// MAVLink v2 framing: CRC, header layout, payload truncation, round trips through the streaming
// decoder, resynchronisation after corruption, and the encode time.

#include "sunvo/mavlink/mavlink.hpp"

#include <gtest/gtest.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "../support/telemetry.hpp"

namespace sunvo::mavlink {
namespace {

using sunvo::testing::sampleOdometry;

std::vector<Frame> decodeAll(Decoder& decoder, const std::vector<std::uint8_t>& bytes) {
  return sunvo::testing::decodeAll(bytes, &decoder);
}

void expectSameOdometry(const Odometry& a, const Odometry& b) {
  EXPECT_EQ(a.time_usec, b.time_usec);
  EXPECT_EQ(a.frame_id, b.frame_id);
  EXPECT_EQ(a.child_frame_id, b.child_frame_id);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.vx, b.vx);
  EXPECT_EQ(a.vy, b.vy);
  EXPECT_EQ(a.vz, b.vz);
  EXPECT_EQ(a.rollspeed, b.rollspeed);
  EXPECT_EQ(a.pitchspeed, b.pitchspeed);
  EXPECT_EQ(a.yawspeed, b.yawspeed);
  EXPECT_EQ(a.pose_covariance, b.pose_covariance);
  EXPECT_EQ(a.velocity_covariance, b.velocity_covariance);
  EXPECT_EQ(a.reset_counter, b.reset_counter);
  EXPECT_EQ(a.estimator_type, b.estimator_type);
  EXPECT_EQ(a.quality, b.quality);
}

TEST(Crc, MatchesTheCrc16Mcrf4xxCheckValue) {
  // The catalogue check value of CRC-16/MCRF4XX is the CRC of the ASCII digits "123456789".
  const char* digits = "123456789";
  EXPECT_EQ(crcCalculate(reinterpret_cast<const std::uint8_t*>(digits), 9), 0x6F91);
}

TEST(Encode, HeartbeatHeaderPayloadAndCrc) {
  std::uint8_t buf[kMaxFrameBytes];
  Heartbeat hb;
  hb.custom_mode = 0x01020304;
  const std::size_t n = encodeHeartbeat(hb, Endpoint{7, 197}, 42, buf);
  ASSERT_EQ(n, kHeaderBytes + kPayloadBytesHeartbeat + kChecksumBytes);
  EXPECT_EQ(buf[0], 0xFD);
  EXPECT_EQ(buf[1], 9);  // mavlink_version = 3 is the last byte: nothing to cut
  EXPECT_EQ(buf[2], 0);  // unsigned
  EXPECT_EQ(buf[3], 0);
  EXPECT_EQ(buf[4], 42);  // seq
  EXPECT_EQ(buf[5], 7);   // sysid
  EXPECT_EQ(buf[6], 197);
  EXPECT_EQ(buf[7], 0);
  EXPECT_EQ(buf[8], 0);
  EXPECT_EQ(buf[9], 0);
  // custom_mode (uint32, little-endian) first, then type, autopilot, base_mode, system_status,
  // mavlink_version.
  const std::uint8_t payload[9] = {0x04, 0x03, 0x02, 0x01, 18, 8, 0, 4, 3};
  EXPECT_EQ(std::memcmp(buf + kHeaderBytes, payload, 9), 0);
  std::uint16_t crc = crcCalculate(buf + 1, 9 + 9);
  crc = crcAccumulate(kCrcExtraHeartbeat, crc);
  EXPECT_EQ(buf[19], crc & 0xFF);
  EXPECT_EQ(buf[20], crc >> 8);
}

TEST(Encode, OdometryMsgIdIs24BitLittleEndian) {
  std::uint8_t buf[kMaxFrameBytes];
  const std::size_t n = encodeOdometry(sampleOdometry(), Endpoint{}, 0, buf);
  EXPECT_EQ(n, kHeaderBytes + kPayloadBytesOdometry + kChecksumBytes);  // quality != 0: no cut
  EXPECT_EQ(buf[7], 331 & 0xFF);
  EXPECT_EQ(buf[8], 331 >> 8);
  EXPECT_EQ(buf[9], 0);
  // time_usec leads the payload (largest type first), frame ids follow the float arrays.
  std::uint64_t t = 0;
  for (int i = 0; i < 8; ++i) t |= static_cast<std::uint64_t>(buf[kHeaderBytes + i]) << (8 * i);
  EXPECT_EQ(t, sampleOdometry().time_usec);
  EXPECT_EQ(buf[kHeaderBytes + 228], kMavFrameLocalNed);
  EXPECT_EQ(buf[kHeaderBytes + 229], kMavFrameBodyFrd);
  EXPECT_EQ(buf[kHeaderBytes + 232], 87);
}

TEST(Encode, TrailingZeroBytesAreCutAndRestoredByTheDecoder) {
  Odometry m = sampleOdometry();
  m.quality = 0;
  m.estimator_type = 0;
  m.reset_counter = 0;
  std::uint8_t buf[kMaxFrameBytes];
  const std::size_t n = encodeOdometry(m, Endpoint{}, 1, buf);
  // The three extension bytes are zero; child_frame_id (offset 229) = 12 ends the payload.
  EXPECT_EQ(buf[1], 230);
  EXPECT_EQ(n, kHeaderBytes + 230 + kChecksumBytes);
  Decoder decoder;
  const auto frames = decodeAll(decoder, std::vector<std::uint8_t>(buf, buf + n));
  ASSERT_EQ(frames.size(), 1u);
  Odometry back;
  ASSERT_TRUE(decodeOdometry(frames[0], &back));
  expectSameOdometry(m, back);

  // An all-zero payload keeps its first byte, as the spec requires.
  Odometry zero;
  zero.q = {0, 0, 0, 0};
  zero.frame_id = 0;
  zero.child_frame_id = 0;
  zero.estimator_type = 0;
  EXPECT_EQ(encodeOdometry(zero, Endpoint{}, 2, buf), kHeaderBytes + 1 + kChecksumBytes);
  EXPECT_EQ(buf[1], 1);
}

TEST(Decoder, RoundTripsAStreamOfBothMessagesFedByteByByte) {
  std::vector<std::uint8_t> stream;
  std::uint8_t buf[kMaxFrameBytes];
  std::vector<Odometry> sent;
  std::uint8_t seq = 250;  // crosses the 255 -> 0 wrap
  for (int i = 0; i < 12; ++i) {
    if (i % 4 == 0) {
      Heartbeat hb;
      hb.system_status = static_cast<std::uint8_t>(i);
      const std::size_t n = encodeHeartbeat(hb, Endpoint{}, seq++, buf);
      stream.insert(stream.end(), buf, buf + n);
    }
    Odometry m = sampleOdometry();
    m.time_usec += static_cast<std::uint64_t>(i) * 100'000;
    m.x = static_cast<float>(i);
    m.quality = static_cast<std::int8_t>(i * 9 - 1);
    sent.push_back(m);
    const std::size_t n = encodeOdometry(m, Endpoint{}, seq++, buf);
    stream.insert(stream.end(), buf, buf + n);
  }
  Decoder decoder;
  const auto frames = decodeAll(decoder, stream);
  ASSERT_EQ(frames.size(), 15u);
  std::size_t odo = 0;
  std::uint8_t want_seq = 250;
  for (const Frame& f : frames) {
    EXPECT_EQ(f.seq, want_seq++);
    EXPECT_EQ(f.system_id, 1);
    EXPECT_EQ(f.component_id, 197);
    Heartbeat hb;
    Odometry m;
    if (decodeHeartbeat(f, &hb)) {
      EXPECT_EQ(hb.type, 18);
      EXPECT_EQ(hb.autopilot, 8);
      EXPECT_EQ(hb.mavlink_version, 3);
      EXPECT_FALSE(decodeOdometry(f, &m));
    } else {
      ASSERT_TRUE(decodeOdometry(f, &m));
      expectSameOdometry(sent[odo++], m);
    }
  }
  EXPECT_EQ(odo, sent.size());
  EXPECT_EQ(decoder.counters().crc_errors, 0u);
  EXPECT_EQ(decoder.counters().seq_gaps, 0u);
  EXPECT_EQ(decoder.counters().bytes_skipped, 0u);
}

// SET_GPS_GLOBAL_ORIGIN and STATUSTEXT: field offsets of common.xml (checked byte for byte against
// node-mavlink in node_mavlink_test.cpp), decoded back through the streaming decoder.
TEST(Decoder, RoundTripsOriginAndStatusText) {
  SetGpsGlobalOrigin origin;
  origin.latitude = -337'856'123;  // degE7
  origin.longitude = 1'512'345'678;
  origin.altitude = -12'345;  // mm
  origin.target_system = 1;
  origin.time_usec = 0x0102030405060708ULL;
  StatusText text;
  text.severity = kMavSeverityWarning;
  setStatusText("a text longer than the fifty characters of STATUSTEXT.text", &text);
  std::vector<std::uint8_t> bytes(2 * kMaxFrameBytes);
  std::size_t n = encodeSetGpsGlobalOrigin(origin, Endpoint{}, 5, bytes.data());
  EXPECT_EQ(n, kHeaderBytes + kPayloadBytesSetGpsGlobalOrigin + kChecksumBytes);
  EXPECT_EQ(bytes[kHeaderBytes + 0], 0x85);   // -337856123 = 0xEBDCB985, little-endian
  EXPECT_EQ(bytes[kHeaderBytes + 13], 0x08);  // time_usec, lowest byte first, at offset 13
  n += encodeStatusText(text, Endpoint{}, 6, bytes.data() + n);
  bytes.resize(n);
  Decoder decoder;
  const std::vector<Frame> frames = testing::decodeAll(bytes, &decoder);
  ASSERT_EQ(frames.size(), 2u);
  SetGpsGlobalOrigin o;
  ASSERT_TRUE(decodeSetGpsGlobalOrigin(frames[0], &o));
  EXPECT_FALSE(decodeStatusText(frames[0], &text));
  EXPECT_EQ(o.latitude, origin.latitude);
  EXPECT_EQ(o.longitude, origin.longitude);
  EXPECT_EQ(o.altitude, origin.altitude);
  EXPECT_EQ(o.target_system, 1);
  EXPECT_EQ(o.time_usec, origin.time_usec);
  StatusText t;
  ASSERT_TRUE(decodeStatusText(frames[1], &t));
  EXPECT_EQ(t.severity, kMavSeverityWarning);
  EXPECT_EQ(std::string(t.text.data(), t.text.size()),
            "a text longer than the fifty characters of STATUST");  // cut at 50, no NUL
  EXPECT_EQ(frames[1].payload_length, 51);                          // id and chunk_seq zero: cut
  EXPECT_EQ(decoder.counters().crc_errors, 0u);
}

TEST(Decoder, ResynchronisesAfterGarbageAndCorruptFrames) {
  std::uint8_t a[kMaxFrameBytes], b[kMaxFrameBytes], c[kMaxFrameBytes];
  const std::size_t na = encodeOdometry(sampleOdometry(), Endpoint{}, 10, a);
  const std::size_t nb = encodeHeartbeat(Heartbeat{}, Endpoint{}, 11, b);
  const std::size_t nc = encodeOdometry(sampleOdometry(), Endpoint{}, 12, c);
  std::vector<std::uint8_t> stream = {0x00, 0x55, 0xFE, 0x13};  // noise, incl. a v1 start byte
  // A corrupt frame: one payload bit flipped.
  a[40] ^= 0x10;
  stream.insert(stream.end(), a, a + na);
  // A false start byte claiming a long payload, directly followed by a good frame: the decoder
  // must not swallow the good frame as the false frame's payload.
  stream.push_back(0xFD);
  stream.push_back(200);
  stream.insert(stream.end(), b, b + nb);
  stream.insert(stream.end(), c, c + nc);
  Decoder decoder;
  const auto frames = decodeAll(decoder, stream);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].seq, 11);
  EXPECT_EQ(frames[0].msgid, kMsgIdHeartbeat);
  EXPECT_EQ(frames[1].seq, 12);
  EXPECT_EQ(decoder.counters().crc_errors, 1u);
  EXPECT_GT(decoder.counters().bytes_skipped, 4u);
}

TEST(Decoder, CountsUnknownMessagesSignedFramesAndSequenceGaps) {
  std::uint8_t buf[kMaxFrameBytes];
  std::vector<std::uint8_t> stream;
  // An unknown message id (no CRC_EXTRA known here): skipped and counted.
  const std::size_t n0 = encodeHeartbeat(Heartbeat{}, Endpoint{}, 0, buf);
  buf[7] = 77;
  stream.insert(stream.end(), buf, buf + n0);
  // A signed frame: incompat flag 0x01 (inside the CRC) and 13 signature bytes after the CRC.
  std::size_t n1 = encodeHeartbeat(Heartbeat{}, Endpoint{}, 5, buf);
  buf[2] = kIncompatFlagSigned;
  std::uint16_t crc = crcCalculate(buf + 1, kHeaderBytes - 1 + buf[1]);
  crc = crcAccumulate(kCrcExtraHeartbeat, crc);
  buf[n1 - 2] = static_cast<std::uint8_t>(crc);
  buf[n1 - 1] = static_cast<std::uint8_t>(crc >> 8);
  for (std::size_t i = 0; i < kSignatureBytes; ++i) buf[n1++] = static_cast<std::uint8_t>(0xA0 + i);
  stream.insert(stream.end(), buf, buf + n1);
  // seq 5 -> 9: three frames missing.
  const std::size_t n2 = encodeOdometry(sampleOdometry(), Endpoint{}, 9, buf);
  stream.insert(stream.end(), buf, buf + n2);
  Decoder decoder;
  const auto frames = decodeAll(decoder, stream);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_TRUE(frames[0].is_signed);
  EXPECT_EQ(frames[0].seq, 5);
  EXPECT_FALSE(frames[1].is_signed);
  EXPECT_EQ(decoder.counters().unknown_msgid, 1u);
  EXPECT_EQ(decoder.counters().seq_gaps, 3u);
  EXPECT_EQ(decoder.counters().frames_ok, 2u);
}

TEST(Encode, OdometryEncodeTimePerFrame) {
  // Reports the encode cost for docs/telemetry.md; the bound only catches gross regressions.
  Odometry m = sampleOdometry();
  std::uint8_t buf[kMaxFrameBytes];
  constexpr int kFrames = 200'000;
  std::size_t bytes = 0;
  timespec c0{}, c1{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kFrames; ++i) {
    m.time_usec += 100'000;
    m.x += 0.01f;
    bytes += encodeOdometry(m, Endpoint{}, static_cast<std::uint8_t>(i), buf);
  }
  const auto t1 = std::chrono::steady_clock::now();
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
  const double ns_per_frame =
      std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(kFrames);
  const double cpu_ns_per_frame = (static_cast<double>(c1.tv_sec - c0.tv_sec) * 1e9 +
                                   static_cast<double>(c1.tv_nsec - c0.tv_nsec)) /
                                  static_cast<double>(kFrames);
  std::cout << "ODOMETRY encode: " << ns_per_frame << " ns wall, " << cpu_ns_per_frame
            << " ns CPU per frame, " << static_cast<double>(bytes) / kFrames
            << " bytes per frame\n";
  RecordProperty("encode_ns_per_frame", std::to_string(ns_per_frame));
  EXPECT_EQ(bytes, static_cast<std::size_t>(kFrames) * 245u);
  EXPECT_LT(cpu_ns_per_frame, 20'000.0);
}

}  // namespace
}  // namespace sunvo::mavlink
