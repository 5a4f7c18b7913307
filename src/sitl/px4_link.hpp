// The state of a running PX4 SITL link (sitl_px4.cpp): its process, the simulator TCP connection, the
// GCS UDP socket, the parsers and the mission's progress. Private to src/sitl.
#pragma once

#include <netinet/in.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "sitl/firmware_process.hpp"
#include "sitl/mavlink.hpp"
#include "sitl/sitl_controller.hpp"

namespace quadcosim::sitl {

/// A frame from the firmware's GCS link, taken into a link (ArduPilot's or PX4's: each has heartbeat,
/// have_heartbeat, target_system, mission, statustext and work_dir): its heartbeat (another GCS's
/// ignored), the COMMAND_ACK of the mission's item, a STATUSTEXT into statustext.log (and on stderr
/// with `echo`) at simulated time t_s.
template <class Link>
void take_gcs_frame(Link& l, const mavlink::Frame& f, double t_s, bool echo) {
  if (f.msgid == mavlink::kHeartbeat) {
    const mavlink::Heartbeat h = mavlink::read_heartbeat(f);
    if (h.type == 6) return;  // another GCS's
    l.heartbeat = h;
    l.have_heartbeat = true;
    l.target_system = f.sysid;
  } else if (f.msgid == mavlink::kCommandAck) {
    const mavlink::CommandAck a = mavlink::read_command_ack(f);
    l.mission.on_ack(a.command, a.result);
  } else if (f.msgid == mavlink::kStatustext) {
    const auto [severity, text] = mavlink::read_statustext(f);
    if (!l.statustext.is_open()) l.statustext.open(std::filesystem::path(l.work_dir) / "statustext.log");
    l.statustext << fmt::format("{:.3f} {} {}\n", t_s, severity, text) << std::flush;
    if (echo) std::fprintf(stderr, "sitl: t = %.3f s: %s\n", t_s, text.c_str());
  }
}

struct SitlController::Px4Link {
  std::string work_dir;
  bool temporary = false;
  int instance = 0;
  int listener = -1;  ///< TCP 127.0.0.1:4560 + instance: PX4's simulator link connects here
  int sim = -1;       ///< that connection
  int gcs = -1;       ///< UDP socket of quadcosim's GCS link (to PX4's 18570 + instance)
  sockaddr_in gcs_peer{};
  std::unique_ptr<FirmwareProcess> process;
  mavlink::Parser sim_parser, gcs_parser;
  std::uint8_t seq = 0, gcs_seq = 0;
  bool answered = false;       ///< a HIL_ACTUATOR_CONTROLS has come: lockstep from then on
  bool group_settled = false;  ///< its start-up script is done: only PX4's own threads are watched
  std::int64_t mag_stamp = -1, baro_stamp = -1, gnss_stamp = -1;  ///< the samples sent last
  bool armed = false;                                             ///< its last HIL_ACTUATOR_CONTROLS' mode
  std::uint8_t target_system = 1;
  mavlink::Heartbeat heartbeat;
  bool have_heartbeat = false;
  double shown_mode = -1.0;  ///< its HEARTBEAT's custom_mode at the last mission decision (out.mode)
  // The mission (as SitlController::Link's): item in progress, when sent, its answer.
  MissionProgress mission;
  long long decisions = 0;
  long long heartbeats = 0;
  std::ofstream statustext;

  long long unsettled = 0;  ///< steps sent before its threads slept (a note on stderr at the end)

  ~Px4Link() {
    if (unsettled > 0) {
      std::fprintf(stderr,
                   "sitl: PX4 was sent %lld step(s) before all its threads had gone to sleep (settle_ms): "
                   "this run may not repeat bit for bit (a busy machine; a larger settle_ms)\n",
                   unsettled);
    }
    process.reset();  // ends the firmware first
    for (int fd : {listener, sim, gcs}) {
      if (fd >= 0) ::close(fd);
    }
    if (temporary && !work_dir.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(work_dir, ec);
    }
  }
};

}  // namespace quadcosim::sitl
