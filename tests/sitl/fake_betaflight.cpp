// A stand-in for Betaflight's SITL build (make TARGET=SITL), for the tests: the same fixed ports and
// packets (src/platform/SIMULATOR: UDP 9003 fdm_packet in, 9004 rc_packet in, 9002 servo_packet out,
// 9001 servo_packet_raw out, TCP 5761 as its UART1, answering MSP requests), the same `--config FILE` (the CLI lines
// kept as eeprom.bin in the current folder, then exit 0), and one motor packet per FDM packet. It reads
// the state as sitl.c's Gazebo bridge does, written out here from sitl.c and sitl_gyro.h, not with
// quadcosim's code: gyro roll = rpy[0], pitch = -rpy[1], yaw = rpy[2]; the attitude quaternion with qy and
// qz negated, then multiplied by Rz(pi/2) (its NWU world). Its law is angle mode: armed while AUX1 is in
// the ARM range of eeprom.bin's `aux 0 0 ...` line, armed only with the throttle at or below 1050 us;
// the sticks' angles (500 us: 60 deg), a PD on roll and pitch and a D on yaw (gains for the paper's
// vehicle), through Betaflight's QUADX mixer table (mixer_init.c) on the throttle's motor value
// 0.055 + 0.945 (T - 1050) / 950; disarmed, every motor is 0.
// Options: --fake-pid-file PATH (its process id), --fake-hang-at N (no answer from FDM packet N, 1-based),
// --fake-record PATH (one line per FDM packet: its 18 values, then the RC channels 1..5 it had),
// --fake-late-every N (every Nth FDM packet answered 6 ms after it came, as a Betaflight whose PID loop
// came due late).
#include <arpa/inet.h>
#include <fcntl.h>
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
#include <sstream>
#include <string>
#include <thread>

#include "sitl/betaflight.hpp"

namespace bf = quadcosim::sitl::betaflight;

namespace {

int bind_udp_or_tcp(int type, int port) {
  const int fd = ::socket(AF_INET, type, 0);
  const int one = 1;
  if (type == SOCK_STREAM) ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    std::printf("[SITL] cannot bind port %d: %s\n", port, std::strerror(errno));
    std::exit(1);
  }
  if (type == SOCK_STREAM) ::listen(fd, 1);
  return fd;
}

// Betaflight's mixerQuadX: motors 1..4 (rear-right, front-right, rear-left, front-left): throttle, roll,
// pitch, yaw.
constexpr float kQuadX[4][4] = {{1, -1, 1, -1}, {1, -1, -1, 1}, {1, 1, 1, 1}, {1, 1, -1, -1}};

}  // namespace

