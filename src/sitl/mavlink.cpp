#include "sitl/mavlink.hpp"

#include <algorithm>
#include <cstring>

namespace quadcosim::sitl::mavlink {

namespace {

struct Put {
  std::vector<std::uint8_t> b;
  template <class T>
  Put& operator()(T v) {
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));  // little-endian hosts (x86-64, aarch64), as MAVLink
    b.insert(b.end(), raw, raw + sizeof(T));
    return *this;
  }
};

template <class T>
T get(const std::vector<std::uint8_t>& p, std::size_t at) {
  std::uint8_t raw[sizeof(T)] = {};
  for (std::size_t i = 0; i < sizeof(T); ++i) raw[i] = at + i < p.size() ? p[at + i] : 0;  // truncated: zeros
  T v;
  std::memcpy(&v, raw, sizeof(T));
  return v;
}

}  // namespace

std::optional<std::uint8_t> crc_extra(std::uint32_t msgid) {
  switch (msgid) {
    case kHeartbeat: return 50;
    case kCommandInt: return 158;
    case kCommandLong: return 152;
    case kCommandAck: return 143;
    case kSetPositionTargetLocalNed: return 143;
    case kHilActuatorControls: return 47;
    case kHilSensor: return 108;
    case kHilGps: return 124;
    case kStatustext: return 83;
    default: return std::nullopt;
  }
}

std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t crc) {
  for (std::uint8_t d : bytes) {
    std::uint8_t t = d ^ static_cast<std::uint8_t>(crc & 0xff);
    t ^= static_cast<std::uint8_t>(t << 4);
    crc = static_cast<std::uint16_t>((crc >> 8) ^ (t << 8) ^ (t << 3) ^ (t >> 4));
  }
  return crc;
}

std::vector<std::uint8_t> encode(std::uint8_t seq, std::uint8_t sysid, std::uint8_t compid, std::uint32_t msgid,
                                 std::span<const std::uint8_t> payload) {
  std::size_t len = payload.size();
  while (len > 1 && payload[len - 1] == 0) --len;
  // Header, payload and checksum written into room reserved once (GCC 12 warns, wrongly, of an
  // insert after a braced header).
  std::vector<std::uint8_t> f(10 + len + 2);
  const std::uint8_t header[10] = {kStx,
                                   static_cast<std::uint8_t>(len),
                                   0,
                                   0,
                                   seq,
                                   sysid,
                                   compid,
                                   static_cast<std::uint8_t>(msgid & 0xff),
                                   static_cast<std::uint8_t>((msgid >> 8) & 0xff),
                                   static_cast<std::uint8_t>((msgid >> 16) & 0xff)};
  std::copy(std::begin(header), std::end(header), f.begin());
  std::copy(payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(len), f.begin() + 10);
  f.resize(10 + len);
  std::uint16_t crc = crc16(std::span<const std::uint8_t>(f).subspan(1));
  const std::uint8_t extra = crc_extra(msgid).value_or(0);
  crc = crc16(std::span<const std::uint8_t>(&extra, 1), crc);
  f.push_back(static_cast<std::uint8_t>(crc & 0xff));
  f.push_back(static_cast<std::uint8_t>(crc >> 8));
  return f;
}

void Parser::feed(std::span<const std::uint8_t> bytes) {
  buf_.insert(buf_.end(), bytes.begin(), bytes.end());
  if (buf_.size() > (1u << 20)) buf_.erase(buf_.begin(), buf_.end() - (1 << 16));  // a stream of garbage
}

std::optional<Frame> Parser::next() {
  for (;;) {
    const auto stx = std::find(buf_.begin(), buf_.end(), kStx);
    buf_.erase(buf_.begin(), stx);
    if (buf_.size() < 12) return std::nullopt;
    const std::size_t len = buf_[1];
    const bool signed_frame = (buf_[2] & 0x01) != 0;
    const std::size_t total = 10 + len + 2 + (signed_frame ? 13 : 0);
    if (buf_.size() < total) return std::nullopt;
    const std::uint32_t msgid = buf_[7] | (buf_[8] << 8) | (static_cast<std::uint32_t>(buf_[9]) << 16);
    const auto extra = crc_extra(msgid);
    if (!extra) {  // a message this file does not read: skip the frame (its length is trustworthy enough)
      buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(total));
      continue;
    }
    std::uint16_t crc = crc16(std::span<const std::uint8_t>(buf_.data() + 1, 9 + len));
    crc = crc16(std::span<const std::uint8_t>(&*extra, 1), crc);
    const std::uint16_t got = static_cast<std::uint16_t>(buf_[10 + len] | (buf_[11 + len] << 8));
    if (crc != got) {
      ++bad_crc_;
      buf_.erase(buf_.begin());  // resynchronise on the next STX
      continue;
    }
    Frame f;
    f.seq = buf_[4];
    f.sysid = buf_[5];
    f.compid = buf_[6];
    f.msgid = msgid;
    f.payload.assign(buf_.begin() + 10, buf_.begin() + 10 + static_cast<std::ptrdiff_t>(len));
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(total));
    return f;
  }
}

