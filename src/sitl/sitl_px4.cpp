// PX4's SITL build as the controller (docs/sitl.md, "PX4"): quadcosim is the simulator its
// simulator_mavlink module connects to (TCP 127.0.0.1:4560 + instance), in lockstep: each step sends
// HIL_GPS (when a new GNSS sample came) and HIL_SENSOR stamped with PX4's clock, and waits for the one
// HIL_ACTUATOR_CONTROLS PX4 answers with that stamp once all its lockstep work for that time is done.
// PX4's clock is quadcosim's plus one control period (it needs a first time above zero).
//
// Start-up: PX4's start-up script runs while its clock advances, and PX4 answers only once its
// outputs run (about 30 ms of its time here). Until its first answer a step waits for an answer or for
// every process of its group to sleep (nothing more can come for this time), then flies the rotors
// stopped. Before each step quadcosim also waits (up to settle_ms; up to 2 s while the start-up
// script's commands run) for PX4's threads that are not lockstep components (commander, navigator,
// the MAVLink links, the script) to go to sleep: what they do for a time is then done before the
// next time starts, whatever the machine's load. A step sent without that (the wait ran out) is
// counted, and a note at the end says the run may not repeat. PX4 runs on one CPU (spec.cpu): its
// real-time threads then take turns in priority order, the same on every run.
//
// The mission goes over PX4's GCS link (UDP 18570 + instance) as COMMAND_LONG / COMMAND_INT.
#include <arpa/inet.h>
#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "isolation/child.hpp"
#include "sensors/geodesy.hpp"
#include "sitl/px4.hpp"
#include "sitl/px4_link.hpp"