int main(int argc, char** argv) {
  long hang_at = -1, late_every = -1;
  std::ofstream record;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : "";
    if (a == "--config") {
      // Betaflight applies the lines, saves eeprom.bin and exits; a CLI that does not end in save is refused.
      std::ifstream in(next);
      std::stringstream all;
      all << in.rdbuf();
      const std::string text = all.str();
      if (!in || text.find("\nsave\n") == std::string::npos) {
        std::printf("[SITL] Config file not found or without save: %s\n", next);
        return 1;
      }
      std::ofstream("eeprom.bin") << text;
      std::printf("[CONFIG] Config file processed, EEPROM saved\n");
      return 0;
    }
    if (a == "--fake-pid-file") std::ofstream(next) << ::getpid() << '\n';
    if (a == "--fake-hang-at") hang_at = std::atol(next);
    if (a == "--fake-late-every") late_every = std::atol(next);
    if (a == "--fake-record") record.open(next);
  }
  // The ARM range from eeprom.bin: `aux 0 0 CHANNEL LOW HIGH ...` (AUX1 is channel index 0).
  int arm_aux = -1, arm_low = 0, arm_high = 0;
  {
    std::ifstream eeprom("eeprom.bin");
    std::string line;
    while (std::getline(eeprom, line)) {
      int idx = 0, box = 0, ch = 0, lo = 0, hi = 0;
      if (std::sscanf(line.c_str(), "aux %d %d %d %d %d", &idx, &box, &ch, &lo, &hi) == 5 && box == 0) {
        arm_aux = ch, arm_low = lo, arm_high = hi;
      }
    }
  }
  std::printf("[SITL] fake Betaflight: ARM on AUX%d %d..%d\n", arm_aux + 1, arm_low, arm_high);
  std::fflush(stdout);
  const int state = bind_udp_or_tcp(SOCK_DGRAM, bf::kStatePort);
  const int rc = bind_udp_or_tcp(SOCK_DGRAM, bf::kRcPort);
  const int cli = bind_udp_or_tcp(SOCK_STREAM, bf::kCliPort);
  ::fcntl(cli, F_SETFL, O_NONBLOCK);
  const int out = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in motors_to{}, raw_to{};
  motors_to.sin_family = raw_to.sin_family = AF_INET;
  motors_to.sin_addr.s_addr = raw_to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  motors_to.sin_port = htons(static_cast<std::uint16_t>(bf::kMotorPort));
  raw_to.sin_port = htons(static_cast<std::uint16_t>(bf::kPwmRawPort));

  std::array<std::uint16_t, bf::kRcChannels> ch{};
  ch.fill(1000);
  bool armed = false;
  long packets = 0;
  std::array<std::uint8_t, 512> buf{};
  int msp = -1;  // a connection to its UART1: MSP requests ("$M<") get an MSP_API_VERSION answer
  for (;;) {
    pollfd p{state, POLLIN, 0};
    if (::poll(&p, 1, 5) <= 0) {
      if (msp < 0) msp = ::accept4(cli, nullptr, nullptr, SOCK_NONBLOCK);
      char req[64];
      const ssize_t m = msp >= 0 ? ::recv(msp, req, sizeof(req), MSG_DONTWAIT) : -1;
      if (m == 0) ::close(msp), msp = -1;
      if (m > 0 && std::string(req, static_cast<std::size_t>(m)).find("$M<") != std::string::npos) {
        const char answer[] = {'$', 'M', '>', 3, 1, 0, 1, 47, 46};
        ::send(msp, answer, sizeof(answer), MSG_NOSIGNAL);
      }
      continue;
    }
    const ssize_t n = ::recv(state, buf.data(), buf.size(), 0);
    if (n != static_cast<ssize_t>(bf::kFdmPacketBytes)) continue;  // sitl.c drops other sizes
    ++packets;
    // The RC packets sent before this FDM packet are in their socket already: the newest counts.
    for (;;) {
      const ssize_t m = ::recv(rc, buf.data() + 256, 256, MSG_DONTWAIT);
      if (m <= 0) break;
      if (m == static_cast<ssize_t>(bf::kRcPacketBytes)) {
        ch = bf::decode_rc(std::span<const std::uint8_t>(buf.data() + 256, static_cast<std::size_t>(m)));
      }
    }
    if (hang_at > 0 && packets >= hang_at) continue;
    const bf::FdmPacket f = bf::decode_fdm(std::span<const std::uint8_t>(buf.data(), bf::kFdmPacketBytes));
    if (record.is_open()) {
      record.precision(17);
      record << f.timestamp_s;
      for (const auto* v : {&f.gyro_rad_s, &f.accel_m_s2, &f.velocity_m_s, &f.position}) {
        for (int k = 0; k < 3; ++k) record << ' ' << (*v)[k];
      }
      for (int k = 0; k < 4; ++k) record << ' ' << f.quat_wxyz[k];
      record << ' ' << f.pressure_Pa;
      for (int k = 0; k < 5; ++k) record << ' ' << ch[static_cast<std::size_t>(k)];
      record << '\n' << std::flush;
    }
    // sitl.c / sitl_gyro.h (Gazebo bridge).
    const double gyro_roll = f.gyro_rad_s[0], gyro_pitch = -f.gyro_rad_s[1], gyro_yaw = f.gyro_rad_s[2];
    const double qw = f.quat_wxyz[0], qx = f.quat_wxyz[1], qy = -f.quat_wxyz[2], qz = -f.quat_wxyz[3];
    const double k = std::sqrt(0.5);
    const double aw = k * (qw - qz), ax = k * (qx - qy), ay = k * (qy + qx), az = k * (qz + qw);
    const double roll = std::atan2(2 * (aw * ax + ay * az), 1 - 2 * (ax * ax + ay * ay));  // right side down +
    const double pitch = std::asin(std::clamp(2 * (aw * ay - az * ax), -1.0, 1.0));        // nose down +
    const int aux = arm_aux >= 0 ? ch[static_cast<std::size_t>(4 + arm_aux)] : 0;
    const bool arm_switch = arm_aux >= 0 && aux >= arm_low && aux < arm_high;
    if (!arm_switch) armed = false;
    if (arm_switch && !armed && ch[2] <= 1050) {
      armed = true;
      std::printf("[SITL] armed at t = %.4f s\n", f.timestamp_s);
      std::fflush(stdout);
    }
    std::array<float, 4> motor{};
    if (armed) {
      const double limit = 60.0 * M_PI / 180.0;
      const double roll_want = (ch[0] - 1500.0) / 500.0 * limit, pitch_want = (ch[1] - 1500.0) / 500.0 * limit;
      const double kp = 0.04, kd = 0.005, kd_yaw = 0.05;
      const double u_roll = kp * (roll_want - roll) - kd * gyro_roll;
      const double u_pitch = kp * (pitch_want - pitch) - kd * gyro_pitch;
      const double u_yaw = -kd_yaw * gyro_yaw;
      const double base = 0.055 + 0.945 * std::clamp((ch[2] - 1050.0) / 950.0, 0.0, 1.0);
      for (int m = 0; m < 4; ++m) {
        const double v = base + kQuadX[m][1] * u_roll + kQuadX[m][2] * u_pitch + kQuadX[m][3] * u_yaw;
        motor[static_cast<std::size_t>(m)] = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
    }
    if (late_every > 0 && packets % late_every == 0) std::this_thread::sleep_for(std::chrono::milliseconds(6));
    const auto bytes = bf::encode_motors(motor);
    ::sendto(out, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&motors_to), sizeof(motors_to));
    std::array<std::uint8_t, 68> raw{};  // servo_packet_raw: motorCount, padding, 16 floats
    raw[0] = 4;
    ::sendto(out, raw.data(), raw.size(), 0, reinterpret_cast<const sockaddr*>(&raw_to), sizeof(raw_to));
  }
  ::close(cli);
}
