#include "sitl/sitl_controller.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <fmt/format.h>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "isolation/child.hpp"
#include "sitl/ardupilot_link.hpp"
#include "sitl/betaflight.hpp"
#include "sitl/betaflight_link.hpp"
#include "sitl/firmware_process.hpp"
#include "sitl/frames.hpp"
#include "sitl/json_codec.hpp"
#include "sitl/mavlink.hpp"
#include "sitl/px4.hpp"
#include "sitl/px4_link.hpp"

namespace quadcosim::sitl {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string>& output_list(const std::string& firmware = "ardupilot") {
  static const std::vector<std::string> names(std::begin(kSitlOutputs), std::end(kSitlOutputs));
  static const std::vector<std::string> px4_names(std::begin(kPx4Outputs), std::end(kPx4Outputs));
  static const std::vector<std::string> bf_names(std::begin(kBetaflightOutputs), std::end(kBetaflightOutputs));
  return firmware == "px4" ? px4_names : firmware == "betaflight" ? bf_names : names;
}

// How long one blocking receive of a servo packet waits before the wait looks at the firmware's
// process, a stop request and the deadline [us].
constexpr int kReceiveSliceUs = 50'000;

// The firmware's MAVLink link is read at each mission decision and otherwise once per this much
// simulated time (ArduPilot writes its serial ports every 10 ms of its clock): reading it every
// frame found it empty almost always, a system call for nothing.
constexpr double kDrainPeriodS = 0.01;

}  // namespace

int copter_mode_number(const std::string& name) {
  static const std::pair<const char*, int> kModes[] = {
      {"stabilize", 0}, {"acro", 1},   {"alt_hold", 2}, {"auto", 3},     {"guided", 4}, {"loiter", 5},
      {"rtl", 6},       {"circle", 7}, {"land", 9},     {"poshold", 16}, {"brake", 17}};
  for (const auto& [n, v] : kModes) {
    if (name == n) return v;
  }
  return -1;
}

SitlController::SitlController(SitlSpec spec, const model::VehicleParams& vehicle)
    : spec_(std::move(spec)),
      model_(vehicle),
      map_(spec_.firmware == "betaflight" ? betaflight::motor_map_for(vehicle)
                                          : motor_map_for(vehicle, spec_.pwm_min_us, spec_.pwm_max_us)),
      reported_(control::ReportedOutputs::find(output_list(spec_.firmware))) {
  if (spec_.firmware != "ardupilot" && spec_.firmware != "px4" && spec_.firmware != "betaflight") {
    throw std::invalid_argument("firmware '" + spec_.firmware + "': expected ardupilot, px4 or betaflight");
  }
  if (betaflight() && !spec_.mission.empty()) {
    throw std::invalid_argument("mission: Betaflight has no MAVLink link; its pilot is the RC (docs/sitl.md)");
  }
  if (spec_.binary.empty()) throw std::invalid_argument("binary: missing; expected the SITL executable's path");
  if (::access(spec_.binary.c_str(), X_OK) != 0 || fs::is_directory(spec_.binary)) {
    throw std::invalid_argument("binary '" + spec_.binary + "' is not an executable file");
  }
  for (const std::string& p : spec_.params) {
    if (!fs::is_regular_file(p)) throw std::invalid_argument("params: no such file '" + p + "'");
  }
  if (px4()) {
    if (spec_.etc_dir.empty()) spec_.etc_dir = (fs::path(spec_.binary).parent_path().parent_path() / "etc").string();
    if (!fs::is_directory(fs::path(spec_.etc_dir) / "init.d-posix")) {
      throw std::invalid_argument("etc_dir '" + spec_.etc_dir +
                                  "' is not PX4's ROMFS folder (no init.d-posix in it); expected the etc folder of "
                                  "the px4_sitl build (build/px4_sitl_default/etc)");
    }
    for (const std::string& p : spec_.params) px4::read_param_file(p);  // throws naming the line
  }
  for (const MissionItem& m : spec_.mission) {
    if (px4()) {
      if (m.kind == MissionItem::Kind::kMode && !px4::mode_numbers(m.mode)) {
        throw std::invalid_argument("mission: mode '" + m.mode + "' is not one of PX4's " + px4::mode_names());
      }
      continue;
    }
    if (m.kind == MissionItem::Kind::kMode && copter_mode_number(m.mode) < 0) {
      throw std::invalid_argument("mission: mode '" + m.mode +
                                  "' is not one of stabilize, acro, alt_hold, auto, guided, loiter, rtl, circle, "
                                  "land, poshold, brake");
    }
  }
  if (!(spec_.timeout_s > 0) || !(spec_.start_timeout_s > 0)) {
    throw std::invalid_argument("timeout_s and start_timeout_s must be positive");
  }
}