std::vector<std::uint8_t> heartbeat(std::uint8_t type, std::uint8_t autopilot, std::uint8_t base_mode,
                                    std::uint32_t custom_mode, std::uint8_t system_status) {
  return Put{}(custom_mode)(type)(autopilot)(base_mode)(system_status)(std::uint8_t{3}).b;
}

std::vector<std::uint8_t> command_long(std::uint8_t target_system, std::uint8_t target_component, std::uint16_t command,
                                       std::uint8_t confirmation, const std::array<float, 7>& params) {
  Put p;
  for (float v : params) p(v);
  return p(command)(target_system)(target_component)(confirmation).b;
}

std::vector<std::uint8_t> command_int(std::uint8_t target_system, std::uint8_t target_component, std::uint16_t command,
                                      std::uint8_t frame, const std::array<float, 4>& params, std::int32_t x,
                                      std::int32_t y, float z) {
  Put p;
  for (float v : params) p(v);
  return p(x)(y)(z)(command)(target_system)(target_component)(frame)(std::uint8_t{0})(std::uint8_t{0}).b;
}

std::vector<std::uint8_t> set_position_target_local_ned(std::uint32_t time_boot_ms, std::uint8_t target_system,
                                                        std::uint8_t target_component, float x, float y, float z,
                                                        bool use_yaw, float yaw) {
  // type_mask: ignore vx..afz (bits 3-8), yaw (bit 10) unless used, yaw rate (bit 11).
  const std::uint16_t mask = static_cast<std::uint16_t>(0x01F8 | 0x0800 | (use_yaw ? 0 : 0x0400));
  Put p;
  p(time_boot_ms)(x)(y)(z);
  for (int i = 0; i < 6; ++i) p(0.0f);
  p(use_yaw ? yaw : 0.0f)(0.0f);
  return p(mask)(target_system)(target_component)(std::uint8_t{1}).b;
}

std::vector<std::uint8_t> hil_sensor(const HilSensor& m) {
  Put p;
  p(m.time_usec);
  for (const auto* v : {&m.acc_m_s2, &m.gyro_rad_s, &m.mag_gauss}) {
    for (float e : *v) p(e);
  }
  return p(m.abs_pressure_hpa)(m.diff_pressure_hpa)(m.pressure_alt_m)(m.temperature_c)(m.fields_updated)(m.id).b;
}

std::vector<std::uint8_t> hil_gps(const HilGps& m) {
  return Put{}(m.time_usec)(m.lat)(m.lon)(m.alt)(m.eph)(m.epv)(m.vel)(m.vn)(m.ve)(m.vd)(m.cog)(m.fix_type)(
             m.satellites_visible)(m.id)(m.yaw)
      .b;
}

HilActuatorControls read_hil_actuator_controls(const Frame& f) {
  HilActuatorControls m;
  m.time_usec = get<std::uint64_t>(f.payload, 0);
  m.flags = get<std::uint64_t>(f.payload, 8);
  for (std::size_t i = 0; i < m.controls.size(); ++i) m.controls[i] = get<float>(f.payload, 16 + 4 * i);
  m.mode = get<std::uint8_t>(f.payload, 80);
  return m;
}

Heartbeat read_heartbeat(const Frame& f) {
  Heartbeat h;
  h.custom_mode = get<std::uint32_t>(f.payload, 0);
  h.type = get<std::uint8_t>(f.payload, 4);
  h.autopilot = get<std::uint8_t>(f.payload, 5);
  h.base_mode = get<std::uint8_t>(f.payload, 6);
  h.system_status = get<std::uint8_t>(f.payload, 7);
  return h;
}

CommandAck read_command_ack(const Frame& f) {
  return {get<std::uint16_t>(f.payload, 0), get<std::uint8_t>(f.payload, 2)};
}

std::pair<std::uint8_t, std::string> read_statustext(const Frame& f) {
  std::string text;
  for (std::size_t i = 1; i < 51 && i < f.payload.size() && f.payload[i] != 0; ++i) {
    text.push_back(static_cast<char>(f.payload[i]));
  }
  return {get<std::uint8_t>(f.payload, 0), text};
}

}  // namespace quadcosim::sitl::mavlink
