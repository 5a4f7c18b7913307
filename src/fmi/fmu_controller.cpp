#include "fmi/fmu_controller.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <deque>
#include <iostream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "control/controller_config.hpp"
#include "fmi/isolated_instance.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "sensors/readings.hpp"
#include "sim/controller_node.hpp"

namespace quadcosim::fmi {

namespace {

constexpr std::array<std::string_view, 3> kRefJerk = {"ref.j_W[1]", "ref.j_W[2]", "ref.j_W[3]"};
constexpr std::array<std::string_view, 1> kRefYaw = {names::kRefYaw};
constexpr std::array<std::string_view, 1> kRefYawRate = {"ref.yaw_rate"};
constexpr std::array<std::string_view, 1> kRefRoll = {"ref.roll"};
constexpr std::array<std::string_view, 1> kRefPitch = {"ref.pitch"};

// The controller FMU's inputs, in the order they are set (the first five: the observation).
enum Input {
  kP,
  kV,
  kQ,
  kW,
  kF,
  kRefP,
  kRefV,
  kRefA,
  kRefJ,
  kRefYawIn,
  kRefYawRateIn,
  kRefRollIn,
  kRefPitchIn,
  kCount
};
const std::array<Signal, kCount> kInputs = {
    Signal{"p_W", names::kPosition, "m", false},          Signal{"v_W", names::kVelocity, "m/s", false},
    Signal{"q_WB", names::kAttitude, "1", false},         Signal{"w_B", names::kRates, "rad/s", false},
    Signal{"f_B", names::kSpecificForce, "m/s2", false},  Signal{"ref.p_W", names::kRefPosition, "m", false},
    Signal{"ref.v_W", names::kRefVelocity, "m/s", false}, Signal{"ref.a_W", names::kRefAcceleration, "m/s2", false},
    Signal{"ref.j_W", kRefJerk, "m/s3", false},           Signal{"ref.yaw", kRefYaw, "rad", false},
    Signal{"ref.yaw_rate", kRefYawRate, "rad/s", false},  Signal{"ref.roll", kRefRoll, "rad", false},
    Signal{"ref.pitch", kRefPitch, "rad", false},
};
const std::array<Signal, 1> kOutputs = {Signal{"omega_cmd", names::kOmegaCmd, "rad/s", true}};

constexpr std::size_t kSensorKinds = std::tuple_size_v<sensors::Kinds>;

/// The extra sensors' inputs (sensors/registry.hpp): one optional signal per column of each kind,
/// "<sensor>.<column>" with the plant FMU's output names (names::sensor_variable) and units, in the
/// registry's order.
struct SensorSignals {
  std::deque<std::string> strings;                    ///< owns the names
  std::deque<std::vector<std::string_view>> names;    ///< each signal's component names
  std::vector<Signal> signals;                        ///< kind by kind, column by column
  std::array<std::size_t, kSensorKinds + 1> first{};  ///< kind i's signals: [first[i], first[i + 1])
};

const SensorSignals& sensor_signals() {
  static const SensorSignals* all = [] {
    auto* s = new SensorSignals;
    sensors::for_each_kind([&]<class Kind>() {
      s->first[sensors::kind_index<Kind>()] = s->signals.size();
      for (const auto& col : Kind::kColumns) {
        const std::string& name = s->strings.emplace_back(std::string(Kind::kName) + "." + std::string(col.name));
        auto& components = s->names.emplace_back();
        for (int i = 0; i < col.width; ++i) {
          components.emplace_back(s->strings.emplace_back(names::sensor_variable(Kind::kName, col.name, col.width, i)));
        }
        s->signals.push_back(Signal{name, components, col.unit, false});
      }
    });
    s->first[kSensorKinds] = s->signals.size();
    return s;
  }();
  return *all;
}

/// Every input signal a scenario may name under `inputs:`: the observation, the reference, the extra
/// sensors' columns.
std::vector<Signal> all_inputs() {
  std::vector<Signal> all(kInputs.begin(), kInputs.end());
  const auto& extra = sensor_signals().signals;
  all.insert(all.end(), extra.begin(), extra.end());
  return all;
}

const std::vector<std::string>* given(const std::map<std::string, std::vector<std::string>, std::less<>>& m,
                                      std::string_view name) {
  const auto it = m.find(name);
  return it == m.end() ? nullptr : &it->second;
}

std::optional<double> number(const std::optional<std::string>& text) {
  if (!text) return std::nullopt;
  try {
    std::size_t used = 0;
    const double d = std::stod(*text, &used);
    if (used == text->size()) return d;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

std::atomic<int> instances_made{0};

}  // namespace

/// What an instance logged lately (the last few lines), for error messages; warnings and errors go
/// to stderr as they come.
struct FmuController::LogTail {
  std::mutex mutex;
  std::deque<std::string> lines;
  void add(const std::string& category, const std::string& status, const std::string& message) {
    const std::string line = status + (category.empty() ? "" : " [" + category + "]") + ": " + message;
    if (status != "OK") std::cerr << "fmu: " << line << '\n';
    const std::lock_guard lock(mutex);
    lines.push_back(line);
    if (lines.size() > 4) lines.pop_front();
  }
  std::string text() {
    const std::lock_guard lock(mutex);
    std::string out;
    for (const auto& l : lines) out += (out.empty() ? "" : "; ") + l;
    return out;
  }
};

struct FmuController::Shared {
  std::shared_ptr<Fmu> fmu;
  std::string description;
  std::array<int, kCount> in_at{};  ///< offset of each input signal in in_vrs, -1 when absent
  std::vector<int> sensor_at;       ///< likewise for each of sensor_signals(), in its order
  /// Per kind of the registry, the first FMU variable among its inputs (empty: the FMU has none).
  std::array<std::string, kSensorKinds> sensor_input;
  std::vector<ValueReference> in_vrs;
  int rotors = 4;                       ///< the FMU's omega_cmd outputs: one per rotor of the vehicle
  std::vector<ValueReference> out_vrs;  ///< omega_cmd[1..rotors], then the figures
  std::vector<std::string> out_names;   ///< the FMU variable of each out_vrs entry
  std::vector<std::string> figure_names;
  control::ReportedOutputs reported;             ///< where among figure_names the FMU reports its attitude setpoint
  std::vector<ParameterSetting> fixed_settings;  ///< the scenario's `parameters:` that are not in the table
  std::deque<std::string> strings;               ///< owns what the specs' string_views show
  std::vector<control::ParameterSpec> specs;
  std::vector<const Variable*> parameter_vars;
  std::vector<double> defaults;
  bool isolated = true;         ///< FmuMapping::isolated
  double step_timeout_s = 0.0;  ///< FmuMapping::step_timeout_s
};

std::span<const Signal> controller_inputs() { return kInputs; }
std::span<const Signal> controller_outputs() { return kOutputs; }

FmuController::FmuController(std::shared_ptr<Fmu> fmu, const FmuMapping& mapping, const model::VehicleParams& vehicle)
    : model_(vehicle) {
  auto sh = std::make_shared<Shared>();
  sh->fmu = std::move(fmu);
  sh->isolated = mapping.isolated;
  sh->step_timeout_s = mapping.step_timeout_s;
  sh->description = describe_fmu(*sh->fmu);
  const ModelDescription& md = sh->fmu->description();
  const std::string name = fmu_name(*sh->fmu);
  check_signal_keys(mapping.inputs, all_inputs(), "inputs");
  check_signal_keys(mapping.outputs, kOutputs, "outputs");
  // One command per rotor: the scenario's names, else omega_cmd[1..N] as the FMU declares them.
  const std::vector<std::string>* given_cmd = given(mapping.outputs, "omega_cmd");
  if (given_cmd) {
    sh->rotors = static_cast<int>(given_cmd->size());
    if (sh->rotors < model::kMinRotors || sh->rotors > model::kMaxRotors) {
      throw MappingError("outputs.omega_cmd", fmt::format("got {} names, expected 4 to 8 (one rotor speed command "
                                                          "per rotor of the vehicle)",
                                                          sh->rotors));
    }
  } else {
    int n = 0;
    while (n < model::kMaxRotors && md.find(names::kOmegaCmdAll[static_cast<std::size_t>(n)])) ++n;
    sh->rotors = std::max(n, model::kMinRotors);  // fewer than four: refused by name below
  }
  if (vehicle.rotor_count != sh->rotors) {
    throw FmuError(
        fmt::format("{}: the FMU controller outputs {} rotor speed commands (omega_cmd[1..{}]); the "
                    "vehicle has {} rotors (layout {})",
                    name, sh->rotors, sh->rotors, vehicle.rotor_count, model::to_string(vehicle.layout)));
  }
  Signal command = kOutputs[0];
  command.names = names::omega_cmd(sh->rotors);
  bool observes = false;
  for (std::size_t i = 0; i < kInputs.size(); ++i) {
    const SignalRefs r = resolve_signal(md, name, kInputs[i], Side::kInput, given(mapping.inputs, kInputs[i].name));
    sh->in_at[i] = r.empty() ? -1 : static_cast<int>(sh->in_vrs.size());
    sh->in_vrs.insert(sh->in_vrs.end(), r.begin(), r.end());
    if (i < kRefP && !r.empty()) observes = true;
  }
  const SensorSignals& extra = sensor_signals();
  for (std::size_t k = 0; k < kSensorKinds; ++k) {
    for (std::size_t i = extra.first[k]; i < extra.first[k + 1]; ++i) {
      const Signal& sig = extra.signals[i];
      const std::vector<std::string>* names = given(mapping.inputs, sig.name);
      const SignalRefs r = resolve_signal(md, name, sig, Side::kInput, names);
      sh->sensor_at.push_back(r.empty() ? -1 : static_cast<int>(sh->in_vrs.size()));
      sh->in_vrs.insert(sh->in_vrs.end(), r.begin(), r.end());
      if (!r.empty() && sh->sensor_input[k].empty())
        sh->sensor_input[k] = names ? names->front() : std::string(sig.names[0]);
    }
  }
  if (!observes) {
    throw MappingError("inputs", fmt::format("{} has none of the sensor inputs p_W, v_W, q_WB, w_B, f_B by their "
                                             "default names (p_W[1], ...); name the FMU's variables, e.g. inputs: "
                                             "{{p_W: [x, y, z]}}",
                                             name));
  }
  sh->out_vrs = resolve_signal(md, name, command, Side::kOutput, given_cmd);
  const std::vector<std::string> omega_names =
      given_cmd ? *given_cmd : std::vector<std::string>(command.names.begin(), command.names.end());
  sh->out_names = omega_names;
  // The controller's own figures: the FMU's other Real outputs.
  for (const Variable& v : md.variables) {
    if (v.causality != Causality::kOutput || v.type != VariableType::kReal) continue;
    if (std::find(omega_names.begin(), omega_names.end(), v.name) != omega_names.end()) continue;
    sh->out_vrs.push_back(v.vr);
    sh->out_names.push_back(v.name);
    sh->figure_names.push_back(v.name);
  }
  sh->reported = control::ReportedOutputs::find(sh->figure_names);
  // The parameter table: Real parameters that may be set (tunable, or fixed until initialisation).
  const std::string prefix(names::kControllerPrefix);
  for (const Variable& v : md.variables) {
    if (v.causality != Causality::kParameter || v.type != VariableType::kReal) continue;
    if (v.variability != Variability::kTunable && v.variability != Variability::kFixed) continue;
    const std::optional<double> start = number(v.start);
    if (!start) continue;  // a parameter without a start value is not offered
    std::string shown = v.name.rfind(prefix, 0) == 0 ? v.name.substr(prefix.size()) : v.name;
    if (control::node_parameters().find(shown)) shown = v.name;  // the node's own names stay the node's
    const std::string& n = sh->strings.emplace_back(shown);
    const std::string& u = sh->strings.emplace_back(v.unit);
    const std::string& d = sh->strings.emplace_back(
        v.description.empty()
            ? fmt::format("FMU parameter {}{}", v.name,
                          v.variability == Variability::kFixed ? " (fixed: until the first step)" : "")
            : v.description + (v.variability == Variability::kFixed ? " (fixed: until the first step)" : ""));
    control::ParameterSpec spec{n,
                                u,
                                d,
                                v.min.value_or(std::numeric_limits<double>::lowest()),
                                v.max.value_or(std::numeric_limits<double>::max()),
                                {},
                                true};
    sh->specs.push_back(spec);
    sh->parameter_vars.push_back(&v);
    sh->defaults.push_back(*start);
  }
  values_ = sh->defaults;
  changed_.assign(values_.size(), false);
  for (const ParameterSetting& p : check_parameters(md, name, mapping)) {
    bool in_table = false;
    for (std::size_t i = 0; i < sh->parameter_vars.size(); ++i) {
      if (sh->parameter_vars[i] == p.variable) {
        values_[i] = p.number;
        changed_[i] = true;
        in_table = true;
      }
    }
    if (!in_table) sh->fixed_settings.push_back(p);
  }
  shared_ = std::move(sh);
  instantiate();
}

FmuController::FmuController(std::shared_ptr<const Shared> shared, std::vector<double> values,
                             const model::Quadrotor& model)
    : shared_(std::move(shared)), values_(std::move(values)), model_(model) {
  changed_.assign(values_.size(), false);
  for (std::size_t i = 0; i < values_.size(); ++i) changed_[i] = values_[i] != shared_->defaults[i];
  instantiate();
}

FmuController::~FmuController() = default;

void FmuController::instantiate() {
  auto log = std::make_shared<LogTail>();
  log_ = log;
  const std::string name = fmt::format("{}_{}", shared_->fmu->description().model_identifier, instances_made++);
  LogSink sink = [log](const std::string& c, const std::string& s, const std::string& m) { log->add(c, s, m); };
  instance_ = shared_->isolated ? instantiate_isolated(shared_->fmu, name, std::move(sink), shared_->step_timeout_s)
                                : shared_->fmu->instantiate(name, std::move(sink));
  initialised_ = false;
  steps_ = 0;
  in_.assign(shared_->in_vrs.size(), 0.0);
  out_.assign(shared_->out_vrs.size(), 0.0);
}

void FmuController::initialise() {
  try {
    for (const ParameterSetting& p : shared_->fixed_settings) set_value(*instance_, *p.variable, p.number);
    for (std::size_t i = 0; i < values_.size(); ++i) {
      if (changed_[i]) set_value(*instance_, *shared_->parameter_vars[i], values_[i]);
    }
    instance_->enter_initialization(0.0);
    instance_->exit_initialization();
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("{}: initialisation failed: {}", describe(), e.what()));
  }
  initialised_ = true;
}

std::unique_ptr<control::Controller> FmuController::clone() const {
  return std::unique_ptr<FmuController>(new FmuController(shared_, values_, model_));
}

std::span<const control::ParameterSpec> FmuController::parameters() const { return shared_->specs; }

std::optional<control::ParameterValue> FmuController::get_parameter(std::string_view name) const {
  for (std::size_t i = 0; i < shared_->specs.size(); ++i) {
    if (shared_->specs[i].name == name) return values_[i];
  }
  return std::nullopt;
}

std::string FmuController::set_parameters(std::span<const control::Setting> settings) {
  std::vector<std::pair<std::size_t, double>> next;
  for (const control::Setting& s : settings) {
    std::size_t i = 0;
    while (i < shared_->specs.size() && shared_->specs[i].name != s.name) ++i;
    if (i == shared_->specs.size()) return control::unknown_parameter(s.name, shared_->specs);
    if (std::string err = control::check_value(shared_->specs[i], s.value); !err.empty()) return err;
    if (initialised_ && shared_->parameter_vars[i]->variability == Variability::kFixed) {
      return fmt::format("{}: the FMU declares it fixed: it can be set before the first step only", s.name);
    }
    next.emplace_back(i, std::get<double>(s.value));
  }
  if (initialised_) {
    // Through the FMU, one at a time; a refusal undoes the ones already set.
    std::vector<std::pair<std::size_t, double>> done;
    for (const auto& [i, value] : next) {
      try {
        set_value(*instance_, *shared_->parameter_vars[i], value);
      } catch (const std::exception& e) {
        for (const auto& [j, old] : done) {
          try {
            set_value(*instance_, *shared_->parameter_vars[j], old);
          } catch (const std::exception&) {
          }
        }
        return fmt::format("{}: refused by {}: {}", shared_->specs[i].name, describe(), e.what());
      }
      done.emplace_back(i, values_[i]);
    }
  }
  for (const auto& [i, value] : next) {
    values_[i] = value;
    if (!initialised_) changed_[i] = true;
  }
  return {};
}

std::span<const std::string> FmuController::output_names() const { return shared_->figure_names; }

void FmuController::reset() {
  if (initialised_) {
    instance_->reset();
    changed_.assign(values_.size(), true);  // the reset instance has its start values again
  }
  initialised_ = false;
  steps_ = 0;
}

void FmuController::step(const control::Observation& o, const control::Reference& r, double dt_s,
                         control::ControllerOutput& out) {
  const double t = static_cast<double>(steps_) * dt_s;
  auto put = [&](Input in, std::initializer_list<double> values) {
    const int at = shared_->in_at[in];
    if (at < 0) return;
    std::size_t i = static_cast<std::size_t>(at);
    for (double v : values) in_[i++] = v;
  };
  put(kP, {o.p_W.x(), o.p_W.y(), o.p_W.z()});
  put(kV, {o.v_W.x(), o.v_W.y(), o.v_W.z()});
  put(kQ, {o.q_WB.w(), o.q_WB.x(), o.q_WB.y(), o.q_WB.z()});
  put(kW, {o.w_B.x(), o.w_B.y(), o.w_B.z()});
  put(kF, {o.specific_force_B.x(), o.specific_force_B.y(), o.specific_force_B.z()});
  put(kRefP, {r.p_W.x(), r.p_W.y(), r.p_W.z()});
  put(kRefV, {r.v_W.x(), r.v_W.y(), r.v_W.z()});
  put(kRefA, {r.a_W.x(), r.a_W.y(), r.a_W.z()});
  put(kRefJ, {r.j_W.x(), r.j_W.y(), r.j_W.z()});
  put(kRefYawIn, {r.yaw_rad});
  put(kRefYawRateIn, {r.yaw_rate_rad_s});
  put(kRefRollIn, {r.roll_rad});
  put(kRefPitchIn, {r.pitch_rad});
  put_sensors(o.sensors);
  try {
    if (!initialised_) initialise();
    instance_->set_real(shared_->in_vrs, in_);
    instance_->do_step(t, dt_s);
    instance_->get_real(shared_->out_vrs, out_);
  } catch (const std::exception& e) {
    const std::string logged = log_ ? log_->text() : "";
    throw sim::ControllerFailure(fmt::format("{}: control step {} (t = {:g} s) failed: {}{}", describe(), steps_, t,
                                             e.what(), logged.empty() ? "" : " (the FMU logged: " + logged + ")"));
  }
  const auto rotors = static_cast<std::size_t>(shared_->rotors);
  for (std::size_t i = 0; i < rotors; ++i) {
    if (!std::isfinite(out_[i])) {
      throw sim::ControllerFailure(fmt::format("{}: control step {} (t = {:g} s): output '{}' is {}; not commanded",
                                               describe(), steps_, t, shared_->out_names[i], out_[i]));
    }
  }
  ++steps_;
  for (std::size_t i = 0; i < shared_->figure_names.size() && i < out.outputs.size(); ++i) {
    out.outputs[i] = out_[rotors + i];
  }
  model::RotorVector omega(shared_->rotors);
  for (std::size_t i = 0; i < rotors; ++i) omega[static_cast<Eigen::Index>(i)] = out_[i];
  control::rotor_speeds_output(model_, r, omega, shared_->reported, out);
}

void FmuController::put_sensors(const sensors::Readings& readings) {
  const SensorSignals& extra = sensor_signals();
  sensors::for_each_kind([&]<class Kind>() {
    constexpr std::size_t k = sensors::kind_index<Kind>();
    if (shared_->sensor_input[k].empty()) return;
    // The reading's columns packed; NaN (a flag 0) for a sensor not carried or before its first sample.
    std::array<double, sensors::sample_width<Kind>()> values;
    const sensors::Reading<Kind>* reading = readings.get<Kind>();
    const bool sampled = reading && reading->stamp_ns >= 0;
    if (sampled) {
      sensors::write_sample<Kind>(reading->sample, values.data());
    } else {
      values.fill(std::numeric_limits<double>::quiet_NaN());
    }
    const double* v = values.data();
    std::size_t i = extra.first[k];
    for (const auto& col : Kind::kColumns) {
      if (const int at = shared_->sensor_at[i++]; at >= 0) {
        for (int c = 0; c < col.width; ++c)
          in_[static_cast<std::size_t>(at + c)] = col.boolean && !sampled ? 0.0 : v[c];
      }
      v += col.width;
    }
  });
}

std::string FmuController::check_sensors(const sensors::SensorSet& carried) const {
  std::string error;
  sensors::for_each_kind([&]<class Kind>() {
    const std::string& input = shared_->sensor_input[sensors::kind_index<Kind>()];
    if (!error.empty() || input.empty() || Kind::config(carried)) return;
    error = fmt::format(
        "{} has the input '{}', but the vehicle carries no {}: turn it on with the scenario key "
        "sensors.{} (docs/sensors.md)",
        fmu_name(*shared_->fmu), input, Kind::kName, Kind::kName);
  });
  return error;
}

const std::shared_ptr<Fmu>& FmuController::fmu() const { return shared_->fmu; }

std::string FmuController::describe() const { return shared_->description; }

const FmuController* fmu_controller(const control::Controller& c) { return dynamic_cast<const FmuController*>(&c); }

}  // namespace quadcosim::fmi
