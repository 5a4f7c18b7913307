// One instance of an exported FMU, below the C API (fmi2_functions.cpp, fmi3_functions.cpp): the
// value of every variable (by value reference, as describe() numbers them), the FMI state machine,
// the checks every call makes, and the model that steps (a plant or a controller, slave.cpp).
//
// Calls refused (wrong state, unknown value reference, set of a variable that cannot be set, NaN
// input, bad step) return Status::kError with a message through the log, and change nothing: the
// instance stays usable. Only a model that fails mid-step leaves it in the error state.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fmi/export/fmu_config.hpp"

namespace quadcosim::fmi::exported {

/// Numbered as fmi2Status and fmi3Status are (OK .. Fatal).
enum class Status { kOK = 0, kWarning = 1, kDiscard = 2, kError = 3, kFatal = 4 };

/// The values of all variables, indexed by value reference: numbers (Real, Integer, Boolean as 0/1)
/// in `number`, String variables in `text`.
struct Values {
  std::vector<double> number;
  std::vector<std::string> text;
};

/// What steps: the plant or the controller, over the values of its variables.
class Model {
 public:
  virtual ~Model() = default;
  virtual std::unique_ptr<Model> clone() const = 0;
  /// Builds the model from the parameters in `v` (initial state, vehicle, switches) and writes the
  /// outputs at period `k` (the start time). "" or why not, naming the variable.
  virtual std::string initialize(sim::Tick k, Values& v) = 0;
  /// "" when step() can take the inputs in `v`, else why not (the step is refused, nothing changes).
  virtual std::string check_inputs(const Values& v) const = 0;
  /// `n` periods from period `k` (time k * period_ns()) under the inputs in `v`, writing the outputs.
  /// "" or why it failed (then the instance is in the error state).
  virtual std::string step(sim::Tick k, std::int64_t n, Values& v) = 0;
  /// Applies tunable parameters (value references and their new values in `next`, all together).
  /// "" or why they were refused (then nothing changed).
  virtual std::string set_tunable(const std::vector<ValueReference>& vrs, const Values& next) = 0;
  /// The model's period [ns]: a communication step is a whole number of them.
  virtual std::int64_t period_ns() const = 0;
  /// Outputs computed only when read (the plant's Euler angles, from its attitude outputs): called
  /// with the value references about to be read, before they are.
  virtual void complete_outputs(const ValueReference* /*vr*/, std::size_t /*n*/, Values& /*v*/) const {}
};

/// The model of `config` over the variables of `md` (describe(config)). Throws FmuError.
std::unique_ptr<Model> make_model(const FmuConfig& config, const ModelDescription& md);
std::unique_ptr<Model> make_plant_model(const FmuConfig& config, const ModelDescription& md);  // plant_model.cpp
std::unique_ptr<Model> make_controller_model(const FmuConfig& config,
                                             const ModelDescription& md);  // controller_model.cpp

/// The value reference of the variable `name` of `md`. Throws FmuError when there is none.
ValueReference find_vr(const ModelDescription& md, std::string_view name);
/// The same for each of `names`.
template <std::size_t N>
std::array<ValueReference, N> find_vrs(const ModelDescription& md, const std::array<std::string_view, N>& names) {
  std::array<ValueReference, N> vrs{};
  for (std::size_t i = 0; i < N; ++i) vrs[i] = find_vr(md, names[i]);
  return vrs;
}

/// The same for a vehicle's rotors (names::omega_cmd(n), names::rotor_speed(n)), optionally with a
/// prefix ("initial.").
std::vector<ValueReference> find_vrs(const ModelDescription& md, std::span<const std::string_view> names,
                                     std::string_view prefix = {});

class Slave {
 public:
  using Log = std::function<void(Status status, const char* category, const std::string& message)>;
  enum class State { kInstantiated, kInitialization, kStepMode, kTerminated, kError };

  /// Throws FmuError (the model cannot be made).
  Slave(FmuConfig config, Log log);

  /// FMI 2 fmi2SetupExperiment (instantiated state only); FMI 3 passes these to enter_initialization.
  Status setup_experiment(double start_time_s, std::optional<double> stop_time_s);
  Status enter_initialization();
  Status exit_initialization();
  /// One communication step [t, t + h]: h a whole number of periods, t the current time.
  Status do_step(double t_s, double h_s);
  Status terminate();
  Status reset();

  Status get_real(const ValueReference* vr, std::size_t n, double* values);
  Status set_real(const ValueReference* vr, std::size_t n, const double* values);
  Status get_integer(const ValueReference* vr, std::size_t n, std::int32_t* values);
  Status set_integer(const ValueReference* vr, std::size_t n, const std::int32_t* values);
  Status get_boolean(const ValueReference* vr, std::size_t n, bool* values);
  Status set_boolean(const ValueReference* vr, std::size_t n, const bool* values);
  /// The pointers stay valid until the next call on this instance.
  Status get_string(const ValueReference* vr, std::size_t n, const char** values);
  Status set_string(const ValueReference* vr, std::size_t n, const char* const* values);

  /// A copy of everything (values, model, time, state) for get/set FMU state; freed with delete.
  struct Snapshot;
  Status get_state(Snapshot** out);
  Status set_state(const Snapshot* s);
  static void free_state(Snapshot* s);

  /// Logs `message` and returns kError (a call the FMU cannot honour).
  Status refuse(const std::string& message);
  void log(Status status, const char* category, const std::string& message) const;

  const ModelDescription& description() const { return md_; }
  State state() const { return state_; }
  double time_s() const;

 private:
  /// True when variable `vr` exists and is of `type`.
  bool valid(ValueReference vr, VariableType type) const { return vr < type_of_.size() && type_of_[vr] == type; }
  /// "" when variable `vr` exists and is of `type`, else why not.
  std::string check_vr(ValueReference vr, VariableType type) const;
  /// Reads Real, Integer or Boolean values (stored as doubles) into `values`.
  template <class Out>
  Status get_numbers(const ValueReference* vr, std::size_t n, VariableType type, Out* values);
  /// Checks and sets `n` values: `numbers` for Real, Integer and Boolean variables, else `strings`.
  Status set_values(const ValueReference* vr, std::size_t n, VariableType type, const double* numbers,
                    const char* const* strings);
  /// Outputs read in initialization mode: the model built from the parameters as they are now.
  Status refresh_outputs();
  void restart();

  FmuConfig config_;
  ModelDescription md_;
  Log log_;
  ValueReference time_vr_;             ///< the independent variable, read as the current communication point
  std::vector<VariableType> type_of_;  ///< by value reference (the variables' index): each get and set checks it
  Values values_;
  std::unique_ptr<Model> model_;
  State state_ = State::kInstantiated;
  sim::Tick tick_ = 0;        ///< the current communication point, in model periods
  sim::Tick start_tick_ = 0;  ///< the start time, in model periods
  bool outputs_stale_ = true;
};

struct Slave::Snapshot {
  Values values;
  std::unique_ptr<Model> model;
  State state;
  sim::Tick tick, start_tick;
  bool outputs_stale;
};

}  // namespace quadcosim::fmi::exported