namespace quadcosim::sitl {

namespace fs = std::filesystem;

namespace {

bool udp_port_free(int port) {
  const int fd = bind_loopback(SOCK_DGRAM, port);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

std::vector<std::string> SitlController::px4_command_line(int instance, const std::string& work_dir) const {
  std::vector<std::string> argv = {spec_.binary, "-i", std::to_string(instance), "-d", "-w", work_dir};
  argv.insert(argv.end(), spec_.args.begin(), spec_.args.end());
  argv.push_back(spec_.etc_dir);
  return argv;
}

std::vector<std::string> SitlController::px4_environment() const {
  std::vector<std::pair<std::string, std::string>> params = px4::vehicle_params(model_.params(), map_);
  for (const std::string& file : spec_.params) {
    for (auto& [name, value] : px4::read_param_file(file)) {
      bool replaced = false;
      for (auto& p : params) {
        if (p.first == name) {
          p.second = value;
          replaced = true;
        }
      }
      if (!replaced) params.emplace_back(name, value);
    }
  }
  std::vector<std::string> env = {"PX4_SYS_AUTOSTART=" + std::to_string(spec_.airframe)};
  for (const auto& [name, value] : params) env.push_back("PX4_PARAM_" + name + "=" + value);
  return env;
}

void SitlController::start_px4() {
  if (!spec_.added.empty()) {
    std::string list;
    for (const std::string& a : spec_.added) list += (list.empty() ? "" : ", ") + a;
    std::fprintf(stderr, "sitl: the scenario lacks what PX4 flies on; added with their defaults (docs/sitl.md): %s\n",
                 list.c_str());
  }
  px4_ = std::make_unique<Px4Link>();
  Px4Link& l = *px4_;
  l.work_dir = make_work_dir(l.temporary);
  // An instance whose ports are all free: the simulator port (kept, listening, for the whole run, so
  // no other run takes it) and the UDP ports PX4's MAVLink links bind.
  const int first = spec_.instance >= 0 ? spec_.instance : 0;
  const int last = spec_.instance >= 0 ? spec_.instance : 99;
  for (int i = first; i <= last && l.listener < 0; ++i) {
    const int fd = bind_loopback(SOCK_STREAM, 4560 + i);
    if (fd < 0) continue;
    if (udp_port_free(18570 + i) && udp_port_free(14580 + i) && udp_port_free(14280 + i) && udp_port_free(13030 + i) &&
        ::listen(fd, 1) == 0) {
      l.listener = fd;
      l.instance = i;
    } else {
      ::close(fd);
    }
  }
  if (l.listener < 0) {
    fail(spec_.instance >= 0 ? fmt::format("instance {}: its ports (TCP {}, UDP {}, {}, {}, {}) are in use", first,
                                           4560 + first, 18570 + first, 14580 + first, 14280 + first, 13030 + first)
                             : std::string("no free PX4 instance 0..99 (ports TCP 4560 + i, UDP 18570 + i, 14580 + "
                                           "i, 14280 + i, 13030 + i all in use)"));
  }
  ::fcntl(l.listener, F_SETFL, O_NONBLOCK);
  l.gcs = bind_loopback(SOCK_DGRAM, 0);
  if (l.gcs < 0) fail(std::string("cannot open a UDP socket: ") + std::strerror(errno));
  l.gcs_peer.sin_family = AF_INET;
  l.gcs_peer.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  l.gcs_peer.sin_port = htons(static_cast<std::uint16_t>(18570 + l.instance));
  const std::vector<std::string> argv = px4_command_line(l.instance, l.work_dir);
  const std::vector<std::string> env = px4_environment();
  {
    std::ofstream f(fs::path(l.work_dir) / "command_line.txt");
    for (const std::string& e : env) f << e << '\n';
    for (const std::string& a : argv) f << a << '\n';
  }
  int cpu = spec_.cpu;
  if (cpu == -2) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    cpu = -1;
    if (::sched_getaffinity(0, sizeof(allowed), &allowed) == 0) {
      for (int c = 0; c < CPU_SETSIZE; ++c) {
        if (CPU_ISSET(c, &allowed)) cpu = c;
      }
    }
  }
  try {
    l.process =
        std::make_unique<FirmwareProcess>(argv, l.work_dir, (fs::path(l.work_dir) / "firmware.log").string(), env, cpu);
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void SitlController::service_px4_gcs() {
  Px4Link& l = *px4_;
  std::array<std::uint8_t, 4096> buf{};
  for (;;) {
    const ssize_t n = ::recv(l.gcs, buf.data(), buf.size(), MSG_DONTWAIT);
    if (n <= 0) break;
    l.gcs_parser.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
  }
  while (auto f = l.gcs_parser.next()) {
    take_gcs_frame(l, *f, t_s_, spec_.echo_statustext);
  }
  auto send = [&](std::uint32_t msgid, const std::vector<std::uint8_t>& payload) {
    const std::vector<std::uint8_t> frame = mavlink::encode(l.gcs_seq++, 255, 190, msgid, payload);
    ::sendto(l.gcs, frame.data(), frame.size(), 0, reinterpret_cast<const sockaddr*>(&l.gcs_peer), sizeof(l.gcs_peer));
  };
  // A GCS heartbeat each second of simulated time from the start: PX4 answers the address it hears.
  if (static_cast<long long>(std::floor(t_s_ + 1e-9)) >= l.heartbeats) {
    ++l.heartbeats;
    send(mavlink::kHeartbeat, mavlink::heartbeat(6, 8, 0, 0, 4));
  }
  // Mission decisions at whole multiples of 0.25 s of simulated time, once PX4's GCS link has spoken.
  const long long decision = static_cast<long long>(std::floor(t_s_ / 0.25 + 1e-9));
  if (decision < l.decisions) return;
  l.decisions = decision + 1;
  if (!l.have_heartbeat) return;
  l.shown_mode = static_cast<double>(l.heartbeat.custom_mode);  // out.mode: as seen at the decisions
  // Accepted (PX4 accepts a mode only once it switched), and an arming shown in its outputs' mode.
  const MissionItem* due = l.mission.due(t_s_, spec_.mission, [&](const MissionItem& m) {
    return m.kind == MissionItem::Kind::kArm ? l.armed : m.kind == MissionItem::Kind::kDisarm ? !l.armed : true;
  });
  if (due != nullptr) {
    const MissionItem& m = *due;
    const std::uint8_t ts = l.target_system;
    switch (m.kind) {
      case MissionItem::Kind::kMode: {
        const px4::ModeNumbers n = *px4::mode_numbers(m.mode);
        l.mission.command = mavlink::kCmdDoSetMode;
        send(mavlink::kCommandLong,
             mavlink::command_long(ts, 1, l.mission.command, 0,
                                   {1.0f, static_cast<float>(n.main), static_cast<float>(n.sub), 0, 0, 0, 0}));
        break;
      }
      case MissionItem::Kind::kArm:
      case MissionItem::Kind::kDisarm:
        l.mission.command = mavlink::kCmdComponentArmDisarm;
        send(mavlink::kCommandLong,
             mavlink::command_long(ts, 1, l.mission.command, 0,
                                   {m.kind == MissionItem::Kind::kArm ? 1.0f : 0.0f, 0, 0, 0, 0, 0, 0}));
        break;
      case MissionItem::Kind::kTakeoff:
        // param7: the altitude above mean sea level; the site's altitude is home's (the GNSS's origin).
        l.mission.command = mavlink::kCmdNavTakeoff;
        send(mavlink::kCommandLong,
             mavlink::command_long(ts, 1, l.mission.command, 0,
                                   {0, 0, 0, kNaN, kNaN, kNaN, static_cast<float>(spec_.site.height_m + m.takeoff_m)}));
        break;
      case MissionItem::Kind::kGoto: {
        // DO_REPOSITION as COMMAND_INT (latitude and longitude in degE7: a float would round them to
        // 0.5 m), flag 1: switch to the hold mode that flies there; default speed; heading kept.
        const sensors::Geodetic g = sensors::LocalTangentPlane(spec_.site).to_geodetic(m.p_W);
        const auto e7 = [](double rad) {
          return static_cast<std::int32_t>(std::llround(rad * 180.0 / std::numbers::pi * 1e7));
        };
        l.mission.command = mavlink::kCmdDoReposition;
        send(mavlink::kCommandInt,
             mavlink::command_int(ts, 1, l.mission.command, 0, {-1.0f, 1.0f, 0.0f, kNaN}, e7(g.latitude_rad),
                                  e7(g.longitude_rad), static_cast<float>(spec_.site.height_m + m.p_W.z())));
        break;
      }
    }
  }
}

void SitlController::step_px4(const control::Observation& obs, const control::Reference& reference, double dt_s,
                              control::ControllerOutput& out) {
  if (!px4_) start_px4();
  Px4Link& l = *px4_;
  auto check_alive = [&] {
    if (auto end = l.process->ended()) fail(fmt::format("step {} (t = {:.4f} s): the firmware {}", steps_, t_s_, *end));
    if (isolation::stop_requested()) {
      throw control::ControllerFailure(
          fmt::format("controller sitl ({} {}): step {} (t = {:.4f} s): interrupted (Ctrl-C or SIGTERM)",
                      spec_.firmware, spec_.binary, steps_, t_s_));
    }
  };
  // Its simulator link connects first.
  if (l.sim < 0) {
    const double deadline = wall_clock_s() + spec_.start_timeout_s;
    while (l.sim < 0) {
      check_alive();
      const int fd = ::accept4(l.listener, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd >= 0) {
        l.sim = fd;
        break;
      }
      if (wall_clock_s() > deadline) {
        fail(fmt::format("step 0: it did not connect to the simulator port {} within {:g} s", 4560 + l.instance,
                         spec_.start_timeout_s));
      }
      pollfd p{l.listener, POLLIN, 0};
      ::poll(&p, 1, 20);
    }
  }
  // Its threads asleep: what they do for the last time is done before the next starts.
  // Idle: asleep at every look over at least min_s (min_looks looks at least); false after max_s.
  auto wait_idle = [&](double min_s, double max_s, int min_looks) {
    const double t0 = wall_clock_s();
    double idle_since = -1.0;
    int looks = 0;
    for (;;) {
      int processes = 0;
      const bool idle = l.process->idle(!l.group_settled, &processes);
      const double now = wall_clock_s();
      if (idle) {
        if (idle_since < 0) idle_since = now;
        if (++looks >= min_looks && now - idle_since >= min_s) {
          if (l.answered && processes <= 1) l.group_settled = true;  // the start-up script is done
          return true;
        }
      } else {
        idle_since = -1.0;
        looks = 0;
      }
      if (now - t0 > max_s) return false;
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
  };
  service_px4_gcs();
  // While its start-up script runs (commands that start, talk to PX4 and end), time waits for it (up to
  // 2 s a step): the script's commands land at the same times on every run.
  const double settle_s = l.group_settled ? spec_.settle_ms / 1000.0 : std::max(spec_.settle_ms / 1000.0, 2.0);
  if (l.answered && spec_.settle_ms > 0 && !wait_idle(0.0, settle_s, 2) && l.group_settled) {
    ++counts_.unsettled;  // counted once its start-up script is done (its commands run longer, harmlessly)
    l.unsettled = counts_.unsettled;
  }

  const std::uint64_t t_us = static_cast<std::uint64_t>(std::llround(static_cast<double>(steps_ + 1) * dt_s * 1e6));
  std::vector<std::uint8_t> bytes;
  auto add = [&](std::uint32_t msgid, const std::vector<std::uint8_t>& payload) {
    const std::vector<std::uint8_t> f = mavlink::encode(l.seq++, 1, 51, msgid, payload);
    bytes.insert(bytes.end(), f.begin(), f.end());
  };
  if (const auto* g = obs.sensors.get<sensors::GnssKind>(); g && g->stamp_ns >= 0 && g->stamp_ns != l.gnss_stamp) {
    l.gnss_stamp = g->stamp_ns;
    add(mavlink::kHilGps, mavlink::hil_gps(px4::hil_gps(g->sample, px4::utc_usec(t_s_))));
  }
  const auto* mag = obs.sensors.get<sensors::MagnetometerKind>();
  const auto* baro = obs.sensors.get<sensors::BarometerKind>();
  const bool new_mag = mag && mag->stamp_ns >= 0 && mag->stamp_ns != l.mag_stamp;
  const bool new_baro = baro && baro->stamp_ns >= 0 && baro->stamp_ns != l.baro_stamp;
  if (new_mag) l.mag_stamp = mag->stamp_ns;
  if (new_baro) l.baro_stamp = baro->stamp_ns;
  add(mavlink::kHilSensor, mavlink::hil_sensor(px4::hil_sensor(obs, t_us, new_mag, new_baro)));
  for (std::size_t at = 0; at < bytes.size();) {
    const ssize_t n = ::send(l.sim, bytes.data() + at, bytes.size() - at, MSG_NOSIGNAL);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd p{l.sim, POLLOUT, 0};
      ::poll(&p, 1, 10);
      check_alive();
      continue;
    }
    if (n <= 0) {
      check_alive();
      fail(fmt::format("step {} (t = {:.4f} s): cannot send HIL_SENSOR: {}", steps_, t_s_,
                       n == 0 ? "connection closed" : std::strerror(errno)));
    }
    at += static_cast<std::size_t>(n);
  }

  // Its answer for this time.
  std::optional<mavlink::HilActuatorControls> answer;
  const double limit_s = l.answered ? spec_.timeout_s : spec_.start_timeout_s;
  const double deadline = wall_clock_s() + limit_s;
  std::array<std::uint8_t, 4096> buf{};
  bool quiet = false;
  while (!answer) {
    check_alive();
    for (;;) {
      const ssize_t n = ::recv(l.sim, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n == 0) {
        // A firmware that exits closes the link first: say how it ended when it does within a second.
        for (int i = 0; i < 100 && !l.process->ended(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        check_alive();
        fail(fmt::format("step {} (t = {:.4f} s): it closed the simulator link", steps_, t_s_));
      }
      if (n < 0) break;
      l.sim_parser.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    }
    while (auto f = l.sim_parser.next()) {
      if (f->msgid != mavlink::kHilActuatorControls) continue;  // its HEARTBEAT, its request for ground truth
      const mavlink::HilActuatorControls c = mavlink::read_hil_actuator_controls(*f);
      if ((c.flags & 1) == 0) {
        fail(
            fmt::format("step {} (t = {:.4f} s): HIL_ACTUATOR_CONTROLS without the lockstep flag: PX4 was built "
                        "without its lockstep scheduler, which quadcosim needs",
                        steps_, t_s_));
      }
      if (c.time_usec < t_us) {
        ++counts_.late;  // an answer to an earlier time, come after that step went on without it
        continue;
      }
      if (c.time_usec > t_us) {
        fail(fmt::format("step {} (t = {:.4f} s): HIL_ACTUATOR_CONTROLS for time {} us, ahead of the {} us sent",
                         steps_, t_s_, c.time_usec, t_us));
      }
      answer = c;
    }
    if (l.sim_parser.bad_crc() > 0) {
      fail(fmt::format("step {} (t = {:.4f} s): a frame with a wrong checksum on the simulator link", steps_, t_s_));
    }
    if (answer || quiet) break;
    if (!l.answered) {
      // Starting: nothing more comes for this time once everything of its group sleeps (read once more
      // after that: the answer may have come while it went to sleep).
      quiet = wait_idle(0.02, 0.05, 2);
    } else {
      pollfd p{l.sim, POLLIN, 0};
      ::poll(&p, 1, 20);
    }
    if (wall_clock_s() > deadline) {
      fail(fmt::format("step {} (t = {:.4f} s): no HIL_ACTUATOR_CONTROLS for {:g} s ({})", steps_, t_s_, limit_s,
                       l.answered ? "it went silent" : "it never answered a HIL_SENSOR"));
    }
  }

  Eigen::Vector4d omega = Eigen::Vector4d::Zero();
  std::array<float, 16> controls{};
  if (answer) {
    l.answered = true;
    l.armed = (answer->mode & 0x80) != 0;
    controls = answer->controls;
    omega = px4::omega_from_controls(map_, controls);
    ++counts_.frames;
  }
  out.outputs.resize(std::size(kPx4Outputs));
  out.outputs[0] = static_cast<double>(counts_.frames);
  for (int c = 0; c < 4; ++c) out.outputs[1 + c] = controls[static_cast<std::size_t>(c)];
  out.outputs[5] = l.armed ? 1.0 : 0.0;
  out.outputs[6] = l.shown_mode;
  out.outputs[7] = static_cast<double>(l.mission.item);
  control::rotor_speeds_output(model_, reference, omega, reported_, out);
  ++steps_;
  t_s_ = static_cast<double>(steps_) * dt_s;
}

}  // namespace quadcosim::sitl
