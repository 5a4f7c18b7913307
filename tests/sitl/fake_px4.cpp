// A stand-in for PX4's SITL build, for the tests: it takes PX4's command line (-i N -d -w DIR ... ETC)
// and environment (PX4_SYS_AUTOSTART, PX4_PARAM_*), connects to the simulator port 4560 + N as PX4's
// simulator_mavlink does, reads HIL_SENSOR and HIL_GPS, and answers each HIL_SENSOR with one
// HIL_ACTUATOR_CONTROLS stamped with its time (flags 1: lockstep), so the whole loop runs without
// PX4. Its law comes from PX4_PARAM_FAKE_* variables:
//   FAKE_MODE 0: armed from the start, every output at FAKE_U (open loop)
//   FAKE_MODE 1: commanded over MAVLink on UDP 18570 + N as PX4's GCS link is: HEARTBEAT each second
//                of its clock (armed flag, custom_mode main << 16 | sub << 24) to the address it last
//                heard from; COMMAND_LONG DO_SET_MODE (4/6: land), COMPONENT_ARM_DISARM (refused,
//                result 1, before FAKE_READY_S [s]), NAV_TAKEOFF (param7: altitude above mean sea level
//                [m]) and COMMAND_INT DO_REPOSITION, each answered by COMMAND_ACK. Armed, it holds the
//                height asked (PD on the barometer's pressure altitude over its first reading and the
//                GNSS's vertical speed; thrust fraction MPC_THR_HOVER (1 + a / g), output its square
//                root, as THR_MDL_FAC 1 says); disarmed, every output is 0. Land descends and disarms.
//   FAKE_FIRST n: the first n HIL_SENSORs get no answer (PX4 starting up)
// and its faults from its own options (quadcosim passes a scenario's sitl.args before the etc folder):
//   --fake-die-at N        exit(3) instead of answering HIL_SENSOR N (1-based)
//   --fake-hang-at N       stop answering at HIL_SENSOR N
//   --fake-bad-crc-at N    the answer to HIL_SENSOR N goes out with a wrong checksum
//   --fake-no-lockstep     flags 0 in every answer (a build without the lockstep scheduler)
//   --fake-record PATH     one line per message received: "S time_usec ax ay az gx gy gz mx my mz p_hpa
//                          alt temp fields" for HIL_SENSOR, "G time_usec lat lon alt eph epv vel vn ve vd
//                          cog fix sats" for HIL_GPS, "C command x y z p1 p2 p3 p4" for a command (z: param7)
//   --fake-pid-file PATH   writes its process id there
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "sitl/mavlink.hpp"

namespace mav = quadcosim::sitl::mavlink;

namespace {

double param(const char* name, double fallback) {
  const char* v = std::getenv((std::string("PX4_PARAM_") + name).c_str());
  return v && *v ? std::atof(v) : fallback;
}

template <class T>
T at(const std::vector<std::uint8_t>& p, std::size_t offset) {
  std::uint8_t raw[sizeof(T)] = {};
  for (std::size_t i = 0; i < sizeof(T); ++i) raw[i] = offset + i < p.size() ? p[offset + i] : 0;
  T v;
  std::memcpy(&v, raw, sizeof(T));
  return v;
}

template <class T>
void put(std::vector<std::uint8_t>& p, std::size_t offset, T v) {
  std::memcpy(p.data() + offset, &v, sizeof(T));
}

}  // namespace