SitlController::~SitlController() = default;  // Px4Link: sitl/px4_link.hpp

std::unique_ptr<control::Controller> SitlController::clone() const {
  return std::make_unique<SitlController>(spec_, model_.params());
}

std::shared_ptr<SitlController> SitlController::with_site(const sensors::Geodetic& site,
                                                          std::vector<std::string> added) const {
  SitlSpec spec = spec_;
  spec.site = site;
  spec.added = std::move(added);
  return std::make_shared<SitlController>(spec, model_.params());
}

std::string SitlController::set_parameters(std::span<const control::Setting> settings) {
  if (settings.empty()) return {};
  return settings.front().name +
         ": no such parameter (a SITL controller's parameters are the firmware's own: "
         "its params files)";
}

std::span<const std::string> SitlController::output_names() const { return output_list(spec_.firmware); }

void SitlController::reset() {
  link_.reset();
  px4_.reset();
  bf_.reset();
  counts_ = {};
  steps_ = 0;
  t_s_ = 0.0;
}

std::string SitlController::generated_params() const {
  return fmt::format(
      "# written by quadcosim for this vehicle (docs/sitl.md); the files after it may override the rest\n"
      "FRAME_CLASS 1\nFRAME_TYPE {}\nMOT_PWM_MIN {:g}\nMOT_PWM_MAX {:g}\n",
      map_.frame_type, map_.pwm_min_us, map_.pwm_max_us);
}

std::vector<std::string> SitlController::command_line(int json_port, int mavlink_port, int rc_port,
                                                      const std::string& generated) const {
  std::string defaults = generated;
  for (const std::string& p : spec_.params) defaults += "," + p;
  std::vector<std::string> argv = {spec_.binary,
                                   "--model",
                                   "JSON:127.0.0.1",
                                   "--sim-port-out",
                                   std::to_string(json_port),
                                   "--serial0",
                                   "tcpclient:127.0.0.1:" + std::to_string(mavlink_port),
                                   "--rc-in-port",
                                   std::to_string(rc_port),
                                   "--home",
                                   spec_.home,
                                   "--defaults",
                                   defaults,
                                   "-w"};
  // The other serial ports would listen on fixed TCP ports (5762, ...): two runs at once would clash.
  for (const char* s : {"--serial1", "--serial2", "--serial5", "--serial6", "--serial7", "--serial8"}) {
    argv.emplace_back(s);
    argv.emplace_back("none:0");
  }
  argv.insert(argv.end(), spec_.args.begin(), spec_.args.end());
  return argv;
}

void SitlController::fail(const std::string& what) const {
  std::string msg = fmt::format("controller sitl ({} {}): {}", spec_.firmware, spec_.binary, what);
  const auto keep = [&](auto& link) {  // the folder stays, with the log the message names
    if (!link || !link->process) return;
    msg += fmt::format("; its log {}:{}", link->process->log_path(), link->process->log_tail());
    link->temporary = false;
  };
  keep(link_), keep(px4_), keep(bf_);
  throw control::ControllerFailure(msg);
}

