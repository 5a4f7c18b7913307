#include "fmi/fmu_plant.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "fmi/isolated_instance.hpp"
#include "fmi/quadrotor_variables.hpp"

namespace quadcosim::fmi {

namespace {

const std::array<Signal, 1> kPlantInputs = {Signal{"omega_cmd", names::kOmegaCmd, "rad/s", true}};
const std::array<Signal, 6> kPlantOutputs = {
    Signal{"p_W", names::kPosition, "m", true},          Signal{"v_W", names::kVelocity, "m/s", true},
    Signal{"q_WB", names::kAttitude, "1", false},        Signal{"w_B", names::kRates, "rad/s", false},
    Signal{"f_B", names::kSpecificForce, "m/s2", false}, Signal{"omega", names::kRotorSpeed, "rad/s", false},
};

const std::vector<std::string>* given(const std::map<std::string, std::vector<std::string>, std::less<>>& m,
                                      std::string_view name) {
  const auto it = m.find(name);
  return it == m.end() ? nullptr : &it->second;
}

/// The rotor count of the FMU: the scenario's omega_cmd names, else how many of omega_cmd[1..8] the FMU
/// declares (fewer than four: four, which then fail to resolve by name). MappingError when the names
/// given are not 4 to 8.
int fmu_rotor_count(const ModelDescription& md, const std::vector<std::string>* given_cmd) {
  if (given_cmd) {
    const auto n = static_cast<int>(given_cmd->size());
    if (n < model::kMinRotors || n > model::kMaxRotors) {
      throw MappingError("inputs.omega_cmd", fmt::format("got {} names, expected 4 to 8 (one rotor speed command per "
                                                         "rotor of the vehicle)",
                                                         n));
    }
    return n;
  }
  int n = 0;
  while (n < model::kMaxRotors && md.find(names::kOmegaCmdAll[static_cast<std::size_t>(n)])) ++n;
  return std::max(n, model::kMinRotors);
}

/// The FMU variable names of an output signal: the scenario's or the defaults.
std::vector<std::string> output_names(const FmuMapping& mapping, const Signal& s) {
  if (const auto* g = given(mapping.outputs, s.name)) return *g;
  return {s.names.begin(), s.names.end()};
}

/// A variable quadcosim may set before initialisation.
bool settable(const Variable* v) {
  return v && v->causality == Causality::kParameter && v->variability != Variability::kConstant;
}

/// The vehicle's parameters the FMU declares as vehicle.<name>, set on `instance`.
void set_vehicle(Instance& instance, const ModelDescription& md, const model::VehicleParams& vehicle) {
  std::vector<ValueReference> vrs;
  std::vector<double> values;
  for (const model::VehicleParameter& p : model::vehicle_parameters()) {
    const std::string name = std::string(names::kVehiclePrefix) + std::string(p.name);
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: {
        const Variable* v = md.find(name);
        if (settable(v) && v->type == VariableType::kReal) {
          vrs.push_back(v->vr);
          values.push_back(p.get(vehicle));
        }
        break;
      }
      case model::VehicleParameter::Kind::kChoice: {
        const Variable* v = md.find(name);
        if (!settable(v)) break;
        const std::string_view choice = p.choice_of(vehicle);
        if (v->type == VariableType::kString) {
          const ValueReference vr[1] = {v->vr};
          const std::string text[1] = {std::string(choice)};
          instance.set_string(vr, text);
        } else if (v->type == VariableType::kInteger || v->type == VariableType::kEnumeration) {
          // An enumeration of the choices in their declared order, 1-based as Modelica's.
          std::int32_t index = 0;
          for (std::size_t i = 0; i < p.choices.size(); ++i) {
            if (p.choices[i] == choice) index = static_cast<std::int32_t>(i + 1);
          }
          const ValueReference vr[1] = {v->vr};
          const std::int32_t x[1] = {index};
          instance.set_integer(vr, x);
        }
        break;
      }
      case model::VehicleParameter::Kind::kSigns: {
        model::VehicleParams copy = vehicle;
        const std::array<int, model::kMaxRotors>& signs = p.signs(copy);
        for (std::size_t r = 0; r < static_cast<std::size_t>(vehicle.rotor_count); ++r) {
          const Variable* v = md.find(fmt::format("{}[{}]", name, r + 1));
          if (!settable(v)) continue;
          set_value(instance, *v, signs[r]);
        }
        break;
      }
      case model::VehicleParameter::Kind::kRotors: break;  // the layout and the FMU's rotor count say it
    }
  }
  if (!vrs.empty()) instance.set_real(vrs, values);
}

/// initial.<output variable> for the state quadcosim starts from, where the FMU declares it.
void set_initial(Instance& instance, const ModelDescription& md, const FmuMapping& mapping,
                 std::span<const Signal> outputs, const model::State& x) {
  const std::array<double, 3> p{x.p_W.x(), x.p_W.y(), x.p_W.z()}, v{x.v_W.x(), x.v_W.y(), x.v_W.z()},
      w{x.w_B.x(), x.w_B.y(), x.w_B.z()};
  const std::array<double, 4> q{x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z()};
  const double* omega = x.omega_rad_s.data();  // one per rotor: as many as the omega signal's names
  const std::array<std::pair<std::string_view, const double*>, 5> initial = {
      {{"p_W", p.data()}, {"v_W", v.data()}, {"q_WB", q.data()}, {"w_B", w.data()}, {"omega", omega}}};
  std::vector<ValueReference> vrs;
  std::vector<double> values;
  for (const auto& [signal, value] : initial) {
    for (const Signal& s : outputs) {
      if (s.name != signal) continue;
      const std::vector<std::string> out = output_names(mapping, s);
      for (std::size_t i = 0; i < out.size(); ++i) {
        const Variable* var = md.find(std::string(names::kInitialPrefix) + out[i]);
        if (settable(var) && var->type == VariableType::kReal) {
          vrs.push_back(var->vr);
          values.push_back(value[i]);
        }
      }
    }
  }
  if (!vrs.empty()) instance.set_real(vrs, values);
}

class FmuDynamics final : public sim::ExternalDynamics {
 public:
  FmuDynamics(std::unique_ptr<Instance> instance, std::string name, const FmuPlant::Refs& refs,
              std::vector<std::string> output_names, const model::VehicleParams& vehicle, const model::State& initial,
              const sim::TickClock& clock, std::shared_ptr<std::atomic<int>> alive)
      : instance_(std::move(instance)),
        name_(std::move(name)),
        omega_cmd_(refs.omega_cmd),
        names_(std::move(output_names)),
        gravity_(vehicle.gravity_m_s2),
        clock_(clock),
        alive_(std::move(alive)) {
    // One get_real per tick for every output, in this order.
    auto add = [&](const SignalRefs& r, int& at) {
      at = r.empty() ? -1 : static_cast<int>(vrs_.size());
      vrs_.insert(vrs_.end(), r.begin(), r.end());
    };
    add(refs.p_W, at_p_);
    add(refs.v_W, at_v_);
    add(refs.q_WB, at_q_);
    add(refs.w_B, at_w_);
    add(refs.f_B, at_f_);
    add(refs.omega, at_omega_);
    values_.resize(vrs_.size());
    command_ = initial.omega_rad_s;
    omega_ = model::RotorVector::Zero(initial.omega_rad_s.size());
    read(0);
  }
  ~FmuDynamics() override { --*alive_; }

