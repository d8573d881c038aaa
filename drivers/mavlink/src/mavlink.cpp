#include "sunvo/mavlink/mavlink.hpp"

#include <bit>
#include <cstring>

namespace sunvo::mavlink {
namespace {

// Little-endian field writers/readers, byte by byte so the result does not depend on the host.
void putU8(std::uint8_t* p, std::size_t offset, std::uint8_t v) {
  p[offset] = v;
}
void putU32(std::uint8_t* p, std::size_t offset, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) p[offset + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void putU64(std::uint8_t* p, std::size_t offset, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) p[offset + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void putF32(std::uint8_t* p, std::size_t offset, float v) {
  putU32(p, offset, std::bit_cast<std::uint32_t>(v));
}
std::uint32_t getU32(const std::uint8_t* p, std::size_t offset) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[offset + i]) << (8 * i);
  return v;
}
std::uint64_t getU64(const std::uint8_t* p, std::size_t offset) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[offset + i]) << (8 * i);
  return v;
}
float getF32(const std::uint8_t* p, std::size_t offset) {
  return std::bit_cast<float>(getU32(p, offset));
}

// CRC-16/MCRF4XX, one byte: the byte-wise form of the reflected 0x1021 polynomial (0x8408).
constexpr std::uint16_t accumulateByte(std::uint8_t byte, std::uint16_t crc) {
  std::uint8_t tmp = static_cast<std::uint8_t>(byte ^ static_cast<std::uint8_t>(crc & 0xFF));
  tmp = static_cast<std::uint8_t>(tmp ^ static_cast<std::uint8_t>(tmp << 4));
  return static_cast<std::uint16_t>((crc >> 8) ^ (static_cast<std::uint16_t>(tmp) << 8) ^
                                    (static_cast<std::uint16_t>(tmp) << 3) ^ (tmp >> 4));
}

// The CRC_EXTRA of the messages this module knows; false for any other id.
bool crcExtraFor(std::uint32_t msgid, std::uint8_t* crc_extra) {
  switch (msgid) {
    case kMsgIdHeartbeat:
      *crc_extra = kCrcExtraHeartbeat;
      return true;
    case kMsgIdOdometry:
      *crc_extra = kCrcExtraOdometry;
      return true;
    case kMsgIdSetGpsGlobalOrigin:
      *crc_extra = kCrcExtraSetGpsGlobalOrigin;
      return true;
    case kMsgIdStatusText:
      *crc_extra = kCrcExtraStatusText;
      return true;
    default:
      return false;
  }
}

// Wraps the payload already written at out + kHeaderBytes (full length max_len) into a frame:
// cuts trailing zeros (keeping at least one byte), writes the header and the CRC.
std::size_t finishFrame(std::uint32_t msgid, std::uint8_t crc_extra, std::size_t max_len,
                        const Endpoint& from, std::uint8_t seq, std::uint8_t* out) {
  std::size_t len = max_len;
  while (len > 1 && out[kHeaderBytes + len - 1] == 0) --len;
  out[0] = kStxV2;
  out[1] = static_cast<std::uint8_t>(len);
  out[2] = 0;  // incompat flags: unsigned
  out[3] = 0;  // compat flags
  out[4] = seq;
  out[5] = from.system_id;
  out[6] = from.component_id;
  out[7] = static_cast<std::uint8_t>(msgid);
  out[8] = static_cast<std::uint8_t>(msgid >> 8);
  out[9] = static_cast<std::uint8_t>(msgid >> 16);
  std::uint16_t crc = crcCalculate(out + 1, kHeaderBytes - 1 + len);
  crc = crcAccumulate(crc_extra, crc);
  out[kHeaderBytes + len] = static_cast<std::uint8_t>(crc);
  out[kHeaderBytes + len + 1] = static_cast<std::uint8_t>(crc >> 8);
  return kHeaderBytes + len + kChecksumBytes;
}

