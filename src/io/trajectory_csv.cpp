#include "io/trajectory_csv.hpp"

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "io/output_folder.hpp"
#include "model/attitude.hpp"

namespace quadcosim::io {

ControlColumns ControlColumns::none() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan, nan, nan, nan, nan, Eigen::Vector4d::Constant(nan), false, {}, false, nan, {}, {}};
}

ControlColumns ControlColumns::from(const msg::ControllerStatus& m) {
  const auto& s = m.setpoint;
  return {s[0],
          s[1],
          s[2],
          s[3],
          s[4],
          s[5],
          Eigen::Vector4d(m.u[0], m.u[1], m.u[2], m.u[3]),
          m.safety,
          m.rotor_saturated,
          m.tilt_saturated,
          m.attitude_error,
          m.output_names,
          m.outputs};
}

std::array<int, 9> ControlColumns::saturation_columns() const {
  std::array<int, 9> out{};
  for (std::size_t i = 0; i < 8; ++i) out[i] = rotor_saturated[i] ? 1 : 0;
  out[8] = tilt_saturated ? 1 : 0;
  return out;
}

std::vector<std::string> TrajectoryWriter::columns(int rotors) {
  std::vector<std::string> c = {"t",  "x",  "y",    "z",     "vx",  "vy", "vz", "qw", "qx",
                                "qy", "qz", "roll", "pitch", "yaw", "p",  "q",  "r"};
  for (int i = 1; i <= rotors; ++i) c.push_back("w" + std::to_string(i));
  for (int i = 1; i <= rotors; ++i) c.push_back("cmd" + std::to_string(i));
  for (const char* n :
       {"x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des", "U1", "U2", "U3", "U4", "safety", "watchdog"}) {
    c.emplace_back(n);
  }
  for (int i = 1; i <= rotors; ++i) c.push_back("sat" + std::to_string(i));
  c.emplace_back("tilt_sat");
  c.emplace_back("att_err");
  return c;
}

std::string TrajectoryWriter::output_column(std::string_view name) { return "out." + std::string(name); }

TrajectoryWriter::TrajectoryWriter(const std::string& path) : path_(path) {
  file_ = open_output_file(path);  // never through a link planted at `path`
}

void TrajectoryWriter::write_header(std::span<const std::string> output_names, int rotors) {
  output_names_.assign(output_names.begin(), output_names.end());
  rotors_ = rotors;
  std::string header;
  for (const auto& c : columns(rotors)) header += (header.empty() ? "" : ",") + c;
  // A name with a comma or a line break would break the CSV's columns: those are written with "_".
  for (const std::string& name : output_names_) {
    std::string column = output_column(name);
    for (char& ch : column) {
      if (ch == ',' || ch == '\n' || ch == '\r' || ch == '"') ch = '_';
    }
    header += "," + column;
  }
  header += '\n';
  buffer_ += header;  // before any row: the first write() or close() calls this first
  header_written_ = true;
}

bool TrajectoryWriter::same_outputs(std::span<const std::string> names) const {
  return std::equal(names.begin(), names.end(), output_names_.begin(), output_names_.end());
}

TrajectoryWriter::~TrajectoryWriter() {
  if (file_) {
    if (!header_written_) write_header({}, rotors_);
    std::fwrite(buffer_.data(), 1, buffer_.size(), file_);
    std::fclose(file_);
  }
}

void TrajectoryWriter::write(double t, const model::State& x, const model::RotorVector& cmd, const ControlColumns& c,
                             bool watchdog) {
  if (!header_written_) write_header(c.output_names, static_cast<int>(cmd.size()));
  const model::Euler e = model::euler_from_quaternion(x.q_WB);
  auto out = std::back_inserter(buffer_);
  fmt::format_to(out, "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},", t, x.p_W.x(), x.p_W.y(), x.p_W.z(),
                 x.v_W.x(), x.v_W.y(), x.v_W.z(), x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z(), e.roll_rad,
                 e.pitch_rad, e.yaw_rad, x.w_B.x(), x.w_B.y(), x.w_B.z());
  if (rotors_ == 4) {
    fmt::format_to(out, "{},{},{},{},{},{},{},{},", x.omega_rad_s[0], x.omega_rad_s[1], x.omega_rad_s[2],
                   x.omega_rad_s[3], cmd[0], cmd[1], cmd[2], cmd[3]);
  } else {
    for (int i = 0; i < rotors_; ++i) fmt::format_to(out, "{},", x.omega_rad_s[i]);
    for (int i = 0; i < rotors_; ++i) fmt::format_to(out, "{},", cmd[i]);
  }
  fmt::format_to(out, "{},{},{},{},{},{},{},{},{},{},{},{},", c.x_des, c.y_des, c.z_des, c.roll_des, c.pitch_des,
                 c.yaw_des, c.U[0], c.U[1], c.U[2], c.U[3], c.safety ? 1 : 0, watchdog ? 1 : 0);
  const auto sat = c.saturation_columns();
  if (rotors_ == 4) {
    fmt::format_to(out, "{},{},{},{},{},{}", sat[0], sat[1], sat[2], sat[3], sat[8], c.attitude_error);
  } else {
    for (int i = 0; i < rotors_; ++i) fmt::format_to(out, "{},", sat[static_cast<std::size_t>(i)]);
    fmt::format_to(out, "{},{}", sat[8], c.attitude_error);
  }
  if (!output_names_.empty()) {
    const bool known = same_outputs(c.output_names) && c.outputs.size() == output_names_.size();
    for (std::size_t i = 0; i < output_names_.size(); ++i) {
      fmt::format_to(out, ",{}", known ? c.outputs[i] : std::numeric_limits<double>::quiet_NaN());
    }
  }
  buffer_.push_back('\n');
  if (buffer_.size() > (1 << 16)) {
    std::fwrite(buffer_.data(), 1, buffer_.size(), file_);
    buffer_.clear();
  }
}

