// trajectory.csv: one row per plant tick, numbers in shortest round-trip form (the same double
// always prints the same text, so identical runs give identical files).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/step_report.hpp"
#include "model/quadrotor.hpp"
#include "sim/messages.hpp"

namespace quadcosim::io {

/// Setpoints and controller outputs shown beside the state; NaN where there is none (open loop).
struct ControlColumns {
  double x_des, y_des, z_des, roll_des, pitch_des, yaw_des;
  Eigen::Vector4d U;  ///< U1 [N], U2..U4 [N m]
  bool safety;
  /// The controller's allocation clamped rotor i's demanded speed at omega_min or omega_max
  /// (ControllerStatus.rotor_saturated); the position loop's tilt limit acted (tilt_saturated).
  std::array<bool, 8> rotor_saturated{};  ///< one per rotor (those past the rotor count false)
  bool tilt_saturated = false;
  /// The controller's attitude error Psi = 1/2 tr(I - R_d^T R) (ControllerStatus.attitude_error; NaN
  /// when it has no desired attitude, and in open loop): the column att_err.
  double attitude_error = std::numeric_limits<double>::quiet_NaN();
  /// The controller's own figures (ControllerStatus.output_names, .outputs; empty in open loop): the
  /// columns out.<name>. They view the status they came from.
  std::span<const std::string> output_names;
  std::span<const double> outputs;
  /// The columns sat1..sat8 (the first N written), then tilt_sat (index 8): 1 where the flag is set, else 0.
  std::array<int, 9> saturation_columns() const;
  static ControlColumns none();
  /// The columns of a controller status message.
  static ControlColumns from(const msg::ControllerStatus& status);
};

class TrajectoryWriter {
 public:
  /// Opens (truncates) `path`; throws std::runtime_error naming the path when it cannot.
  explicit TrajectoryWriter(const std::string& path);
  ~TrajectoryWriter();
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  /// The columns every trajectory.csv of a vehicle with `rotors` rotors has, in order (w1..wN,
  /// cmd1..cmdN, sat1..satN); the controller's own figures follow them.
  static std::vector<std::string> columns(int rotors = 4);
  /// The column of a controller's own figure: "out." + its name ("out.error.z").
  static std::string output_column(std::string_view name);

  /// `command` is the rotor command acting over the next interval [rad/s], one per rotor (its size, N,
  /// fixed by the first row, sets the rotor columns); `watchdog`: the plant's
  /// watchdog set it (no valid command for its limit). The first row fixes the columns: columns() and
  /// one out.<name> for each of c.output_names; a later row whose controller declares other names (or
  /// none: a restarted or replaced controller, the safety command) has NaN in them.
  void write(double t_s, const model::State& x, const model::RotorVector& command, const ControlColumns& c,
             bool watchdog = false);
  /// Flushes and closes; throws std::runtime_error on a write error.
  void close();

 private:
  void write_header(std::span<const std::string> output_names, int rotors);
  bool same_outputs(std::span<const std::string> names) const;

  std::FILE* file_ = nullptr;
  std::string path_;
  std::string buffer_;
  bool header_written_ = false;
  std::vector<std::string> output_names_;  ///< the out.<name> columns, fixed by the first row
  int rotors_ = 4;                         ///< the rotor columns, fixed by the first row
};

/// Builds in memory the Series that read_series() gives for the trajectory.csv TrajectoryWriter writes from
/// the same ticks: t, the judged channels and setpoints (series_columns()), the saturation flags and U1, the
/// same doubles bit for bit (the CSV holds shortest round-trip text), without writing the file; att_err too.
class SeriesRecorder {
 public:
  SeriesRecorder();
  /// Adds the row TrajectoryWriter::write(t_s, x, command, c, watchdog) writes.
  void add(double t_s, const model::State& x, const model::RotorVector& command, const ControlColumns& c,
           bool watchdog = false);
  const Series& series() const { return series_; }
  /// Empties the series for another run of `rows` ticks, keeping its memory (a sweep's worker
  /// records every run it flies in one recorder instead of allocating the columns again per run).
  void clear(std::size_t rows);

 private:
  Series series_;
  std::vector<std::vector<double>*> columns_;  ///< into series_.values, in series_columns() order (4 rotors)
  /// Rotors 5..N: sat5..satN, then cmd5..cmdN, made at the first row of a vehicle with more rotors.
  std::vector<std::vector<double>*> extra_rotor_columns_;
};

/// One row of a motor command schedule (openloop input).
struct CommandRow {
  double t_s;
  Eigen::Vector4d omega_rad_s;
};

/// Reads a CSV with header `t,w1,w2,w3,w4` (times strictly increasing, starting at or after 0;
/// speeds finite and >= 0). Throws std::runtime_error naming file, line and the problem.
std::vector<CommandRow> read_command_schedule(const std::string& path);

}  // namespace quadcosim::io
