// The state of a running Betaflight SITL link (sitl_betaflight.cpp): its process, its fixed UDP ports, the
// altitude loop's integral and the counts. Private to src/sitl.
#pragma once

#include <sys/socket.h>
#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <memory>
#include <string>

#include "sitl/firmware_process.hpp"
#include "sitl/sitl_controller.hpp"

namespace quadcosim::sitl {

struct SitlController::BfLink {
  std::string work_dir;
  bool temporary = false;
  int motors = -1;  ///< UDP 9002: its motor packets
  int raw = -1;     ///< UDP 9001: its raw PWM packets, read and dropped (and the port held)
  int out = -1;     ///< sends to 9003 and 9004
  std::unique_ptr<FirmwareProcess> process;
  bool answered = false;
  Eigen::Vector2d first_lon_lat = Eigen::Vector2d::Zero();
  double integral_m_s = 0.0;
  double armed_at_s = -1.0;  ///< [s] when its motors first turned (it arms them at idle); -1: not yet
  bool motors_on = false;    ///< its last motor packet had a motor above 0
  double hover_u = 0.0;      ///< the motor value of the hover speed
  long long resent = 0, stale = 0, late = 0;
  double stamp_offset_s = 0.0;    ///< [s] added to its stamps: the tries at step 0 before its first answer
  double next_send_wall_s = 0.0;  ///< [s, steady clock] when the next step's packets go (pacing)
  double answered_wall_s = 0.0;   ///< [s, steady clock] when its last motor packet came
  std::array<float, 4> held{};    ///< its newest motor packet: what a step without its own answer flies

  ~BfLink() {
    process.reset();
    for (int fd : {motors, raw, out}) {
      if (fd >= 0) ::close(fd);
    }
    if (temporary && !work_dir.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(work_dir, ec);
    }
  }
  void drain(int fd, long long* count) {
    std::array<std::uint8_t, 256> buf{};
    while (::recv(fd, buf.data(), buf.size(), MSG_DONTWAIT) > 0) {
      if (count) ++*count;
    }
  }
};

}  // namespace quadcosim::sitl