void TrajectoryWriter::close() {
  if (!file_) return;
  if (!header_written_) write_header({}, rotors_);
  const bool ok = std::fwrite(buffer_.data(), 1, buffer_.size(), file_) == buffer_.size();
  int err = ok ? 0 : errno;
  buffer_.clear();
  const bool closed = std::fclose(file_) == 0;
  if (!closed && err == 0) err = errno;
  file_ = nullptr;
  // "No space left on device", "File too large": what the user must fix.
  if (!ok || !closed) throw std::runtime_error(path_ + ": write failed (" + std::strerror(err) + ")");
}

SeriesRecorder::SeriesRecorder() {
  const std::vector<std::string>& all = series_columns();
  for (std::size_t i = 0; i < kSeriesColumnsOfFourRotors; ++i) columns_.push_back(&series_.values[all[i]]);
}

void SeriesRecorder::clear(std::size_t rows) {
  series_.t_s.clear();
  series_.t_s.reserve(rows);
  for (std::vector<double>* column : columns_) {
    column->clear();
    column->reserve(rows);
  }
  for (std::vector<double>* column : extra_rotor_columns_) {
    column->clear();
    column->reserve(rows);
  }
}

void SeriesRecorder::add(double t_s, const model::State& x, const model::RotorVector& command, const ControlColumns& c,
                         bool watchdog) {
  const auto rotors = static_cast<int>(command.size());
  if (rotors > 4 && extra_rotor_columns_.empty()) {
    for (int i = 5; i <= rotors; ++i) extra_rotor_columns_.push_back(&series_.values["sat" + std::to_string(i)]);
    for (int i = 5; i <= rotors; ++i) extra_rotor_columns_.push_back(&series_.values["cmd" + std::to_string(i)]);
    for (std::vector<double>* column : extra_rotor_columns_) column->assign(series_.t_s.size(), 0.0);
  }
  // The values of TrajectoryWriter::write's columns of the same names.
  const model::Euler e = model::euler_from_quaternion(x.q_WB);
  const auto sat = c.saturation_columns();
  const double row[] = {x.p_W.x(),
                        x.p_W.y(),
                        x.p_W.z(),
                        e.roll_rad,
                        e.pitch_rad,
                        e.yaw_rad,
                        c.x_des,
                        c.y_des,
                        c.z_des,
                        c.roll_des,
                        c.pitch_des,
                        c.yaw_des,
                        static_cast<double>(sat[0]),
                        static_cast<double>(sat[1]),
                        static_cast<double>(sat[2]),
                        static_cast<double>(sat[3]),
                        static_cast<double>(sat[8]),
                        c.U[0],
                        c.attitude_error,
                        command[0],
                        command[1],
                        command[2],
                        command[3],
                        c.safety ? 1.0 : 0.0,
                        watchdog ? 1.0 : 0.0,
                        x.v_W.z()};
  static_assert(std::size(row) == 26);
  assert(columns_.size() == std::size(row));
  series_.t_s.push_back(t_s);
  for (std::size_t i = 0; i < columns_.size(); ++i) columns_[i]->push_back(row[i]);
  const std::size_t extra = extra_rotor_columns_.size() / 2;
  for (std::size_t i = 0; i < extra; ++i) {
    extra_rotor_columns_[i]->push_back(static_cast<double>(sat[4 + i]));
    extra_rotor_columns_[extra + i]->push_back(command[static_cast<Eigen::Index>(4 + i)]);
  }
}

std::vector<CommandRow> read_command_schedule(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file");
  std::string line;
  int line_no = 0;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + what);
  };
  auto trim = [](std::string s) {
    while (!s.empty() && (s.back() == '\r' || s.back() == ' ')) s.pop_back();
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    return s;
  };
  if (!std::getline(in, line)) {
    line_no = 1;
    fail("empty file, expected the header t,w1,w2,w3,w4");
  }
  line_no = 1;
  {
    std::vector<std::string> cols;
    if (trim(line).back() == ',') fail("header '" + trim(line) + "' has a trailing comma, expected t,w1,w2,w3,w4");
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cols.push_back(trim(c));
    if (cols != std::vector<std::string>{"t", "w1", "w2", "w3", "w4"}) {
      fail("header is '" + trim(line) + "', expected t,w1,w2,w3,w4");
    }
  }
  std::vector<CommandRow> rows;
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    if (trim(line).back() == ',') fail("trailing comma: expected exactly 5 values (t,w1,w2,w3,w4)");
    std::stringstream ss(line);
    std::vector<double> v;
    for (std::string cell; std::getline(ss, cell, ',');) {
      cell = trim(cell);
      std::size_t used = 0;
      double d = 0.0;
      try {
        d = std::stod(cell, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != cell.size()) fail("'" + cell + "' is not a number");
      v.push_back(d);
    }
    if (v.size() != 5) fail("expected 5 values (t,w1,w2,w3,w4), got " + std::to_string(v.size()));
    for (double d : v) {
      if (!std::isfinite(d)) fail("values must be finite");
    }
    if (v[0] < 0.0) fail("time must be >= 0");
    if (!rows.empty() && v[0] <= rows.back().t_s) fail("times must increase strictly");
    for (int i = 1; i <= 4; ++i) {
      if (v[i] < 0.0) fail("w" + std::to_string(i) + " must be >= 0 rad/s");
    }
    rows.push_back({v[0], Eigen::Vector4d(v[1], v[2], v[3], v[4])});
  }
  if (rows.empty()) fail("no command rows after the header");
  return rows;
}

}  // namespace quadcosim::io