  void outputs(sim::Tick /*k*/, model::Outputs& y, model::State& x) override {
    y = y_;
    x.p_W = y_.p_W;
    x.v_W = y_.v_W;
    x.q_WB = y_.q_WB;
    x.w_B = y_.w_B;
    model::assign_rotors(x.omega_rad_s, at_omega_ >= 0 ? omega_ : command_);
  }

  void step(sim::Tick k, const model::RotorVector& omega_rad_s) override {
    try {
      // Inputs hold their value: the command is set when it changed (every control period, not
      // every plant tick); command_ is the one the FMU holds (the initial speeds at first).
      if (omega_rad_s.size() != command_.size() || omega_rad_s != command_) {
        if (static_cast<std::size_t>(omega_rad_s.size()) != omega_cmd_.size()) {
          throw FmuError(
              fmt::format("{} rotor speed commands for the FMU's {}", omega_rad_s.size(), omega_cmd_.size()));
        }
        instance_->set_real(omega_cmd_, std::span<const double>(omega_rad_s.data(), omega_cmd_.size()));
      }
      instance_->do_step(clock_.seconds(k), clock_.period_s());
    } catch (const InstanceInterrupted&) {
      throw;  // a stop request, not the FMU's failure
    } catch (const std::exception& e) {
      throw FmuError(fmt::format("{}: step at tick {} (t = {:g} s) failed: {}", name_, k, clock_.seconds(k), e.what()));
    }
    model::assign_rotors(command_, omega_rad_s);
    read(k + 1);
  }