// Payload offsets (bytes), base fields by size then extensions; see the header comment.
namespace hb {
constexpr std::size_t kCustomMode = 0, kType = 4, kAutopilot = 5, kBaseMode = 6, kSystemStatus = 7,
                      kMavlinkVersion = 8;
}
namespace odo {
constexpr std::size_t kTimeUsec = 0, kX = 8, kY = 12, kZ = 16, kQ = 20, kVx = 36, kVy = 40,
                      kVz = 44, kRollspeed = 48, kPitchspeed = 52, kYawspeed = 56,
                      kPoseCovariance = 60, kVelocityCovariance = 144, kFrameId = 228,
                      kChildFrameId = 229, kResetCounter = 230, kEstimatorType = 231,
                      kQuality = 232;
static_assert(kQuality + 1 == kPayloadBytesOdometry);
static_assert(kVelocityCovariance + 21 * 4 == kFrameId);
}  // namespace odo

}  // namespace

std::uint16_t crcAccumulate(std::uint8_t byte, std::uint16_t crc) {
  return accumulateByte(byte, crc);
}

std::uint16_t crcCalculate(const std::uint8_t* data, std::size_t n, std::uint16_t crc) {
  // Table-driven: accumulateByte(b, crc) = (crc >> 8) ^ table[(crc ^ b) & 0xFF], where
  // table[i] = accumulateByte(i, 0), because the CRC is linear over GF(2).
  static constexpr std::array<std::uint16_t, 256> kTable = [] {
    std::array<std::uint16_t, 256> table{};
    for (std::size_t i = 0; i < 256; ++i)
      table[i] = accumulateByte(static_cast<std::uint8_t>(i), 0);
    return table;
  }();
  for (std::size_t i = 0; i < n; ++i) {
    crc = static_cast<std::uint16_t>((crc >> 8) ^ kTable[(crc ^ data[i]) & 0xFF]);
  }
  return crc;
}

std::size_t encodeHeartbeat(const Heartbeat& msg, const Endpoint& from, std::uint8_t seq,
                            std::uint8_t* out) {
  std::uint8_t* p = out + kHeaderBytes;
  putU32(p, hb::kCustomMode, msg.custom_mode);
  putU8(p, hb::kType, msg.type);
  putU8(p, hb::kAutopilot, msg.autopilot);
  putU8(p, hb::kBaseMode, msg.base_mode);
  putU8(p, hb::kSystemStatus, msg.system_status);
  putU8(p, hb::kMavlinkVersion, msg.mavlink_version);
  return finishFrame(kMsgIdHeartbeat, kCrcExtraHeartbeat, kPayloadBytesHeartbeat, from, seq, out);
}

std::size_t encodeOdometry(const Odometry& msg, const Endpoint& from, std::uint8_t seq,
                           std::uint8_t* out) {
  std::uint8_t* p = out + kHeaderBytes;
  putU64(p, odo::kTimeUsec, msg.time_usec);
  putF32(p, odo::kX, msg.x);
  putF32(p, odo::kY, msg.y);
  putF32(p, odo::kZ, msg.z);
  for (std::size_t i = 0; i < 4; ++i) putF32(p, odo::kQ + 4 * i, msg.q[i]);
  putF32(p, odo::kVx, msg.vx);
  putF32(p, odo::kVy, msg.vy);
  putF32(p, odo::kVz, msg.vz);
  putF32(p, odo::kRollspeed, msg.rollspeed);
  putF32(p, odo::kPitchspeed, msg.pitchspeed);
  putF32(p, odo::kYawspeed, msg.yawspeed);
  for (std::size_t i = 0; i < 21; ++i) {
    putF32(p, odo::kPoseCovariance + 4 * i, msg.pose_covariance[i]);
    putF32(p, odo::kVelocityCovariance + 4 * i, msg.velocity_covariance[i]);
  }
  putU8(p, odo::kFrameId, msg.frame_id);
  putU8(p, odo::kChildFrameId, msg.child_frame_id);
  putU8(p, odo::kResetCounter, msg.reset_counter);
  putU8(p, odo::kEstimatorType, msg.estimator_type);
  putU8(p, odo::kQuality, static_cast<std::uint8_t>(msg.quality));
  return finishFrame(kMsgIdOdometry, kCrcExtraOdometry, kPayloadBytesOdometry, from, seq, out);
}