int main(int argc, char** argv) {
  int instance = 0;
  long die_at = -1, hang_at = -1, bad_crc_at = -1;
  bool no_lockstep = false;
  std::ofstream record;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : "";
    if (a == "-i") instance = std::atoi(next);
    if (a == "-w" && ::chdir(next) != 0) return 2;
    if (a == "--fake-die-at") die_at = std::atol(next);
    if (a == "--fake-hang-at") hang_at = std::atol(next);
    if (a == "--fake-bad-crc-at") bad_crc_at = std::atol(next);
    if (a == "--fake-no-lockstep") no_lockstep = true;
    if (a == "--fake-record") record.open(next);
    if (a == "--fake-pid-file") std::ofstream(next) << ::getpid() << '\n';
  }
  const int mode = static_cast<int>(param("FAKE_MODE", 0));
  const double fixed_u = param("FAKE_U", 0.0);
  const long first = static_cast<long>(param("FAKE_FIRST", 0));
  const double ready_s = param("FAKE_READY_S", 0.0);
  const double hover = param("MPC_THR_HOVER", 0.5);
  std::printf("fake px4: instance %d, autostart %s, mode %d\n", instance, std::getenv("PX4_SYS_AUTOSTART"), mode);
  std::fflush(stdout);

  // The GCS link, bound before the simulator link connects (quadcosim's first heartbeat then finds it).
  const int gcs = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  local.sin_port = htons(static_cast<std::uint16_t>(18570 + instance));
  if (::bind(gcs, reinterpret_cast<sockaddr*>(&local), sizeof(local)) != 0) return 5;
  // The simulator link: connect, retrying, as simulator_mavlink does.
  const int sim = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  to.sin_port = htons(static_cast<std::uint16_t>(4560 + instance));
  for (int tries = 0; ::connect(sim, reinterpret_cast<sockaddr*>(&to), sizeof(to)) != 0; ++tries) {
    if (tries > 20000) return 4;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  sockaddr_in gcs_peer{};
  bool have_peer = false;
  std::uint8_t seq = 0, gcs_seq = 0;
  auto send_gcs = [&](std::uint32_t id, const std::vector<std::uint8_t>& payload) {
    if (!have_peer) return;
    const auto f = mav::encode(gcs_seq++, static_cast<std::uint8_t>(instance + 1), 1, id, payload);
    ::sendto(gcs, f.data(), f.size(), 0, reinterpret_cast<const sockaddr*>(&gcs_peer), sizeof(gcs_peer));
  };
  auto ack = [&](std::uint16_t command, std::uint8_t result) {
    std::vector<std::uint8_t> p(3, 0);
    put(p, 0, command);
    p[2] = result;
    send_gcs(mav::kCommandAck, p);
  };

  mav::Parser parser, gcs_parser;
  std::array<std::uint8_t, 4096> buf{};
  long sensors = 0;
  bool armed = mode == 0, landing = false;
  std::uint32_t custom_mode = (4u << 16) | (3u << 24);  // AUTO.LOITER
  double target_m = 0.0, home_alt = NAN, alt = NAN, climb = 0.0;
  double last_heartbeat_s = -1.0;
  for (;;) {
    pollfd fds[2] = {{sim, POLLIN, 0}, {gcs, POLLIN, 0}};
    if (::poll(fds, 2, 1000) < 0) continue;
    if (fds[1].revents & POLLIN) {
      sockaddr_in from{};
      socklen_t len = sizeof(from);
      const ssize_t n = ::recvfrom(gcs, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), &len);
      if (n > 0) {
        gcs_peer = from;
        have_peer = true;
        gcs_parser.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
      }
    }
    if (fds[0].revents & (POLLIN | POLLHUP)) {
      const ssize_t n = ::recv(sim, buf.data(), buf.size(), 0);
      if (n <= 0) return 0;  // quadcosim closed the link: the run is over
      parser.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    }
    while (auto f = gcs_parser.next()) {
      if (f->msgid != mav::kCommandLong && f->msgid != mav::kCommandInt) continue;
      const bool is_int = f->msgid == mav::kCommandInt;
      const std::uint16_t command = at<std::uint16_t>(f->payload, is_int ? 28 : 28);
      const float p1 = at<float>(f->payload, 0), p2 = at<float>(f->payload, 4), p3 = at<float>(f->payload, 8),
                  p4 = at<float>(f->payload, 12);
      const float p7 = at<float>(f->payload, 24);
      if (record.is_open()) {
        record << "C " << command << ' ' << (is_int ? at<std::int32_t>(f->payload, 16) : 0) << ' '
               << (is_int ? at<std::int32_t>(f->payload, 20) : 0) << ' ' << p7 << ' ' << p1 << ' ' << p2 << ' ' << p3
               << ' ' << p4 << '\n';
      }
      if (command == mav::kCmdComponentArmDisarm) {
        const bool ready = last_heartbeat_s >= ready_s;
        if (p1 > 0.5 && !ready) {
          ack(command, 1);
        } else {
          armed = p1 > 0.5;
          ack(command, 0);
        }
      } else if (command == mav::kCmdNavTakeoff) {
        target_m = p7 - (std::isfinite(home_alt) ? home_alt : 0.0);
        landing = false;
        custom_mode = (4u << 16) | (2u << 24);
        ack(command, 0);
      } else if (command == mav::kCmdDoSetMode) {
        custom_mode = (static_cast<std::uint32_t>(p2) << 16) | (static_cast<std::uint32_t>(p3) << 24);
        landing = p2 == 4.0f && p3 == 6.0f;
        ack(command, 0);
      } else if (command == mav::kCmdDoReposition) {
        target_m = p7 - (std::isfinite(home_alt) ? home_alt : 0.0);
        custom_mode = (4u << 16) | (3u << 24);
        ack(command, 0);
      } else {
        ack(command, 3);  // unsupported
      }
    }
    while (auto f = parser.next()) {
      if (f->msgid == mav::kHilGps) {
        const auto& p = f->payload;
        climb = -at<std::int16_t>(p, 30) / 100.0;
        if (record.is_open()) {
          record << "G " << at<std::uint64_t>(p, 0) << ' ' << at<std::int32_t>(p, 8) << ' ' << at<std::int32_t>(p, 12)
                 << ' ' << at<std::int32_t>(p, 16) << ' ' << at<std::uint16_t>(p, 20) << ' ' << at<std::uint16_t>(p, 22)
                 << ' ' << at<std::uint16_t>(p, 24) << ' ' << at<std::int16_t>(p, 26) << ' ' << at<std::int16_t>(p, 28)
                 << ' ' << at<std::int16_t>(p, 30) << ' ' << at<std::uint16_t>(p, 32) << ' '
                 << int(at<std::uint8_t>(p, 34)) << ' ' << int(at<std::uint8_t>(p, 35)) << '\n';
        }
        continue;
      }
      if (f->msgid != mav::kHilSensor) continue;
      const auto& p = f->payload;
      const std::uint64_t t_us = at<std::uint64_t>(p, 0);
      const std::uint32_t fields = at<std::uint32_t>(p, 60);
      if (record.is_open()) {
        char line[512];
        std::snprintf(line, sizeof(line), "S %llu %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %u\n",
                      static_cast<unsigned long long>(t_us), at<float>(p, 8), at<float>(p, 12), at<float>(p, 16),
                      at<float>(p, 20), at<float>(p, 24), at<float>(p, 28), at<float>(p, 32), at<float>(p, 36),
                      at<float>(p, 40), at<float>(p, 44), at<float>(p, 52), at<float>(p, 56), fields);
        record << line << std::flush;
      }
      if ((fields & 0x1A00) == 0x1A00) {
        // Pressure altitude of the standard atmosphere (its inverse, written here from ISO 2533).
        const double hpa = at<float>(p, 44);
        alt = 44330.77 * (1.0 - std::pow(hpa / 1013.25, 0.190263));
        if (!std::isfinite(home_alt)) home_alt = alt;
      }
      ++sensors;
      const double t_s = static_cast<double>(t_us) * 1e-6;
      if (t_s - last_heartbeat_s >= 1.0 - 1e-9 || last_heartbeat_s < 0) {
        last_heartbeat_s = t_s;
        send_gcs(mav::kHeartbeat,
                 mav::heartbeat(2, 12, static_cast<std::uint8_t>(armed ? 0x81 : 0x01), custom_mode, 4));
      }
      if (sensors == die_at) return 3;
      if (sensors == hang_at) {
        for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
      }
      if (sensors <= first) continue;
      float u = 0.0f;
      if (mode == 0) {
        u = static_cast<float>(fixed_u);
      } else if (armed && std::isfinite(alt)) {
        if (landing) target_m -= 0.004 * 0.7;  // 0.7 m/s at 250 Hz
        const double h = alt - home_alt;
        const double a = 2.0 * (target_m - h) - 2.5 * climb;
        const double fraction = std::clamp(hover * (1.0 + a / 9.81), 0.0, 1.0);
        u = static_cast<float>(std::sqrt(fraction));
        if (landing && h < 0.05 && target_m < -0.5) {
          armed = false;
          landing = false;
        }
      }
      std::vector<std::uint8_t> out(81, 0);
      put(out, 0, t_us);
      put(out, 8, static_cast<std::uint64_t>(no_lockstep ? 0 : 1));
      if (armed) {
        for (int i = 0; i < 4; ++i) put(out, 16 + 4 * static_cast<std::size_t>(i), u);
      }
      out[80] = static_cast<std::uint8_t>(armed ? 129 : 1);
      std::vector<std::uint8_t> frame =
          mav::encode(seq++, static_cast<std::uint8_t>(instance + 1), 1, mav::kHilActuatorControls, out);
      if (sensors == bad_crc_at) frame.back() ^= 0x5A;
      for (std::size_t done = 0; done < frame.size();) {
        const ssize_t n = ::send(sim, frame.data() + done, frame.size() - done, MSG_NOSIGNAL);
        if (n <= 0) return 0;
        done += static_cast<std::size_t>(n);
      }
    }
  }
}