 private:
  /// The outputs at tick k, checked finite.
  void read(sim::Tick k) {
    try {
      instance_->get_real(vrs_, values_);
    } catch (const std::exception& e) {
      throw FmuError(fmt::format("{}: reading the outputs at tick {} (t = {:g} s) failed: {}", name_, k,
                                 clock_.seconds(k), e.what()));
    }
    for (std::size_t i = 0; i < values_.size(); ++i) {
      if (!std::isfinite(values_[i])) {
        throw FmuError(fmt::format("{}: output '{}' is {} at tick {} (t = {:g} s)", name_, names_[i], values_[i], k,
                                   clock_.seconds(k)));
      }
    }
    const double* v = values_.data();
    y_.p_W = {v[at_p_], v[at_p_ + 1], v[at_p_ + 2]};
    y_.v_W = {v[at_v_], v[at_v_ + 1], v[at_v_ + 2]};
    y_.q_WB = at_q_ >= 0 ? Eigen::Quaterniond(v[at_q_], v[at_q_ + 1], v[at_q_ + 2], v[at_q_ + 3])
                         : Eigen::Quaterniond::Identity();
    y_.w_B = at_w_ >= 0 ? Eigen::Vector3d(v[at_w_], v[at_w_ + 1], v[at_w_ + 2]) : Eigen::Vector3d::Zero();
    y_.specific_force_B = at_f_ >= 0 ? Eigen::Vector3d(v[at_f_], v[at_f_ + 1], v[at_f_ + 2])
                                     : Eigen::Vector3d(y_.q_WB.conjugate() * Eigen::Vector3d(0.0, 0.0, gravity_));
    if (at_omega_ >= 0) {
      for (Eigen::Index i = 0; i < omega_.size(); ++i) omega_[i] = v[at_omega_ + i];
    }
  }

  std::unique_ptr<Instance> instance_;
  std::string name_;
  SignalRefs omega_cmd_;
  std::vector<ValueReference> vrs_;
  std::vector<double> values_;
  std::vector<std::string> names_;  ///< the FMU variable of each entry of vrs_
  int at_p_ = -1, at_v_ = -1, at_q_ = -1, at_w_ = -1, at_f_ = -1, at_omega_ = -1;
  double gravity_;
  sim::TickClock clock_;
  model::Outputs y_;
  model::RotorVector omega_;    ///< the rotor speeds the FMU outputs, one per rotor
  model::RotorVector command_;  ///< the command the FMU holds, one per rotor
  std::shared_ptr<std::atomic<int>> alive_;
};

}  // namespace

std::span<const Signal> plant_inputs() { return kPlantInputs; }
std::span<const Signal> plant_outputs() { return kPlantOutputs; }

