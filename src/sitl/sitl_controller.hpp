// A flight stack's SITL build as a quadcosim controller (docs/sitl.md): each control step hands the
// firmware the vehicle's state as its sensors observed it (realism's noisy IMU included) and returns
// the rotor speeds its next servo packet commands, in lockstep over ArduPilot's JSON physics protocol;
// or, for PX4 (firmware px4, sitl_px4.cpp), hands it HIL_SENSOR / HIL_GPS messages made of the IMU,
// magnetometer, barometer and GNSS samples and flies its HIL_ACTUATOR_CONTROLS answer (px4.hpp).
//
// Step n (period dt): the state at t_n = n dt goes to the firmware as the answer to its pending servo
// packet (frame c); the firmware runs its loop up to t_n and sends frame c + 1, whose PWM widths
// (motor_map.hpp) are the rotor speeds over [t_n, t_n+1). A frame count seen again is dropped and
// counted (never answered twice, never integrated twice); a frame count that jumps ahead is counted
// as skipped; one that goes back means the firmware restarted, and fails the step. The firmware
// process starts at the first step (ports chosen free then: its JSON port, a TCP port it connects to
// as its SERIAL0 / MAVLink link, its RC input port), runs in a folder of its own, and ends with the
// controller on every path (firmware_process.hpp). A firmware that exits, sends something that is not
// a servo packet, or stays silent past timeout_s fails the step (control::ControllerFailure naming
// the firmware, the step, its time and the end of the firmware's log).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/controller.hpp"
#include "model/quadrotor.hpp"
#include "sensors/geodesy.hpp"
#include "sitl/motor_map.hpp"

namespace quadcosim::sitl {

namespace betaflight {
struct RcSticks;
}  // namespace betaflight
class FirmwareProcess;

/// One command of a mission flown over the firmware's MAVLink link (docs/sitl.md), sent once the
/// simulated time reaches at_s and the previous one was accepted (COMMAND_ACK result 0); a refused or
/// unanswered command is sent again every second. The mission is looked at every 0.25 s of simulated
/// time only, so that when an answer arrives within that period never changes the flight.
struct MissionItem {
  enum class Kind { kMode, kArm, kDisarm, kTakeoff, kGoto };
  double at_s = 0.0;
  Kind kind = Kind::kMode;
  std::string mode;  ///< kMode: ArduCopter's stabilize, alt_hold, guided, ...; PX4's posctl, takeoff, loiter, land, ...
  double takeoff_m = 0.0;                         ///< kTakeoff: height above home [m]
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< kGoto: position in quadcosim's world (ENU) [m]
};

/// Where a mission stands (the same rules for every firmware): the item being asked, when it was sent,
/// the MAVLink command whose COMMAND_ACK answers it, and that answer.
struct MissionProgress {
  std::size_t item = 0;  ///< the next item not yet done
  double sent_s = -1.0;  ///< when it was last sent [s, simulated]; -1: not yet
  std::uint16_t command = 0;
  std::optional<std::uint8_t> result;

