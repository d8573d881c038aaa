#pragma once
// MAVLink v2 framing for the messages sunvo sends: HEARTBEAT (#0), ODOMETRY (#331),
// SET_GPS_GLOBAL_ORIGIN (#48) and STATUSTEXT (#253) (common message set). Protocol only: no I/O, no
// allocation, no exceptions.
//
// A v2 frame on the wire (all multi-byte numbers little-endian):
//   [0] 0xFD  [1] payload length  [2] incompat flags  [3] compat flags  [4] seq  [5] sysid
//   [6] compid  [7..9] msgid (24 bit)  [10..] payload  [..+2] CRC-16/MCRF4XX  [..+13] signature
// The CRC runs over bytes 1..end of payload, then over the message's CRC_EXTRA byte. The payload
// holds the base fields sorted by type size (largest first, stable), then the extension fields in
// XML order; trailing zero bytes are cut off (at least one payload byte stays), the receiver
// fills them back in with zeros. Layouts and CRC_EXTRA were checked against node-mavlink 2.3.0
// (mavlink-mappings: Heartbeat.MAGIC_NUMBER = 50, PAYLOAD_LENGTH = 9; Odometry.MAGIC_NUMBER = 91,
// PAYLOAD_LENGTH = 233; SetGpsGlobalOrigin 41 / 21; StatusText 83 / 54) and against the C headers
// generated from common.xml.

#include <array>
#include <cstddef>
#include <cstdint>

