// A stand-in for a SITL firmware, for the tests: it takes ArduPilot's command line (the options
// quadcosim passes), speaks the JSON physics protocol from the firmware's side, and flies a plain
// controller, so the whole loop runs without ArduPilot. Its parameters come from the --defaults files:
//   FAKE_MODE 0: every motor at FAKE_PWM [us] (open loop: the height follows a closed form)
//   FAKE_MODE 1: hold FAKE_ALT [m] above home, level (PD on height and tilt, hover feed-forward from
//                FAKE_MASS [kg], FAKE_KT [N/(rad/s)^2], FAKE_WMAX [rad/s], FAKE_ARM [m])
//   FAKE_MODE 2: as 1, but commanded over MAVLink on its SERIAL0 link, as a GCS commands ArduCopter:
//                HEARTBEAT at 1 Hz (armed flag, custom mode); COMMAND_LONG DO_SET_MODE (4 guided,
//                9 land), COMPONENT_ARM_DISARM (refused, result 1, before FAKE_READY_S [s] and outside
//                guided), NAV_TAKEOFF (param7 [m]) each answered by COMMAND_ACK;
//                SET_POSITION_TARGET_LOCAL_NED sets the height (-z); land descends to the ground and
//                disarms there. Disarmed, every motor is at MOT_PWM_MIN (stopped).
// and its faults from its own options (quadcosim passes a scenario's sitl.args):
//   --fake-bad-magic-at N   frame N goes out with a wrong magic
//   --fake-die-at N         exit(3) instead of sending frame N
//   --fake-hang-at N        stop answering (sleep) at frame N
//   --fake-repeat-every N   every Nth frame is sent twice (as the firmware does when it waits long)
//   --fake-first-copies N   the first frame is sent N times before the first answer
//   --fake-panic            print a PANIC line and hang before any frame (as ArduPilot's SITL does on a
//                           bad --defaults path)
//   --fake-record PATH      writes each state it receives: t, gyro FRD, accel FRD (one line a frame)
//   --fake-pid-file PATH    writes its process id there (for the tests: is it gone afterwards?)
// Motor outputs follow ArduPilot's quad plus frame: channel 1 right, 2 left, 3 front, 4 back.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "sitl/json_codec.hpp"
#include "sitl/mavlink.hpp"

using quadcosim::sitl::FdmState;

namespace {

std::map<std::string, double> read_params(const std::string& list) {
  std::map<std::string, double> p;
  std::stringstream files(list);
  for (std::string file; std::getline(files, file, ',');) {
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);) {
      std::istringstream l(line);
      std::string name;
      double v = 0;
      if (l >> name >> v && name[0] != '#') p[name] = v;
    }
  }
  return p;
}

double get(const std::map<std::string, double>& p, const char* name, double fallback) {
  auto it = p.find(name);
  return it == p.end() ? fallback : it->second;
}

}  // namespace