  /// A COMMAND_ACK: the answer to the item asked when it names its command.
  void on_ack(std::uint16_t acked, std::uint8_t r) {
    if (acked == command && sent_s >= 0) result = r;
  }
  /// At a decision at t_s: the item to send now (marked sent, its answer cleared), or null. An item sent
  /// is done once accepted (result 0) and `shown(item)` (the firmware's state says so: a mode, arming);
  /// unanswered or refused, it is sent again a second after; the next waits for its at_s.
  template <class Shown>
  const MissionItem* due(double t_s, const std::vector<MissionItem>& mission, Shown&& shown) {
    while (item < mission.size()) {
      const MissionItem& m = mission[item];
      if (sent_s >= 0) {
        if (result && *result == 0 && shown(m)) {
          ++item;
          sent_s = -1.0;
          result.reset();
          continue;
        }
        if (t_s - sent_s < 1.0 - 1e-9) return nullptr;  // its answer may still come
      }
      if (t_s + 1e-9 < m.at_s) return nullptr;
      result.reset();
      sent_s = t_s;
      return &m;
    }
    return nullptr;
  }
};

/// ArduCopter's custom mode number for a mode name (lower case), or -1.
int copter_mode_number(const std::string& name);

/// What a scenario's `controller: {sitl: {...}}` says (docs/scenarios.md).
struct SitlSpec {
  /// The flight stack: ardupilot (JSON protocol), px4 (simulator_mavlink) or betaflight (its SITL's UDP packets).
  std::string firmware = "ardupilot";
  std::string binary;               ///< the SITL executable (build/sitl/bin/arducopter, build/px4_sitl_*/bin/px4)
  std::vector<std::string> params;  ///< parameter files (NAME VALUE lines), applied in order
  std::string work_dir;             ///< where it runs (eeprom, logs); empty: a fresh temporary folder, removed after
  std::string home = "-35.363261,149.165230,584,0";  ///< --home: latitude, longitude [deg], altitude [m], yaw
  double start_timeout_s = 30.0;                     ///< [s] wall time for its first servo packet
  double timeout_s = 5.0;                            ///< [s] wall time without a servo packet that ends the run
  double pwm_min_us = 1000.0;                        ///< zero rotor speed at and below [us]
  double pwm_max_us = 2000.0;                        ///< omega_max at and above [us]
  std::vector<std::string> args;                     ///< more command-line arguments for the firmware
  std::vector<MissionItem> mission;  ///< commands over MAVLink (none: the firmware flies as its params say)
  bool echo_statustext = false;      ///< print the firmware's STATUSTEXT messages on stderr as they come
  // PX4 only.
  std::string etc_dir;       ///< its ROMFS folder (default: the binary's build folder's etc, ../etc from bin/px4)
  int airframe = 10016;      ///< PX4_SYS_AUTOSTART
  int instance = -1;         ///< -i: its ports are 4560 + i (simulator), 18570 + i (GCS), ...; -1: the first free
  double settle_ms = 200.0;  ///< [ms] wall time to wait, before each step, for its threads to sleep (0: no wait)
  /// The CPU it runs on (its real-time threads then take turns in priority order, the same on every
  /// run); -1: any; -2 (default): the last CPU this process may use.
  int cpu = -2;
  // Betaflight only.
  double arm_at_s = 2.0;         ///< [s] simulated time at which the pilot raises AUX1 (ARM); before it, throttle low
  double resend_ms = 100.0;      ///< [ms] wall time without a motor packet after which the FDM packet goes again
  double realtime_factor = 1.0;  ///< steps paced at this many times real time (0: unpaced; docs/sitl.md)
  sensors::Geodetic site;  ///< the world origin on the Earth (the GNSS's site): takeoff and goto altitudes, positions
  std::vector<std::string> added;  ///< what the scenario lacked and was added for PX4 (noted when it starts)
};

/// The figures a PX4 controller records (out.<name>): frame counts its answers, u1..u4 are its outputs
/// 1..4 (0..1), armed its HIL_ACTUATOR_CONTROLS' flag, mode its HEARTBEAT's custom_mode as seen at the
/// last 0.25 s decision (-1 before the first), mission the index of the mission item in progress.
inline constexpr const char* kPx4Outputs[] = {"frame", "u1", "u2", "u3", "u4", "armed", "mode", "mission"};

/// The figures a Betaflight controller records: m1..m4 its motors 1..4 (0..1), throttle_us and arm the RC
/// throttle and AUX1 sent, resent the FDM packets sent again, stale the motor packets dropped as late,
/// late the steps whose answer came more than a pacing period late.
inline constexpr const char* kBetaflightOutputs[] = {"m1",  "m2",     "m3",    "m4",  "throttle_us",
                                                     "arm", "resent", "stale", "late"};

/// The figures a SITL controller records (out.<name> in trajectory.csv).
/// armed and mode are the firmware's last HEARTBEAT's; mission is the index of the mission item in progress.
inline constexpr const char* kSitlOutputs[] = {"frame",    "pwm1",    "pwm2",  "pwm3", "pwm4",
                                               "repeated", "skipped", "armed", "mode", "mission"};

class SitlController final : public control::Controller {
 public:
  /// Checks the spec (the binary exists and is executable, the parameter files exist, the vehicle's
  /// spin signs fit an ArduPilot quad): std::invalid_argument naming what is wrong. Starts nothing.
  SitlController(SitlSpec spec, const model::VehicleParams& vehicle);
  ~SitlController() override;