FmuPlant::FmuPlant(std::shared_ptr<Fmu> fmu, const FmuMapping& mapping) : fmu_(std::move(fmu)), mapping_(mapping) {
  const ModelDescription& md = fmu_->description();
  const std::string name = fmu_name(*fmu_);
  check_signal_keys(mapping.inputs, kPlantInputs, "inputs");
  check_signal_keys(mapping.outputs, kPlantOutputs, "outputs");
  // The rotor count: omega_cmd[1..N] (and omega[1..N]) for N = the FMU's.
  rotor_count_ = fmu_rotor_count(md, given(mapping.inputs, "omega_cmd"));
  Signal command = kPlantInputs[0];
  command.names = names::omega_cmd(rotor_count_);
  outputs_.assign(kPlantOutputs.begin(), kPlantOutputs.end());
  outputs_.back().names = names::rotor_speed(rotor_count_);
  refs_.omega_cmd = resolve_signal(md, name, command, Side::kInput, given(mapping.inputs, "omega_cmd"));
  SignalRefs* outs[] = {&refs_.p_W, &refs_.v_W, &refs_.q_WB, &refs_.w_B, &refs_.f_B, &refs_.omega};
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    *outs[i] = resolve_signal(md, name, outputs_[i], Side::kOutput, given(mapping.outputs, outputs_[i].name));
  }
  parameters_ = check_parameters(md, name, mapping);
}

std::string FmuPlant::describe() const { return describe_fmu(*fmu_); }

std::string FmuPlant::check(const model::VehicleParams& vehicle) const {
  if (vehicle.rotor_count == rotor_count_) return {};
  return fmt::format(
      "{}: the FMU plant takes {} rotor speed commands (omega_cmd[1..{}]); the vehicle has {} rotors "
      "(layout {})",
      fmu_name(*fmu_), rotor_count_, rotor_count_, vehicle.rotor_count, model::to_string(vehicle.layout));
}

std::unique_ptr<sim::ExternalDynamics> FmuPlant::make(const model::VehicleParams& vehicle, const model::State& initial,
                                                      const sim::TickClock& clock) const {
  const ModelDescription& md = fmu_->description();
  const std::string name = fmu_name(*fmu_);
  if (std::string err = check(vehicle); !err.empty()) throw FmuError(err);
  if (md.can_be_instantiated_only_once_per_process && alive_->load() > 0) {
    throw FmuError(
        fmt::format("{} can be instantiated only once per process (canBeInstantiatedOnlyOncePerProcess); "
                    "a second plant (a swarm's next vehicle) needs a second instance",
                    name));
  }
  const int n = (*made_)++;
  const std::string instance_name = fmt::format("{}_{}", md.model_identifier, n);
  std::unique_ptr<Instance> instance = mapping_.isolated
                                           ? instantiate_isolated(fmu_, instance_name, {}, mapping_.step_timeout_s)
                                           : fmu_->instantiate(instance_name);
  ++*alive_;
  std::shared_ptr<std::atomic<int>> alive = alive_;
  struct Undo {  // the count goes down again if anything below throws
    std::shared_ptr<std::atomic<int>>* alive;
    ~Undo() {
      if (alive) --**alive;
    }
  } undo{&alive};
  try {
    set_vehicle(*instance, md, vehicle);
    set_initial(*instance, md, mapping_, outputs_, initial);
    for (const ParameterSetting& p : parameters_) set_value(*instance, *p.variable, p.number);
    instance->enter_initialization(0.0);
    // The command acting before the first one arrives is the initial rotor speeds (as the native
    // plant latches them): the outputs at t = 0 (the specific force) are computed under it.
    instance->set_real(refs_.omega_cmd, std::span<const double>(initial.omega_rad_s.data(), refs_.omega_cmd.size()));
    instance->exit_initialization();
  } catch (const std::exception& e) {
    throw FmuError(fmt::format("{}: initialisation failed: {}", describe(), e.what()));
  }
  std::vector<std::string> names;
  for (const Signal& s : outputs_) {
    const SignalRefs* r = s.name == "p_W"    ? &refs_.p_W
                          : s.name == "v_W"  ? &refs_.v_W
                          : s.name == "q_WB" ? &refs_.q_WB
                          : s.name == "w_B"  ? &refs_.w_B
                          : s.name == "f_B"  ? &refs_.f_B
                                             : &refs_.omega;
    if (r->empty()) continue;
    for (const auto& v : output_names(mapping_, s)) names.push_back(v);
  }
  auto dynamics = std::make_unique<FmuDynamics>(std::move(instance), describe(), refs_, std::move(names), vehicle,
                                                initial, clock, alive);
  undo.alive = nullptr;  // from here FmuDynamics counts it down when it goes
  return dynamics;
}

}  // namespace quadcosim::fmi
