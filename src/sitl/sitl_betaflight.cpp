// Betaflight's SITL build as the controller (docs/sitl.md, "Betaflight"). Its ports are fixed (UDP 9001
// to 9004, TCP 5761): one instance per network namespace; a second is refused, naming the port in use.
//
// Start: the CLI lines (betaflight::base_cli, then the params files) go through `BINARY --config FILE`,
// which applies them, saves eeprom.bin in the run's folder and exits; then BINARY runs there, and the
// first packets wait for it to answer MSP on TCP 5761 (its start-up done).
//
// Each step (period dt, t_n = n dt): the RC packet (stamped t_n), then the FDM packet (the state at t_n
// in the Gazebo bridge's frames, betaflight.hpp), and the motor packet that answers it: its motors are
// the rotor speeds over [t_n, t_n+1). Steps are paced at realtime_factor times real time (a step's packets
// leave dt / realtime_factor of wall time after the last step's whatever its answer did), which holds
// Betaflight's clock rate (simRate) at that factor; a step whose answer has not come by the next send time
// flies the newest motor packet before it (out.late). Unpaced (realtime_factor 0) and before the first
// answer, each step waits for its answer: stale packets are dropped before each send (out.stale), and a
// step without an answer within resend_ms wall time sends the same FDM packet again (out.resent) until
// timeout_s. Betaflight sends one motor packet
// per FDM packet (sitl.c's updateLock); built with ENABLE_SIMULATOR_GYROPID_SYNC its PID loop also runs
// once per FDM packet. Its clock is wall time scaled by the rate of FDM timestamps to wall time (simRate):
// not quadcosim's, so the flight is not bit-for-bit repeatable (docs/sitl.md says how far).
//
// The pilot: AUX1 low and throttle 1000 us until arm_at_s, then AUX1 high (ARM; ANGLE is always on), low
// for 0.25 s each second until its motors turn (armed: they idle), the throttle still at 1000 us for 0.5 s
// after that (Betaflight arms only with the throttle low), then roll and pitch sticks at
// the reference's roll and pitch over Betaflight's angle limit (60 deg), yaw centred, and the throttle stick from an
// altitude loop on the reference's height: the hover throttle as feed-forward plus PID on the height error (gains for a
// natural frequency of 1.5 rad/s; the integral only within 0.5 m of the reference).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <thread>

#include "isolation/child.hpp"
#include "sensors/geodesy.hpp"
#include "sitl/betaflight.hpp"
#include "sitl/betaflight_link.hpp"
#include "sitl/firmware_process.hpp"
#include "sitl/json_codec.hpp"
#include "sitl/sitl_controller.hpp"