namespace sunvo::mavlink {

inline constexpr std::uint8_t kStxV2 = 0xFD;
inline constexpr std::size_t kHeaderBytes = 10;     // STX .. msgid
inline constexpr std::size_t kChecksumBytes = 2;    // CRC-16/MCRF4XX
inline constexpr std::size_t kSignatureBytes = 13;  // present when incompat flag 0x01 is set
inline constexpr std::size_t kMaxPayloadBytes = 255;
inline constexpr std::size_t kMaxFrameBytes =
    kHeaderBytes + kMaxPayloadBytes + kChecksumBytes + kSignatureBytes;  // 280
inline constexpr std::uint8_t kIncompatFlagSigned = 0x01;

inline constexpr std::uint32_t kMsgIdHeartbeat = 0;
inline constexpr std::uint8_t kCrcExtraHeartbeat = 50;
inline constexpr std::size_t kPayloadBytesHeartbeat = 9;
inline constexpr std::uint32_t kMsgIdOdometry = 331;
inline constexpr std::uint8_t kCrcExtraOdometry = 91;
inline constexpr std::size_t kPayloadBytesOdometry = 233;
inline constexpr std::uint32_t kMsgIdSetGpsGlobalOrigin = 48;
inline constexpr std::uint8_t kCrcExtraSetGpsGlobalOrigin = 41;
inline constexpr std::size_t kPayloadBytesSetGpsGlobalOrigin = 21;
inline constexpr std::uint32_t kMsgIdStatusText = 253;
inline constexpr std::uint8_t kCrcExtraStatusText = 83;
inline constexpr std::size_t kPayloadBytesStatusText = 54;
inline constexpr std::size_t kStatusTextChars =
    50;  // STATUSTEXT.text: char[50], NUL only if shorter

// Enum values from common.xml / minimal.xml used by sunvo.
inline constexpr std::uint8_t kMavFrameLocalNed = 1;    // MAV_FRAME_LOCAL_NED
inline constexpr std::uint8_t kMavFrameBodyFrd = 12;    // MAV_FRAME_BODY_FRD
inline constexpr std::uint8_t kMavFrameLocalFrd = 20;   // MAV_FRAME_LOCAL_FRD
inline constexpr std::uint8_t kMavEstimatorVision = 2;  // MAV_ESTIMATOR_TYPE_VISION
inline constexpr std::uint8_t kMavlinkVersion = 3;      // HEARTBEAT.mavlink_version
inline constexpr std::uint8_t kMavStateActive = 4;      // MAV_STATE_ACTIVE
inline constexpr std::uint8_t kMavStateCritical = 5;    // MAV_STATE_CRITICAL
// MAV_SEVERITY (STATUSTEXT.severity): lower is more severe.
inline constexpr std::uint8_t kMavSeverityCritical = 2;
inline constexpr std::uint8_t kMavSeverityError = 3;
inline constexpr std::uint8_t kMavSeverityWarning = 4;
inline constexpr std::uint8_t kMavSeverityNotice = 5;
inline constexpr std::uint8_t kMavSeverityInfo = 6;

struct Heartbeat {
  std::uint8_t type = 18;          // MAV_TYPE_ONBOARD_CONTROLLER
  std::uint8_t autopilot = 8;      // MAV_AUTOPILOT_INVALID (not a flight controller)
  std::uint8_t base_mode = 0;      // MAV_MODE_FLAG bits
  std::uint32_t custom_mode = 0;   // autopilot-specific
  std::uint8_t system_status = 4;  // MAV_STATE_ACTIVE
  std::uint8_t mavlink_version = kMavlinkVersion;  // encoded as given; decoded from the frame
};

// ODOMETRY (#331), every field including the extensions; units as in common.xml.
struct Odometry {
  std::uint64_t time_usec = 0;                        // us since the Unix epoch (sunvo sends UTC)
  std::uint8_t frame_id = kMavFrameLocalNed;          // frame of x, y, z and q
  std::uint8_t child_frame_id = kMavFrameBodyFrd;     // frame of the velocities
  float x = 0.0f, y = 0.0f, z = 0.0f;                 // m, position of the body in frame_id
  std::array<float, 4> q = {1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z: rotation body -> frame_id
  float vx = 0.0f, vy = 0.0f, vz = 0.0f;              // m/s in child_frame_id; NaN = unknown
  float rollspeed = 0.0f, pitchspeed = 0.0f, yawspeed = 0.0f;  // rad/s about body x, y, z
  // Upper triangle, row-major, of the 6x6 covariance of (x, y, z, roll, pitch, yaw) and of
  // (vx, vy, vz, rollspeed, pitchspeed, yawspeed); NaN in element 0 = unknown.
  std::array<float, 21> pose_covariance{};
  std::array<float, 21> velocity_covariance{};
  std::uint8_t reset_counter = 0;  // incremented when the estimate jumps (re-initialisation)
  std::uint8_t estimator_type = kMavEstimatorVision;
  std::int8_t quality = 0;  // %, -1 failed, 0 unknown, 1 worst .. 100 best
};

// SET_GPS_GLOBAL_ORIGIN (#48): the geodetic point the local frame (x = y = z = 0) sits at.
// Payload: latitude 0, longitude 4, altitude 8 (int32), target_system 12 (uint8), then the
// extension time_usec 13 (uint64).
struct SetGpsGlobalOrigin {
  std::int32_t latitude = 0;       // degE7 (WGS84)
  std::int32_t longitude = 0;      // degE7 (WGS84)
  std::int32_t altitude = 0;       // mm above mean sea level
  std::uint8_t target_system = 0;  // 0 = every system
  std::uint64_t time_usec = 0;     // us since the Unix epoch; 0 = unknown
};

// STATUSTEXT (#253): a line of text for the operator. Payload: severity 0, text 1..50, then the
// extensions id 51 (uint16) and chunk_seq 53 (uint8).
struct StatusText {
  std::uint8_t severity = kMavSeverityInfo;   // MAV_SEVERITY
  std::array<char, kStatusTextChars> text{};  // not NUL-terminated when all 50 are used
  std::uint16_t id = 0;                       // 0: a single-chunk message
  std::uint8_t chunk_seq = 0;
};

// Who sends: MAVLink system and component ids.
struct Endpoint {
  std::uint8_t system_id = 1;
  std::uint8_t component_id = 197;  // MAV_COMP_ID_VISUAL_INERTIAL_ODOMETRY
};

// CRC-16/MCRF4XX (the "X.25" CRC of MAVLink): poly 0x1021 reflected, init 0xFFFF, no final xor.
// crcAccumulate folds one byte into crc; crcCalculate runs over n bytes starting at init.
std::uint16_t crcAccumulate(std::uint8_t byte, std::uint16_t crc);
std::uint16_t crcCalculate(const std::uint8_t* data, std::size_t n, std::uint16_t crc = 0xFFFF);

// Encode one unsigned MAVLink v2 frame into out (room for kMaxFrameBytes); returns its length.
std::size_t encodeHeartbeat(const Heartbeat& msg, const Endpoint& from, std::uint8_t seq,
                            std::uint8_t* out);
std::size_t encodeOdometry(const Odometry& msg, const Endpoint& from, std::uint8_t seq,
                           std::uint8_t* out);
std::size_t encodeSetGpsGlobalOrigin(const SetGpsGlobalOrigin& msg, const Endpoint& from,
                                     std::uint8_t seq, std::uint8_t* out);
std::size_t encodeStatusText(const StatusText& msg, const Endpoint& from, std::uint8_t seq,
                             std::uint8_t* out);
// Copies text into msg->text (cut at 50 chars, the rest zero); no allocation.
void setStatusText(const char* text, StatusText* msg);

// One frame received with a good CRC. payload holds payload_length bytes as sent (truncated);
// the rest of the array is zero, so decoders can read the full layout.
struct Frame {
  std::uint8_t payload_length = 0;
  std::uint8_t incompat_flags = 0;
  std::uint8_t compat_flags = 0;
  std::uint8_t seq = 0;
  std::uint8_t system_id = 0;
  std::uint8_t component_id = 0;
  std::uint32_t msgid = 0;
  std::uint16_t checksum = 0;
  bool is_signed = false;  // carried a signature (not verified: sunvo holds no key)
  std::array<std::uint8_t, kMaxPayloadBytes> payload{};
};

struct DecoderCounters {
  std::uint64_t frames_ok = 0;      // frames returned
  std::uint64_t crc_errors = 0;     // candidate frames of a known message with a bad CRC
  std::uint64_t unknown_msgid = 0;  // v2 frames of messages this decoder has no CRC_EXTRA for
  std::uint64_t bad_flags = 0;      // frames with incompat flags other than "signed"
  std::uint64_t bytes_skipped = 0;  // bytes discarded while hunting for a frame start
  std::uint64_t seq_gaps = 0;       // frames missing by seq between consecutive frames
};

// Streaming decoder for v2 frames of the messages above. Holds at most one frame of bytes in a
// fixed buffer. After a bad CRC it resumes the search one byte after the bad start byte, so a
// good frame hidden inside a corrupt one is still found. MAVLink v1 frames (0xFE) are skipped.
class Decoder {
 public:
  // Appends one byte; true when a frame completed, written to *out.
  bool push(std::uint8_t byte, Frame* out);
  // Returns a further complete frame already buffered (possible only after a resync); call it
  // after push() returned true until it returns false if every frame matters.
  bool next(Frame* out);
  const DecoderCounters& counters() const { return counters_; }

 private:
  void drop(std::size_t n);

  std::array<std::uint8_t, kMaxFrameBytes> buf_{};
  std::size_t size_ = 0;
  bool have_last_seq_ = false;
  std::uint8_t last_seq_ = 0;
  DecoderCounters counters_;
};

// Decode the payload of a frame; false when msgid does not match.
bool decodeHeartbeat(const Frame& frame, Heartbeat* out);
bool decodeOdometry(const Frame& frame, Odometry* out);
bool decodeSetGpsGlobalOrigin(const Frame& frame, SetGpsGlobalOrigin* out);
bool decodeStatusText(const Frame& frame, StatusText* out);

}  // namespace sunvo::mavlink
