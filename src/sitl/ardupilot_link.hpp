// The state of a running ArduPilot SITL link (sitl_controller.cpp): its process, the JSON physics
// socket, the GCS TCP connection and its parser, the mission's progress, and the buffers each frame
// reuses. Private to src/sitl.
#pragma once

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include "sitl/firmware_process.hpp"
#include "sitl/json_codec.hpp"
#include "sitl/mavlink.hpp"
#include "sitl/sitl_controller.hpp"

namespace quadcosim::sitl {

struct SitlController::Link {
  std::string work_dir;
  bool temporary = false;
  int udp = -1, listener = -1, tcp = -1;
  int json_port = 0, mavlink_port = 0, rc_port = 0;
  std::unique_ptr<FirmwareProcess> process;
  bool have_peer = false;
  sockaddr_in peer{};
  std::uint32_t pending = 0;  ///< frame count of the packet the next reply answers
  bool have_pending = false;
  mavlink::Parser parser;  ///< the firmware's MAVLink stream
  std::uint8_t seq = 0;
  std::uint8_t target_system = 1;  ///< the firmware's system id (from its heartbeat)
  mavlink::Heartbeat heartbeat;    ///< its newest
  bool have_heartbeat = false;
  // The mission: the item in progress, when it was last sent (simulated time), the answers to it.
  MissionProgress mission;
  long long decisions = 0;
  // Its heartbeat's armed bit and custom_mode as seen at the last 0.25 s decision (out.armed,
  // out.mode): a heartbeat arrives over TCP at a wall time, so the newest one at a given frame can
  // differ between two runs; at the decisions, which the mission already waits on, it does not.
  double shown_armed = 0.0, shown_mode = -1.0;
  std::ofstream statustext;
  long long drained_at = -1;  ///< the 10 ms period of simulated time its MAVLink link was last read in
  // Reused every frame (no allocation in the exchange): the datagram, its decoding, the reply line.
  std::array<std::uint8_t, 512> datagram{};
  ServoPacket packet;
  std::string line;

  void send(std::uint32_t msgid, const std::vector<std::uint8_t>& payload) {
    if (tcp < 0) return;
    const std::vector<std::uint8_t> frame = mavlink::encode(seq++, 255, 190, msgid, payload);
    std::size_t at = 0;
    while (at < frame.size()) {
      const ssize_t n = ::send(tcp, frame.data() + at, frame.size() - at, MSG_NOSIGNAL);
      if (n <= 0) {
        if (errno == EAGAIN || errno == EINTR) continue;
        return;
      }
      at += static_cast<std::size_t>(n);
    }
  }

  ~Link() {
    process.reset();  // ends the firmware first
    for (int fd : {udp, listener, tcp}) {
      if (fd >= 0) ::close(fd);
    }
    if (temporary && !work_dir.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(work_dir, ec);
    }
  }

  // Accepts the firmware's MAVLink connection and drains what it sent (kept for the MAVLink layer).
  void service_tcp() {
    if (tcp < 0 && listener >= 0) {
      const int fd = ::accept4(listener, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd >= 0) tcp = fd;
    }
    if (tcp < 0) return;
    std::array<std::uint8_t, 4096> buf{};
    for (;;) {
      const ssize_t n = ::recv(tcp, buf.data(), buf.size(), MSG_DONTWAIT);
      if (n <= 0) break;
      parser.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    }
  }
};

}  // namespace quadcosim::sitl