namespace quadcosim::sitl {

namespace fs = std::filesystem;
namespace bf = betaflight;

namespace {

constexpr double kAngleLimitRad = 60.0 * std::numbers::pi / 180.0;  // Betaflight's angle_limit default
constexpr double kIdle = 0.055;         // its motor idle (dshot_idle_value 550: 5.5 %) at minimum throttle
constexpr double kMinCheckUs = 1050.0;  // min_check: the throttle stick's zero
constexpr double kIntegralBandM = 0.5;  // [m] the height loop integrates within this of the reference
constexpr double kArmHoldS = 0.5;       // [s] AUX1 high with the throttle low before the altitude loop

}  // namespace

std::vector<std::string> SitlController::betaflight_cli() const {
  std::vector<std::string> lines = bf::base_cli();
  for (const std::string& file : spec_.params) {
    std::ifstream f(file);
    std::string line;
    while (std::getline(f, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
      if (line.rfind("save", 0) == 0 || line.rfind("exit", 0) == 0) continue;  // quadcosim saves at the end
      lines.push_back(line);
    }
  }
  lines.emplace_back("save");
  return lines;
}

void SitlController::start_betaflight() {
  bf_ = std::make_unique<BfLink>();
  BfLink& l = *bf_;
  // The ports first: a second instance in this network namespace is refused before anything starts.
  auto taken = [&](int type, int port) {
    fail(
        fmt::format("{} port {} on 127.0.0.1 is in use ({}): Betaflight's SITL ports are fixed (UDP 9001-9004, "
                    "TCP 5761), so one Betaflight runs per network namespace; another run or firmware holds it "
                    "(docs/sitl.md, \"Betaflight\")",
                    type == SOCK_DGRAM ? "UDP" : "TCP", port, std::strerror(errno)));
  };
  l.motors = bind_loopback(SOCK_DGRAM, bf::kMotorPort);
  if (l.motors < 0) taken(SOCK_DGRAM, bf::kMotorPort);
  l.raw = bind_loopback(SOCK_DGRAM, bf::kPwmRawPort);
  if (l.raw < 0) taken(SOCK_DGRAM, bf::kPwmRawPort);
  for (const auto& [type, port] : {std::pair{SOCK_DGRAM, bf::kStatePort}, std::pair{SOCK_DGRAM, bf::kRcPort},
                                   std::pair{SOCK_STREAM, bf::kCliPort}}) {
    const int fd = bind_loopback(type, port);
    if (fd < 0) taken(type, port);
    ::close(fd);
  }
  l.out = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (l.out < 0) fail(std::string("cannot open a UDP socket: ") + std::strerror(errno));
  l.work_dir = make_work_dir(l.temporary);
  const fs::path cli = fs::path(l.work_dir) / "quadcosim-cli.txt";
  {
    std::ofstream f(cli);
    for (const std::string& line : betaflight_cli()) f << line << '\n';
    if (!f) fail("cannot write " + cli.string());
  }
  // Its configuration: applied, saved to eeprom.bin, and the process exits.
  {
    FirmwareProcess config({spec_.binary, "--config", cli.string()}, l.work_dir,
                           (fs::path(l.work_dir) / "config.log").string());
    const double deadline = wall_clock_s() + spec_.start_timeout_s;
    std::optional<std::string> end;
    while (!(end = config.ended())) {
      if (wall_clock_s() > deadline) {
        fail(fmt::format("its --config run did not exit within {:g} s (log {})", spec_.start_timeout_s,
                         (fs::path(l.work_dir) / "config.log").string()));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (*end != "exited with status 0" || !fs::exists(fs::path(l.work_dir) / "eeprom.bin")) {
      l.temporary = false;
      fail(fmt::format("applying its CLI lines ({} --config {}) {}; its log {}:{}", spec_.binary, cli.string(), *end,
                       (fs::path(l.work_dir) / "config.log").string(), config.log_tail()));
    }
  }
  std::vector<std::string> argv = {spec_.binary};
  argv.insert(argv.end(), spec_.args.begin(), spec_.args.end());
  l.process = launch(argv, l.work_dir);
  wait_for_betaflight_msp();
  const model::VehicleParams& v = model_.params();
  l.hover_u = std::sqrt(v.mass_kg * v.gravity_m_s2 / (4.0 * v.kt_N_per_rad2_s2)) / map_.omega_max_rad_s;
}

// Betaflight's state handler dereferences its sensors as soon as an FDM packet comes, and they exist
// only once its start-up is done (a packet earlier crashed it: SIGSEGV): the first FDM packet waits for
// an answer to an MSP request (MSP_API_VERSION, "$M<" 0 1 1) on its UART1, TCP 5761, which its
// scheduler gives once it runs.
void SitlController::wait_for_betaflight_msp() {
  const double deadline = wall_clock_s() + spec_.start_timeout_s;
  const sockaddr_in to = loopback_address(bf::kCliPort);
  for (;;) {
    if (auto end = bf_->process->ended()) fail(fmt::format("while starting, the firmware {}", *end));
    if (wall_clock_s() > deadline) {
      fail(fmt::format("no answer to MSP on TCP {} within {:g} s: its start-up did not finish", bf::kCliPort,
                       spec_.start_timeout_s));
    }
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd >= 0 && ::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof(to)) == 0) {
      const std::array<std::uint8_t, 6> request = {'$', 'M', '<', 0, 1, 1};
      ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
      std::string got;
      const double until = wall_clock_s() + 0.2;
      while (wall_clock_s() < until && got.find("$M>") == std::string::npos) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 20) <= 0) continue;
        std::array<char, 256> buf{};
        const ssize_t n = ::recv(fd, buf.data(), buf.size(), MSG_DONTWAIT);
        if (n <= 0) break;
        got.append(buf.data(), static_cast<std::size_t>(n));
      }
      ::close(fd);
      if (got.find("$M>") != std::string::npos) return;
    } else if (fd >= 0) {
      ::close(fd);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

bf::RcSticks SitlController::betaflight_sticks(const control::Observation& obs, const control::Reference& ref,
                                               double dt_s) {
  BfLink& l = *bf_;
  bf::RcSticks s;
  if (t_s_ + 1e-9 < spec_.arm_at_s) return s;  // disarmed, throttle low
  if (l.armed_at_s < 0 && l.motors_on) l.armed_at_s = t_s_;
  if (l.armed_at_s < 0) {
    // Not armed yet (its motors still stopped): AUX1 high for 0.75 s, low for 0.25 s, again (Betaflight
    // arms on the switch's rising edge only while nothing else disables arming), throttle low.
    s.arm = std::fmod(t_s_ - spec_.arm_at_s + 1e-9, 1.0) < 0.75;
    return s;
  }
  s.arm = true;
  if (t_s_ + 1e-9 < l.armed_at_s + kArmHoldS) return s;  // idling with the throttle low first
  s.roll_us = 1500.0 + 500.0 * ref.roll_rad / kAngleLimitRad;
  s.pitch_us = 1500.0 + 500.0 * ref.pitch_rad / kAngleLimitRad;
  // Height: thrust ~ u^2, so d(accel)/du = 2 g / u_hover; PID gains for omega_n = 1.5 rad/s, zeta = 0.8.
  const double g_per_u = 2.0 * model_.params().gravity_m_s2 / std::max(l.hover_u, 1e-3);
  const double wn = 1.5, zeta = 0.8;
  const double kp = wn * wn / g_per_u, kd = 2.0 * zeta * wn / g_per_u, ki = 0.3 * kp;
  const double e_m = ref.p_W.z() - obs.p_W.z();
  const double u_wanted = l.hover_u + kp * e_m + kd * (ref.v_W.z() - obs.v_W.z()) + ki * l.integral_m_s;
  const double u = std::clamp(u_wanted, kIdle, 1.0);
  // No wind-up while the throttle is at its end or far from the height (a climb from the ground).
  if (u == u_wanted && std::abs(e_m) < kIntegralBandM) l.integral_m_s += e_m * dt_s;
  // Betaflight's motor value at throttle stick T: idle + (1 - idle) (T - min_check) / (2000 - min_check).
  s.throttle_us = kMinCheckUs + (2000.0 - kMinCheckUs) * (u - kIdle) / (1.0 - kIdle);
  return s;
}

void SitlController::step_betaflight(const control::Observation& obs, const control::Reference& reference, double dt_s,
                                     control::ControllerOutput& out) {
  if (!bf_) start_betaflight();
  BfLink& l = *bf_;
  const bf::RcSticks sticks = betaflight_sticks(obs, reference, dt_s);
  // Its stamps: quadcosim's time plus the two packets of the prelude (below).
  const double stamp_s = t_s_ + l.stamp_offset_s + 2.0 * dt_s;
  auto rc = bf::encode_rc(stamp_s, bf::rc_channels(sticks));
  const sensors::LocalTangentPlane plane(spec_.site);
  const sensors::Geodetic g = plane.to_geodetic(obs.p_W);
  const Eigen::Vector3d lla(g.longitude_rad * 180.0 / std::numbers::pi, g.latitude_rad * 180.0 / std::numbers::pi,
                            g.height_m);
  if (steps_ == 0) l.first_lon_lat = lla.head<2>();
  auto fdm =
      bf::encode_fdm(bf::gazebo_fdm(stamp_s, obs.w_B, obs.specific_force_B, obs.q_WB, obs.v_W, lla, l.first_lon_lat));
  const sockaddr_in rc_to = loopback_address(bf::kRcPort), fdm_to = loopback_address(bf::kStatePort);
  auto send = [&] {  // the raw PWM packets are never read: dropped before each send
    l.drain(l.raw, nullptr);
    ::sendto(l.out, rc.data(), rc.size(), 0, reinterpret_cast<const sockaddr*>(&rc_to), sizeof(rc_to));
    ::sendto(l.out, fdm.data(), fdm.size(), 0, reinterpret_cast<const sockaddr*>(&fdm_to), sizeof(fdm_to));
  };
  // Paced: step n's packets leave one wall period (dt / realtime_factor) after step n-1's, so that
  // Betaflight's simRate, quadcosim's time over wall time between two FDM packets, stays at the factor.
  const double period_s = spec_.realtime_factor > 0 ? dt_s / spec_.realtime_factor : 0.0;
  if (steps_ == 0) {
    // The prelude: the initial state stamped 0 and dt, a period apart. Betaflight's first packet
    // sets its last stamp without its last arrival time when it comes 500 ms after its start (sitl.c's
    // timeout path), and the second then sets simRate from that stale time (near 0: its clock stops);
    // the third, step 0, sets simRate right: dt over the period.
    for (int k = 0; k < 2; ++k) {
      const auto pre = bf::encode_fdm(
          bf::gazebo_fdm(k * dt_s, obs.w_B, obs.specific_force_B, obs.q_WB, obs.v_W, lla, l.first_lon_lat));
      const auto pre_rc = bf::encode_rc(k * dt_s, bf::rc_channels(sticks));
      ::sendto(l.out, pre_rc.data(), pre_rc.size(), 0, reinterpret_cast<const sockaddr*>(&rc_to), sizeof(rc_to));
      ::sendto(l.out, pre.data(), pre.size(), 0, reinterpret_cast<const sockaddr*>(&fdm_to), sizeof(fdm_to));
      std::this_thread::sleep_for(std::chrono::duration<double>(period_s > 0 ? period_s : dt_s));
    }
  }
  std::array<float, 4> motors{};
  std::array<std::uint8_t, 256> buf{};
  auto alive = [&] {
    if (auto end = l.process->ended()) fail(fmt::format("step {} (t = {:.4f} s): the firmware {}", steps_, t_s_, *end));
    if (isolation::stop_requested()) {
      throw control::ControllerFailure(
          fmt::format("controller sitl ({} {}): step {} (t = {:.4f} s): interrupted (Ctrl-C or SIGTERM)",
                      spec_.firmware, spec_.binary, steps_, t_s_));
    }
  };
  auto decode = [&](ssize_t n) {
    try {
      return bf::decode_motors(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    } catch (const DecodeError& e) {
      fail(fmt::format("step {} (t = {:.4f} s): on UDP {}: {}", steps_, t_s_, bf::kMotorPort, e.what()));
    }
  };
  if (period_s > 0 && l.answered) {
    // Free-running once answered: step n's packets leave one period after step n-1's whatever the answers
    // did, so Betaflight's simRate stays dt / P. Waiting for a late answer would send the next packets
    // late, lower simRate, make its next PID loop come due later still and so the next answer: a run
    // settles at a fraction of the factor (0.13x measured). A step whose answer has not come by the next
    // step's send time flies the newest motor packet Betaflight sent before it (out.late counts them).
    const double wait_s = l.next_send_wall_s - wall_clock_s();
    if (wait_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    if (wait_s < -period_s) l.next_send_wall_s = wall_clock_s();  // quadcosim fell behind: restart the schedule
    for (ssize_t n; (n = ::recv(l.motors, buf.data(), buf.size(), MSG_DONTWAIT)) > 0;) {
      l.held = decode(n);  // answers that came after their step: the newest is what the firmware flies now
      ++l.stale;
    }
    send();
    l.next_send_wall_s += period_s;
    motors = l.held;
    bool own = false;
    for (double now = wall_clock_s(); now < l.next_send_wall_s; now = wall_clock_s()) {
      alive();
      const double left_s = std::min(l.next_send_wall_s - now, 0.05);
      const timespec slice{0, static_cast<long>(left_s * 1e9)};
      pollfd p{l.motors, POLLIN, 0};
      if (::ppoll(&p, 1, &slice, nullptr) <= 0) continue;
      const ssize_t n = ::recv(l.motors, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n <= 0) continue;
      motors = l.held = decode(n);
      own = true;
      break;
    }
    if (own) {
      l.answered_wall_s = wall_clock_s();
    } else {
      ++l.late;
      if (wall_clock_s() - l.answered_wall_s > spec_.timeout_s) {
        fail(fmt::format("step {} (t = {:.4f} s): no motor packet on UDP {} for {:g} s (it went silent)", steps_, t_s_,
                         bf::kMotorPort, spec_.timeout_s));
      }
    }
  } else {
    l.drain(l.motors, &l.stale);  // waiting for its own answer: what came before it is stale
    send();
    l.next_send_wall_s = wall_clock_s() + period_s;
    const double limit_s = l.answered ? spec_.timeout_s : spec_.start_timeout_s;
    const double deadline = wall_clock_s() + limit_s;
    double resend_at = wall_clock_s() + spec_.resend_ms / 1000.0;
    for (;;) {
      alive();
      const double now = wall_clock_s();
      if (now > deadline) {
        fail(fmt::format("step {} (t = {:.4f} s): no motor packet on UDP {} for {:g} s ({})", steps_, t_s_,
                         bf::kMotorPort, limit_s, l.answered ? "it went silent" : "it never answered an FDM packet"));
      }
      if (now > resend_at) {
        ++l.resent;
        if (!l.answered) {
          // Not answered yet: each try a dt later in its time (the same state), so that its clock rate
          // is set again (a packet with the last stamp leaves it as it is, stopped or not).
          l.stamp_offset_s += dt_s;
          rc = bf::encode_rc(t_s_ + 2.0 * dt_s + l.stamp_offset_s, bf::rc_channels(sticks));
          fdm = bf::encode_fdm(bf::gazebo_fdm(t_s_ + 2.0 * dt_s + l.stamp_offset_s, obs.w_B, obs.specific_force_B,
                                              obs.q_WB, obs.v_W, lla, l.first_lon_lat));
        }
        l.drain(l.motors, &l.stale);
        send();
        l.next_send_wall_s = now + period_s;  // the next step a whole period after this one
        resend_at = now + spec_.resend_ms / 1000.0;
      }
      pollfd p{l.motors, POLLIN, 0};
      if (::poll(&p, 1, 1) <= 0) continue;
      const ssize_t n = ::recv(l.motors, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n < 0) continue;
      motors = l.held = decode(n);
      break;
    }
    l.answered_wall_s = wall_clock_s();
  }
  l.answered = true;
  l.motors_on = std::any_of(motors.begin(), motors.end(), [](float m) { return m > 0.0f; });
  ++counts_.frames;
  out.outputs.resize(std::size(kBetaflightOutputs));
  for (int c = 0; c < 4; ++c) out.outputs[static_cast<std::size_t>(c)] = motors[static_cast<std::size_t>(c)];
  out.outputs[4] = std::round(sticks.throttle_us);
  out.outputs[5] = sticks.arm ? 1.0 : 0.0;
  out.outputs[6] = static_cast<double>(l.resent);
  out.outputs[7] = static_cast<double>(l.stale);
  out.outputs[8] = static_cast<double>(l.late);
  control::rotor_speeds_output(model_, reference, bf::omega_from_motors(map_, motors), reported_, out);
  ++steps_;
  t_s_ = static_cast<double>(steps_) * dt_s;
}

}  // namespace quadcosim::sitl