void Decoder::drop(std::size_t n) {
  std::memmove(buf_.data(), buf_.data() + n, size_ - n);
  size_ -= n;
}

bool Decoder::push(std::uint8_t byte, Frame* out) {
  // The buffer never holds a whole frame between calls (next() consumes it), so there is room.
  if (size_ == buf_.size()) drop(1);
  buf_[size_++] = byte;
  return next(out);
}

bool Decoder::next(Frame* out) {
  while (size_ > 0) {
    if (buf_[0] != kStxV2) {
      ++counters_.bytes_skipped;
      drop(1);
      continue;
    }
    if (size_ < kHeaderBytes) return false;
    const std::uint8_t incompat = buf_[2];
    if ((incompat & ~kIncompatFlagSigned) != 0) {
      // A flag this decoder does not understand: the spec says drop the frame. Resume the search
      // after the start byte (the length could be garbage too).
      ++counters_.bad_flags;
      drop(1);
      continue;
    }
    const std::size_t len = buf_[1];
    const bool is_signed = (incompat & kIncompatFlagSigned) != 0;
    const std::size_t total =
        kHeaderBytes + len + kChecksumBytes + (is_signed ? kSignatureBytes : 0);
    if (size_ < total) return false;
    const std::uint32_t msgid = static_cast<std::uint32_t>(buf_[7]) |
                                (static_cast<std::uint32_t>(buf_[8]) << 8) |
                                (static_cast<std::uint32_t>(buf_[9]) << 16);
    std::uint8_t crc_extra = 0;
    if (!crcExtraFor(msgid, &crc_extra)) {
      // Without CRC_EXTRA the CRC cannot be checked, so the length cannot be trusted either.
      ++counters_.unknown_msgid;
      drop(1);
      continue;
    }
    std::uint16_t crc = crcCalculate(buf_.data() + 1, kHeaderBytes - 1 + len);
    crc = crcAccumulate(crc_extra, crc);
    const std::uint16_t crc_rx =
        static_cast<std::uint16_t>(buf_[kHeaderBytes + len] | (buf_[kHeaderBytes + len + 1] << 8));
    if (crc != crc_rx) {
      ++counters_.crc_errors;
      drop(1);
      continue;
    }
    out->payload_length = static_cast<std::uint8_t>(len);
    out->incompat_flags = incompat;
    out->compat_flags = buf_[3];
    out->seq = buf_[4];
    out->system_id = buf_[5];
    out->component_id = buf_[6];
    out->msgid = msgid;
    out->checksum = crc_rx;
    out->is_signed = is_signed;
    out->payload.fill(0);
    std::memcpy(out->payload.data(), buf_.data() + kHeaderBytes, len);
    if (have_last_seq_) {
      counters_.seq_gaps += static_cast<std::uint8_t>(out->seq - last_seq_ - 1);
    }
    have_last_seq_ = true;
    last_seq_ = out->seq;
    ++counters_.frames_ok;
    drop(total);
    return true;
  }
  return false;
}

bool decodeHeartbeat(const Frame& frame, Heartbeat* out) {
  if (frame.msgid != kMsgIdHeartbeat) return false;
  const std::uint8_t* p = frame.payload.data();
  out->custom_mode = getU32(p, hb::kCustomMode);
  out->type = p[hb::kType];
  out->autopilot = p[hb::kAutopilot];
  out->base_mode = p[hb::kBaseMode];
  out->system_status = p[hb::kSystemStatus];
  out->mavlink_version = p[hb::kMavlinkVersion];
  return true;
}