  std::string_view type() const override { return "sitl"; }
  /// The step waits on another process's sockets (up to timeout_s).
  bool wants_own_thread() const override { return true; }
  /// A controller with the same spec whose firmware has not started.
  std::unique_ptr<control::Controller> clone() const override;
  std::span<const control::ParameterSpec> parameters() const override { return {}; }
  std::optional<control::ParameterValue> get_parameter(std::string_view) const override { return std::nullopt; }
  std::string set_parameters(std::span<const control::Setting> settings) override;
  std::span<const std::string> output_names() const override;
  /// Ends the firmware; the next step starts a fresh one (its eeprom wiped).
  void reset() override;
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

  const SitlSpec& spec() const { return spec_; }
  bool px4() const { return spec_.firmware == "px4"; }
  bool betaflight() const { return spec_.firmware == "betaflight"; }
  /// Betaflight's CLI lines: quadcosim's (betaflight::base_cli), the params files' (comments, save and
  /// exit left out), then save.
  std::vector<std::string> betaflight_cli() const;
  /// The same controller with `site` as its world origin on the Earth (PX4's takeoff and goto).
  std::shared_ptr<SitlController> with_site(const sensors::Geodetic& site, std::vector<std::string> added = {}) const;
  /// PX4's command line and environment (NAME=VALUE: PX4_SYS_AUTOSTART, PX4_PARAM_* of the vehicle's
  /// parameters and then the files'), for `instance` and `work_dir`.
  std::vector<std::string> px4_command_line(int instance, const std::string& work_dir) const;
  std::vector<std::string> px4_environment() const;
  const MotorMap& motor_map() const { return map_; }
  /// The command line the firmware gets (its ports as given), for docs and tests.
  std::vector<std::string> command_line(int json_port, int mavlink_port, int rc_port,
                                        const std::string& generated_params) const;
  /// The parameter file quadcosim writes before the user's: the frame that matches the vehicle.
  std::string generated_params() const;

  struct Counts {
    long long frames = 0;     ///< servo packets taken (one a step)
    long long repeated = 0;   ///< packets dropped because their frame count was seen already
    long long skipped = 0;    ///< frame counts that never came (a jump ahead)
    long long foreign = 0;    ///< datagrams from another sender, dropped
    long long late = 0;       ///< PX4: answers to an earlier step (while it started), dropped
    long long unsettled = 0;  ///< PX4: steps sent before its threads had all gone to sleep
  };
  const Counts& counts() const { return counts_; }

 private:
  struct Link;
  struct Px4Link;
  struct BfLink;
  void start();
  void start_betaflight();
  void wait_for_betaflight_msp();
  void step_betaflight(const control::Observation& observation, const control::Reference& reference, double dt_s,
                       control::ControllerOutput& out);
  betaflight::RcSticks betaflight_sticks(const control::Observation& obs, const control::Reference& ref, double dt_s);
  void start_px4();
  /// The folder the firmware runs in: spec_.work_dir (made when missing), or a fresh temporary one
  /// (`temporary` set: removed after a run that succeeded).
  std::string make_work_dir(bool& temporary) const;
  void step_px4(const control::Observation& observation, const control::Reference& reference, double dt_s,
                control::ControllerOutput& out);
  void service_px4_gcs();
  /// Reads the firmware's MAVLink messages; at decision times, advances the mission.
  void service_mavlink();
  [[noreturn]] void fail(const std::string& what) const;
  /// Writes argv into work_dir/command_line.txt and starts it there (its output to firmware.log);
  /// fails by name when it cannot be started.
  std::unique_ptr<FirmwareProcess> launch(const std::vector<std::string>& argv, const std::string& work_dir) const;

  SitlSpec spec_;
  model::Quadrotor model_;
  MotorMap map_;
  std::unique_ptr<Link> link_;
  std::unique_ptr<Px4Link> px4_;
  std::unique_ptr<BfLink> bf_;
  Counts counts_;
  long long steps_ = 0;
  double t_s_ = 0.0;
  control::ReportedOutputs reported_;
};

}  // namespace quadcosim::sitl