std::unique_ptr<FirmwareProcess> SitlController::launch(const std::vector<std::string>& argv,
                                                        const std::string& work_dir) const {
  {
    std::ofstream f(fs::path(work_dir) / "command_line.txt");
    for (const std::string& a : argv) f << a << '\n';
  }
  try {
    return std::make_unique<FirmwareProcess>(argv, work_dir, (fs::path(work_dir) / "firmware.log").string());
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

std::string SitlController::make_work_dir(bool& temporary) const {
  if (spec_.work_dir.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "quadcosim-sitl-XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) fail(std::string("cannot make a folder to run in: ") + std::strerror(errno));
    temporary = true;
    return tmpl;
  }
  std::error_code ec;
  fs::create_directories(spec_.work_dir, ec);
  return fs::absolute(spec_.work_dir).string();
}

void SitlController::start() {
  link_ = std::make_unique<Link>();
  Link& l = *link_;
  l.work_dir = make_work_dir(l.temporary);
  try {
    l.udp = loopback_socket(SOCK_DGRAM, l.json_port);
    // Blocking receives that give up after a slice, to look at the process, a stop and the deadline.
    const timeval slice{0, kReceiveSliceUs};
    if (::setsockopt(l.udp, SOL_SOCKET, SO_RCVTIMEO, &slice, sizeof(slice)) != 0) {
      throw std::runtime_error(std::string("setsockopt SO_RCVTIMEO: ") + std::strerror(errno));
    }
    l.line.reserve(1024);
    l.listener = loopback_socket(SOCK_STREAM, l.mavlink_port);
    if (::listen(l.listener, 1) != 0) throw std::runtime_error(std::string("listen: ") + std::strerror(errno));
    ::fcntl(l.listener, F_SETFL, O_NONBLOCK);
    // A free UDP port for the firmware's RC input, released for it to bind.
    const int rc = loopback_socket(SOCK_DGRAM, l.rc_port);
    ::close(rc);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  const std::string generated = (fs::path(l.work_dir) / "quadcosim-frame.parm").string();
  {
    std::ofstream f(generated);
    f << generated_params();
    if (!f) fail("cannot write " + generated);
  }
  const std::vector<std::string> argv = command_line(l.json_port, l.mavlink_port, l.rc_port, generated);
  l.process = launch(argv, l.work_dir);
}

void SitlController::service_mavlink() {
  Link& l = *link_;
  // Decisions once the firmware has spoken on its link (its first HEARTBEAT), and then at whole
  // multiples of 0.25 s of simulated time only (step counts, not wall time). The link is read before
  // each: a decision sees all that had come by then, as when it was read every frame.
  const long long decision = static_cast<long long>(std::floor(t_s_ / 0.25 + 1e-9));
  const long long period = static_cast<long long>(std::floor(t_s_ / kDrainPeriodS + 1e-9));
  const bool deciding = l.have_heartbeat && decision >= l.decisions;
  if (deciding || period != l.drained_at || l.tcp < 0) {
    l.drained_at = period;
    l.service_tcp();
    while (auto f = l.parser.next()) {
      take_gcs_frame(l, *f, t_s_, spec_.echo_statustext);
    }
  }
  if (!l.have_heartbeat || l.tcp < 0 || decision < l.decisions) return;
  l.decisions = decision + 1;
  l.shown_armed = l.heartbeat.armed() ? 1.0 : 0.0;
  l.shown_mode = static_cast<double>(l.heartbeat.custom_mode);
  if (decision % 4 == 0) l.send(mavlink::kHeartbeat, mavlink::heartbeat(6, 8, 0, 0, 4));  // a GCS, at 1 Hz
  // Accepted, and for a mode or arming, shown so by the firmware's heartbeat: the next one.
  const MissionItem* due = l.mission.due(t_s_, spec_.mission, [&](const MissionItem& m) {
    return m.kind == MissionItem::Kind::kMode
               ? l.heartbeat.custom_mode == static_cast<std::uint32_t>(copter_mode_number(m.mode))
           : m.kind == MissionItem::Kind::kArm    ? l.heartbeat.armed()
           : m.kind == MissionItem::Kind::kDisarm ? !l.heartbeat.armed()
                                                  : true;
  });
  if (due != nullptr) {
    const MissionItem& m = *due;
    const std::uint8_t ts = l.target_system;
    switch (m.kind) {
      case MissionItem::Kind::kMode:
        l.mission.command = mavlink::kCmdDoSetMode;
        l.send(mavlink::kCommandLong,
               mavlink::command_long(ts, 1, l.mission.command, 0,
                                     {1.0f, static_cast<float>(copter_mode_number(m.mode)), 0, 0, 0, 0, 0}));
        break;
      case MissionItem::Kind::kArm:
      case MissionItem::Kind::kDisarm:
        l.mission.command = mavlink::kCmdComponentArmDisarm;
        l.send(mavlink::kCommandLong,
               mavlink::command_long(ts, 1, l.mission.command, 0,
                                     {m.kind == MissionItem::Kind::kArm ? 1.0f : 0.0f, 0, 0, 0, 0, 0, 0}));
        break;
      case MissionItem::Kind::kTakeoff:
        l.mission.command = mavlink::kCmdNavTakeoff;
        l.send(mavlink::kCommandLong,
               mavlink::command_long(ts, 1, l.mission.command, 0, {0, 0, 0, 0, 0, 0, static_cast<float>(m.takeoff_m)}));
        break;
      case MissionItem::Kind::kGoto: {
        const Eigen::Vector3d p = enu_to_ned(m.p_W);
        l.send(mavlink::kSetPositionTargetLocalNed,
               mavlink::set_position_target_local_ned(static_cast<std::uint32_t>(t_s_ * 1000.0), ts, 1,
                                                      static_cast<float>(p.x()), static_cast<float>(p.y()),
                                                      static_cast<float>(p.z()), false, 0.0f));
        l.mission.command = 0;
        l.mission.result = 0;  // no answer to a position target: done when sent
        break;
      }
    }
  }
}

void SitlController::step(const control::Observation& obs, const control::Reference& reference, double dt_s,
                          control::ControllerOutput& out) {
  if (px4() || betaflight()) {
    px4() ? step_px4(obs, reference, dt_s, out) : step_betaflight(obs, reference, dt_s, out);
    return;
  }
  if (!link_) start();
  Link& l = *link_;
  const bool first = !l.have_pending;
  const double limit_s = first ? spec_.start_timeout_s : spec_.timeout_s;

  // The state at t_n answers the pending packet. Commands go out first: the firmware waits for the
  // answer, so they are in its link's buffer before it runs the frame (the same frame on every run).
  if (l.have_pending) {
    service_mavlink();
    FdmState s;
    s.timestamp_s = fdm_timestamp_s(t_s_);  // its clock: exactly one period a frame
    s.gyro_FRD = flu_to_frd(obs.w_B);
    s.accel_FRD = flu_to_frd(obs.specific_force_B);
    s.p_NED = enu_to_ned(obs.p_W);
    s.v_NED = enu_to_ned(obs.v_W);
    s.q_NED_FRD = attitude_ned_frd(obs.q_WB);
    std::string& line = l.line;
    encode_fdm_json(s, line);
    if (::sendto(l.udp, line.data(), line.size(), 0, reinterpret_cast<const sockaddr*>(&l.peer), sizeof(l.peer)) !=
        static_cast<ssize_t>(line.size())) {
      fail(fmt::format("step {} (t = {:.4f} s): cannot send the state: {}", steps_, t_s_, std::strerror(errno)));
    }
  }

  // Its next servo packet: the rotor speeds over [t_n, t_n+1). One blocking receive a frame when the
  // packet comes (the socket's timeout is kReceiveSlice); the checks that cost system calls (the
  // process's end, its MAVLink link) only after a slice without one, the others on every pass.
  const double deadline = wall_clock_s() + limit_s;
  bool quiet = first;  // before the first packet, every pass looks at everything
  for (;;) {
    if (quiet) {
      l.service_tcp();
      if (auto end = l.process->ended()) {
        fail(fmt::format("step {} (t = {:.4f} s): the firmware {}", steps_, t_s_, *end));
      }
    }
    if (first) {
      // A firmware that panics while starting (ArduPilot's SITL then spins instead of exiting) says so
      // in its log: fail at once with its words rather than after start_timeout_s.
      const std::string tail = l.process->log_tail(4);
      if (const std::size_t at = tail.find("PANIC"); at != std::string::npos) {
        fail(
            fmt::format("step 0: the firmware panicked while starting: {}", tail.substr(at, tail.find('\n', at) - at)));
      }
    }
    if (isolation::stop_requested()) {  // the firmware's folder goes as after a run that succeeded
      throw control::ControllerFailure(
          fmt::format("controller sitl ({} {}): step {} (t = {:.4f} s): interrupted (Ctrl-C or SIGTERM)",
                      spec_.firmware, spec_.binary, steps_, t_s_));
    }
    if (deadline - wall_clock_s() <= 0) {
      fail(fmt::format("step {} (t = {:.4f} s): no servo packet for {:g} s (frame {}{})", steps_, t_s_, limit_s,
                       l.have_pending ? std::to_string(l.pending + 1) : std::string("0"),
                       first ? ": it never spoke on its JSON port" : ": it went silent"));
    }
    sockaddr_in from{};
    socklen_t from_len = sizeof(from);
    const ssize_t n =
        ::recvfrom(l.udp, l.datagram.data(), l.datagram.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    quiet = n < 0;  // the slice ran out (or a signal came): look at the rest before waiting again
    if (n < 0) continue;
    std::span<const std::uint8_t> bytes(l.datagram.data(), static_cast<std::size_t>(n));
    if (l.have_peer && (from.sin_port != l.peer.sin_port || from.sin_addr.s_addr != l.peer.sin_addr.s_addr)) {
      ++counts_.foreign;
      continue;
    }
    ServoPacket& packet = l.packet;
    try {
      decode_servo_packet(bytes, packet);
    } catch (const DecodeError& e) {
      fail(fmt::format("step {} (t = {:.4f} s): {}", steps_, t_s_, e.what()));
    }
    if (!l.have_peer) {
      l.peer = from;
      l.have_peer = true;
    }
    if (first) {
      // Its first frame, perhaps sent more than once while it waited: take the newest.
      for (;;) {
        pollfd q{l.udp, POLLIN, 0};
        if (::poll(&q, 1, 0) <= 0) break;
        const ssize_t m = ::recv(l.udp, l.datagram.data(), l.datagram.size(), MSG_DONTWAIT);
        if (m <= 0) break;
        try {
          const ServoPacket again =
              decode_servo_packet(std::span<const std::uint8_t>(l.datagram.data(), std::size_t(m)));
          if (again.frame_count == packet.frame_count) {
            ++counts_.repeated;
          } else {
            packet = again;
          }
        } catch (const DecodeError& e) {
          fail(fmt::format("step {} (t = {:.4f} s): {}", steps_, t_s_, e.what()));
        }
      }
    } else {
      if (packet.frame_count == l.pending) {
        ++counts_.repeated;  // sent again while it waited for our answer: answered already
        continue;
      }
      if (packet.frame_count < l.pending) {
        fail(fmt::format("step {} (t = {:.4f} s): frame count went back from {} to {}: the firmware restarted", steps_,
                         t_s_, l.pending, packet.frame_count));
      }
      counts_.skipped += packet.frame_count - l.pending - 1;
    }
    l.pending = packet.frame_count;
    l.have_pending = true;
    ++counts_.frames;
    const Eigen::Vector4d omega = map_.omega_from_pwm(packet.pwm_us);
    out.outputs.resize(output_list().size());
    out.outputs[0] = packet.frame_count;
    for (int c = 0; c < 4; ++c) out.outputs[1 + c] = c < static_cast<int>(packet.pwm_us.size()) ? packet.pwm_us[c] : 0;
    out.outputs[5] = static_cast<double>(counts_.repeated);
    out.outputs[6] = static_cast<double>(counts_.skipped);
    out.outputs[7] = l.shown_armed;
    out.outputs[8] = l.shown_mode;
    out.outputs[9] = static_cast<double>(l.mission.item);
    control::rotor_speeds_output(model_, reference, omega, reported_, out);
    break;
  }
  ++steps_;
  // t_{n+1} as a product, not a running sum: the same times on every run.
  t_s_ = static_cast<double>(steps_) * dt_s;
}

}  // namespace quadcosim::sitl