bool decodeOdometry(const Frame& frame, Odometry* out) {
  if (frame.msgid != kMsgIdOdometry) return false;
  const std::uint8_t* p = frame.payload.data();
  out->time_usec = getU64(p, odo::kTimeUsec);
  out->x = getF32(p, odo::kX);
  out->y = getF32(p, odo::kY);
  out->z = getF32(p, odo::kZ);
  for (std::size_t i = 0; i < 4; ++i) out->q[i] = getF32(p, odo::kQ + 4 * i);
  out->vx = getF32(p, odo::kVx);
  out->vy = getF32(p, odo::kVy);
  out->vz = getF32(p, odo::kVz);
  out->rollspeed = getF32(p, odo::kRollspeed);
  out->pitchspeed = getF32(p, odo::kPitchspeed);
  out->yawspeed = getF32(p, odo::kYawspeed);
  for (std::size_t i = 0; i < 21; ++i) {
    out->pose_covariance[i] = getF32(p, odo::kPoseCovariance + 4 * i);
    out->velocity_covariance[i] = getF32(p, odo::kVelocityCovariance + 4 * i);
  }
  out->frame_id = p[odo::kFrameId];
  out->child_frame_id = p[odo::kChildFrameId];
  out->reset_counter = p[odo::kResetCounter];
  out->estimator_type = p[odo::kEstimatorType];
  out->quality = static_cast<std::int8_t>(p[odo::kQuality]);
  return true;
}

std::size_t encodeSetGpsGlobalOrigin(const SetGpsGlobalOrigin& msg, const Endpoint& from,
                                     std::uint8_t seq, std::uint8_t* out) {
  std::uint8_t* p = out + kHeaderBytes;
  putU32(p, 0, static_cast<std::uint32_t>(msg.latitude));
  putU32(p, 4, static_cast<std::uint32_t>(msg.longitude));
  putU32(p, 8, static_cast<std::uint32_t>(msg.altitude));
  putU8(p, 12, msg.target_system);
  putU64(p, 13, msg.time_usec);
  return finishFrame(kMsgIdSetGpsGlobalOrigin, kCrcExtraSetGpsGlobalOrigin,
                     kPayloadBytesSetGpsGlobalOrigin, from, seq, out);
}

void setStatusText(const char* text, StatusText* msg) {
  msg->text.fill('\0');
  for (std::size_t i = 0; i < kStatusTextChars && text[i] != '\0'; ++i) msg->text[i] = text[i];
}

std::size_t encodeStatusText(const StatusText& msg, const Endpoint& from, std::uint8_t seq,
                             std::uint8_t* out) {
  std::uint8_t* p = out + kHeaderBytes;
  putU8(p, 0, msg.severity);
  for (std::size_t i = 0; i < kStatusTextChars; ++i) {
    putU8(p, 1 + i, static_cast<std::uint8_t>(msg.text[i]));
  }
  putU8(p, 51, static_cast<std::uint8_t>(msg.id & 0xFF));
  putU8(p, 52, static_cast<std::uint8_t>(msg.id >> 8));
  putU8(p, 53, msg.chunk_seq);
  return finishFrame(kMsgIdStatusText, kCrcExtraStatusText, kPayloadBytesStatusText, from, seq,
                     out);
}

bool decodeSetGpsGlobalOrigin(const Frame& frame, SetGpsGlobalOrigin* out) {
  if (frame.msgid != kMsgIdSetGpsGlobalOrigin) return false;
  const std::uint8_t* p = frame.payload.data();
  out->latitude = static_cast<std::int32_t>(getU32(p, 0));
  out->longitude = static_cast<std::int32_t>(getU32(p, 4));
  out->altitude = static_cast<std::int32_t>(getU32(p, 8));
  out->target_system = p[12];
  out->time_usec = getU64(p, 13);
  return true;
}

bool decodeStatusText(const Frame& frame, StatusText* out) {
  if (frame.msgid != kMsgIdStatusText) return false;
  const std::uint8_t* p = frame.payload.data();
  out->severity = p[0];
  for (std::size_t i = 0; i < kStatusTextChars; ++i) out->text[i] = static_cast<char>(p[1 + i]);
  out->id = static_cast<std::uint16_t>(p[51] | (p[52] << 8));
  out->chunk_seq = p[53];
  return true;
}

}  // namespace sunvo::mavlink