int main(int argc, char** argv) {
  int sim_port = 9002, mavlink_port = 0;
  std::ofstream record;
  std::string defaults;
  long bad_magic_at = -1, die_at = -1, hang_at = -1, repeat_every = 0, first_copies = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : "";
    if (a == "--sim-port-out") sim_port = std::atoi(next);
    if (a == "--defaults") defaults = next;
    if (a == "--serial0" && std::strncmp(next, "tcpclient:", 10) == 0) {
      const char* colon = std::strrchr(next, ':');
      mavlink_port = std::atoi(colon + 1);
    }
    if (a == "--fake-bad-magic-at") bad_magic_at = std::atol(next);
    if (a == "--fake-die-at") die_at = std::atol(next);
    if (a == "--fake-hang-at") hang_at = std::atol(next);
    if (a == "--fake-repeat-every") repeat_every = std::atol(next);
    if (a == "--fake-first-copies") first_copies = std::atol(next);
    if (a == "--fake-record") record.open(next);
    if (a == "--fake-panic") {
      std::printf("PANIC: Failed to load defaults from %s\n", defaults.c_str());
      std::fflush(stdout);
      for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    if (a == "--fake-pid-file") std::ofstream(next) << ::getpid() << "\n";
  }
  const auto p = read_params(defaults);
  const int mode = static_cast<int>(get(p, "FAKE_MODE", 1));
  const double pwm_const = get(p, "FAKE_PWM", 1400);
  double alt = get(p, "FAKE_ALT", 2.0);
  const double ready_s = get(p, "FAKE_READY_S", 2.0);
  const double mass = get(p, "FAKE_MASS", 1.96), kt = get(p, "FAKE_KT", 2.06e-7);
  const double wmax = get(p, "FAKE_WMAX", 12000), arm = get(p, "FAKE_ARM", 0.59), g = 9.81;
  const double pwm_min = get(p, "MOT_PWM_MIN", 1000), pwm_max = get(p, "MOT_PWM_MAX", 2000);
  std::printf("fake firmware: JSON to 127.0.0.1:%d, mode %d\n", sim_port, mode);
  std::fflush(stdout);

  // Its MAVLink link, as ArduPilot's SERIAL0 tcpclient: connected, silent.
  int tcp = -1;
  if (mavlink_port > 0) {
    tcp = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(mavlink_port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(tcp, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) std::perror("fake firmware: connect");
  }
  namespace mav = quadcosim::sitl::mavlink;
  mav::Parser parser;
  std::uint8_t seq = 0;
  bool armed = mode != 2;
  std::uint32_t custom_mode = 0;
  long last_heartbeat = -1;
  const auto send = [&](std::uint32_t id, const std::vector<std::uint8_t>& payload) {
    if (tcp < 0) return;
    const auto f = mav::encode(seq++, 1, 1, id, payload);
    if (::send(tcp, f.data(), f.size(), MSG_NOSIGNAL) < 0) std::perror("fake firmware: send");
  };
  const auto ack = [&](std::uint16_t command, std::uint8_t result) {
    std::vector<std::uint8_t> payload = {static_cast<std::uint8_t>(command & 0xff),
                                         static_cast<std::uint8_t>(command >> 8), result};
    send(mav::kCommandAck, payload);
    std::printf("fake firmware: command %u -> %u\n", command, result);
  };
  const int udp = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(sim_port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);

  quadcosim::sitl::ServoPacket packet;
  packet.frame_rate_hz = 400;
  packet.pwm_us.assign(16, 0);
  // Before any state: idle, or in open loop its constant from the first frame on.
  const double first = mode == 0 ? pwm_const : pwm_min;
  double pwm[4] = {first, first, first, first};
  double integral = 0.0, last_t = 0.0;
  for (std::uint32_t frame = 0;; ++frame) {
    if (static_cast<long>(frame) == die_at) {
      std::printf("fake firmware: dying at frame %u\n", frame);
      return 3;
    }
    if (static_cast<long>(frame) == hang_at) {
      std::printf("fake firmware: hanging at frame %u\n", frame);
      std::fflush(stdout);
      for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    packet.frame_count = frame;
    for (int c = 0; c < 4; ++c) packet.pwm_us[c] = static_cast<std::uint16_t>(std::lround(pwm[c]));
    std::vector<std::uint8_t> bytes = quadcosim::sitl::encode_servo_packet(packet);
    if (static_cast<long>(frame) == bad_magic_at) bytes[0] ^= 0x55;
    long copies = frame == 0 ? first_copies : 1;
    if (repeat_every > 0 && frame > 0 && frame % repeat_every == 0) copies = 2;
    for (long k = 0; k < copies; ++k) {
      ::sendto(udp, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
    }
    // The answer, resending the frame every second without one (as ArduPilot does).
    char buf[65536];
    ssize_t n = -1;
    for (int waited = 0; n <= 0; ++waited) {
      pollfd pf{udp, POLLIN, 0};
      if (::poll(&pf, 1, 1000) > 0) {
        n = ::recv(udp, buf, sizeof(buf) - 1, 0);
      } else {
        if (waited > 60) return 4;  // nobody there
        ::sendto(udp, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
      }
    }
    buf[n] = 0;
    FdmState s;
    try {
      s = quadcosim::sitl::decode_fdm_json(std::string(buf, static_cast<std::size_t>(n)));
    } catch (const std::exception& e) {
      std::printf("fake firmware: %s\n", e.what());
      return 5;
    }
    if (record.is_open()) {
      record.precision(17);
      record << s.timestamp_s << ' ' << s.gyro_FRD.x() << ' ' << s.gyro_FRD.y() << ' ' << s.gyro_FRD.z() << ' '
             << s.accel_FRD.x() << ' ' << s.accel_FRD.y() << ' ' << s.accel_FRD.z() << std::endl;  // it is killed
    }
    const double dt = s.timestamp_s - last_t;
    last_t = s.timestamp_s;
    if (mode == 0) {
      for (double& w : pwm) w = pwm_const;
      continue;
    }
    if (mode == 2) {
      // Its GCS link, once a frame: heartbeats, commands.
      if (static_cast<long>(s.timestamp_s) > last_heartbeat) {
        last_heartbeat = static_cast<long>(s.timestamp_s);
        send(mav::kHeartbeat,
             mav::heartbeat(2, 3, static_cast<std::uint8_t>(armed ? 0x80 | 0x01 : 0x01), custom_mode, armed ? 4 : 3));
      }
      std::uint8_t in[4096];
      for (ssize_t n; tcp >= 0 && (n = ::recv(tcp, in, sizeof(in), MSG_DONTWAIT)) > 0;) {
        parser.feed(std::span<const std::uint8_t>(in, static_cast<std::size_t>(n)));
      }
      while (auto f = parser.next()) {
        if (f->msgid == mav::kCommandLong) {
          std::vector<std::uint8_t> pl = f->payload;
          pl.resize(33, 0);
          float param[7];
          std::memcpy(param, pl.data(), sizeof(param));
          const std::uint16_t command = static_cast<std::uint16_t>(pl[28] | (pl[29] << 8));
          if (command == mav::kCmdDoSetMode) {
            custom_mode = static_cast<std::uint32_t>(param[1]);
            if (custom_mode == 9) alt = -1.0;  // land: down to the ground
            ack(command, 0);
          } else if (command == mav::kCmdComponentArmDisarm) {
            const bool ok = param[0] == 0.0f || (custom_mode == 4 && s.timestamp_s >= ready_s);
            if (ok) armed = param[0] != 0.0f;
            ack(command, ok ? 0 : 1);
          } else if (command == mav::kCmdNavTakeoff) {
            const bool ok = armed && custom_mode == 4;
            if (ok) alt = param[6];
            ack(command, ok ? 0 : 4);
          } else {
            ack(command, 3);
          }
        } else if (f->msgid == mav::kSetPositionTargetLocalNed) {
          std::vector<std::uint8_t> pl = f->payload;
          pl.resize(53, 0);
          float z = 0;
          std::memcpy(&z, pl.data() + 12, sizeof(z));
          alt = -z;
          std::printf("fake firmware: target height %.2f m\n", alt);
        }
      }
      if (armed && custom_mode == 9 && -s.p_NED.z() < 0.02 && std::abs(s.v_NED.z()) < 0.05) armed = false;
      if (!armed) {
        for (double& w : pwm) w = pwm_min;
        integral = 0.0;
        continue;
      }
    }
    // Hold FAKE_ALT: height and climb rate from NED, attitude from the quaternion (FRD).
    const double h = -s.p_NED.z(), climb = -s.v_NED.z();
    if (dt > 0) integral = std::clamp(integral + (alt - h) * dt, -2.0, 2.0);
    const Eigen::Vector3d x_B = s.q_NED_FRD * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d y_B = s.q_NED_FRD * Eigen::Vector3d::UnitY();
    const double pitch = std::asin(std::clamp(-x_B.z(), -1.0, 1.0));  // nose up positive
    const double roll = std::asin(std::clamp(y_B.z(), -1.0, 1.0));    // right side down positive
    const double thrust = mass * (g + 4.0 * (alt - h) - 3.0 * climb + 1.0 * integral);
    const double tx = 0.0149 * (-60.0 * roll - 12.0 * s.gyro_FRD.x());
    const double ty = 0.0153 * (-60.0 * pitch - 12.0 * s.gyro_FRD.y());
    // Channel thrusts: 1 right (+y FRD: more thrust rolls it up, -tx), 2 left, 3 front (+ty), 4 back.
    const double f[4] = {thrust / 4 - tx / (2 * arm), thrust / 4 + tx / (2 * arm), thrust / 4 + ty / (2 * arm),
                         thrust / 4 - ty / (2 * arm)};
    for (int c = 0; c < 4; ++c) {
      const double w = std::sqrt(std::max(f[c], 0.0) / kt);
      pwm[c] = pwm_min + std::clamp(w / wmax, 0.0, 1.0) * (pwm_max - pwm_min);
    }
  }
}
