#include "fmi/export/slave.hpp"

#include <charconv>
#include <cmath>

namespace quadcosim::fmi::exported {

namespace {

/// How far [ns] a communication point or step size may be from a whole number of periods.
constexpr double kToleranceNs = 5.0;

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string_view type_name(VariableType t) {
  switch (t) {
    case VariableType::kReal: return "Real";
    case VariableType::kInteger: return "Integer";
    case VariableType::kBoolean: return "Boolean";
    case VariableType::kString: return "String";
    default: return "other";
  }
}

/// The whole number of `period_ns` periods in `seconds`, or nothing when it is not one (within the
/// tolerance) or out of range.
std::optional<sim::Tick> whole_periods(double seconds, std::int64_t period_ns) {
  const double ns = seconds * 1e9;
  if (!std::isfinite(ns) || std::abs(ns) > 9e18) return std::nullopt;
  const auto n = static_cast<sim::Tick>(std::llround(ns / static_cast<double>(period_ns)));
  if (std::abs(ns - static_cast<double>(n) * static_cast<double>(period_ns)) > kToleranceNs) return std::nullopt;
  return n;
}

Values start_values(const ModelDescription& md) {
  Values v;
  v.number.assign(md.variables.size(), 0.0);
  v.text.assign(md.variables.size(), std::string());
  for (const Variable& var : md.variables) {
    if (!var.start) continue;
    if (var.type == VariableType::kString) {
      v.text[var.vr] = *var.start;
    } else if (var.type == VariableType::kBoolean) {
      v.number[var.vr] = *var.start == "true" ? 1.0 : 0.0;
    } else {
      // Shortest round-trip text: exact. from_chars, unlike strtod, ignores the importer's locale.
      std::from_chars(var.start->data(), var.start->data() + var.start->size(), v.number[var.vr]);
    }
  }
  return v;
}

const char* state_name(Slave::State s) {
  switch (s) {
    case Slave::State::kInstantiated: return "instantiated (before enterInitializationMode)";
    case Slave::State::kInitialization: return "initialization mode";
    case Slave::State::kStepMode: return "step mode";
    case Slave::State::kTerminated: return "terminated";
    case Slave::State::kError: return "error (after a failed step; reset or free it)";
  }
  return "?";
}

}  // namespace

ValueReference find_vr(const ModelDescription& md, std::string_view name) {
  for (const Variable& v : md.variables) {
    if (v.name == name) return v.vr;
  }
  throw FmuError("the FMU has no variable '" + std::string(name) + "'");
}

std::vector<ValueReference> find_vrs(const ModelDescription& md, std::span<const std::string_view> names,
                                     std::string_view prefix) {
  std::vector<ValueReference> vrs;
  for (const std::string_view n : names) vrs.push_back(find_vr(md, std::string(prefix) + std::string(n)));
  return vrs;
}

std::unique_ptr<Model> make_model(const FmuConfig& config, const ModelDescription& md) {
  return config.kind == FmuKind::kPlant ? make_plant_model(config, md) : make_controller_model(config, md);
}

Slave::Slave(FmuConfig config, Log log)
    : config_(std::move(config)), md_(describe(config_)), log_(std::move(log)), time_vr_(find_vr(md_, "time")) {
  for (const Variable& v : md_.variables) type_of_.push_back(v.type);  // describe() numbers them 0, 1, ...
  restart();
}

void Slave::restart() {
  values_ = start_values(md_);
  model_ = make_model(config_, md_);
  state_ = State::kInstantiated;
  tick_ = start_tick_ = 0;
  outputs_stale_ = true;
}

void Slave::log(Status status, const char* category, const std::string& message) const {
  if (log_) log_(status, category, message);
}

Status Slave::refuse(const std::string& message) {
  log(Status::kError, "logStatusError", message);
  return Status::kError;
}

double Slave::time_s() const { return static_cast<double>(tick_ * model_->period_ns()) / 1e9; }

Status Slave::setup_experiment(double start_time_s, std::optional<double> /*stop_time_s*/) {
  if (state_ != State::kInstantiated) {
    return refuse(std::string("setupExperiment is allowed only before enterInitializationMode, not in ") +
                  state_name(state_));
  }
  const std::optional<sim::Tick> k = whole_periods(start_time_s, model_->period_ns());
  if (!k) {
    return refuse("start time " + number_text(start_time_s) + " s is not a whole number of periods (period " +
                  number_text(static_cast<double>(model_->period_ns()) / 1e9) + " s)");
  }
  start_tick_ = tick_ = *k;
  return Status::kOK;
}

Status Slave::enter_initialization() {
  if (state_ != State::kInstantiated) {
    return refuse(std::string("enterInitializationMode is allowed only once after instantiation, not in ") +
                  state_name(state_));
  }
  state_ = State::kInitialization;
  return Status::kOK;
}

Status Slave::exit_initialization() {
  if (state_ != State::kInitialization) {
    return refuse(std::string("exitInitializationMode is allowed only in initialization mode, not in ") +
                  state_name(state_));
  }
  if (std::string err = model_->initialize(start_tick_, values_); !err.empty()) return refuse(err);
  tick_ = start_tick_;
  outputs_stale_ = false;
  state_ = State::kStepMode;
  return Status::kOK;
}

Status Slave::do_step(double t_s, double h_s) {
  if (state_ != State::kStepMode) {
    return refuse(std::string("doStep is allowed only after exitInitializationMode (in step mode), not in ") +
                  state_name(state_));
  }
  if (!(h_s > 0.0)) return refuse("communication step size h = " + number_text(h_s) + " s: it must be positive");
  const std::int64_t period = model_->period_ns();
  const std::optional<sim::Tick> n = whole_periods(h_s, period);
  if (!n || *n < 1) {
    return refuse("communication step size h = " + number_text(h_s) + " s is not a whole number of periods (period " +
                  number_text(static_cast<double>(period) / 1e9) + " s)");
  }
  const std::optional<sim::Tick> k = whole_periods(t_s, period);
  if (!k || *k != tick_) {
    return refuse("doStep from t = " + number_text(t_s) + " s, but the FMU is at t = " + number_text(time_s()) +
                  " s (the last communication point)");
  }
  if (std::string err = model_->check_inputs(values_); !err.empty()) return refuse(err);
  if (std::string err = model_->step(tick_, *n, values_); !err.empty()) {
    state_ = State::kError;
    return refuse(err);
  }
  tick_ += *n;
  return Status::kOK;
}

Status Slave::terminate() {
  if (state_ != State::kStepMode && state_ != State::kInitialization) {
    return refuse(std::string("terminate is allowed in initialization or step mode, not in ") + state_name(state_));
  }
  state_ = State::kTerminated;
  return Status::kOK;
}

Status Slave::reset() {
  try {
    restart();
  } catch (const std::exception& e) {
    state_ = State::kError;
    return refuse(std::string("reset failed: ") + e.what());
  }
  return Status::kOK;
}

std::string Slave::check_vr(ValueReference vr, VariableType type) const {
  if (vr < md_.variables.size() && md_.variables[vr].type == type) return {};  // the usual case, no text
  if (vr >= md_.variables.size()) return "unknown value reference " + std::to_string(vr);
  const Variable& v = md_.variables[vr];
  if (v.type != type) {
    return "variable " + v.name + " (value reference " + std::to_string(vr) + ") is " + std::string(type_name(v.type)) +
           ", not " + std::string(type_name(type));
  }
  return {};
}

Status Slave::refresh_outputs() {
  std::unique_ptr<Model> m = model_->clone();
  Values v = values_;
  if (std::string err = m->initialize(start_tick_, v); !err.empty()) return refuse(err);
  values_ = std::move(v);
  outputs_stale_ = false;
  return Status::kOK;
}

template <class Out>
Status Slave::get_numbers(const ValueReference* vr, std::size_t n, VariableType type, Out* values) {
  if (state_ == State::kInstantiated) {
    return refuse(std::string("get") + std::string(type_name(type)) + " is not allowed before enterInitializationMode");
  }
  if (n > 0 && (!vr)) return refuse("get" + std::string(type_name(type)) + ": null value reference array");
  for (std::size_t i = 0; i < n; ++i) {
    if (!valid(vr[i], type)) return refuse(check_vr(vr[i], type));
  }
  if (state_ == State::kInitialization && outputs_stale_) {
    if (Status s = refresh_outputs(); s != Status::kOK) return s;
  }
  values_.number[time_vr_] = time_s();
  model_->complete_outputs(vr, n, values_);
  for (std::size_t i = 0; i < n; ++i) values[i] = static_cast<Out>(values_.number[vr[i]]);
  return Status::kOK;
}

Status Slave::set_values(const ValueReference* vr, std::size_t n, VariableType type, const double* numbers,
                         const char* const* strings) {
  const std::string_view call_type = type_name(type);
  const auto refuse_set = [&](const std::string& why) { return refuse("set" + std::string(call_type) + ": " + why); };
  if (state_ == State::kTerminated || state_ == State::kError) {
    return refuse_set(std::string("not allowed in ") + state_name(state_));
  }
  if (n > 0 && (!vr || (!numbers && !strings))) return refuse_set("null value reference or value array");
  // Every value is checked before any is applied: a refused call changes nothing.
  bool tunable = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!valid(vr[i], type)) return refuse_set(check_vr(vr[i], type));
    const Variable& v = md_.variables[vr[i]];
    if (v.variability == Variability::kConstant) return refuse_set(v.name + " is a constant: it cannot be set");
    switch (v.causality) {
      case Causality::kInput: break;
      case Causality::kParameter:
        if (v.variability == Variability::kFixed && state_ == State::kStepMode) {
          return refuse_set(v.name + " is a fixed parameter: it can be set only before exitInitializationMode");
        }
        tunable = tunable || v.variability == Variability::kTunable;
        break;
      case Causality::kIndependent: return refuse_set(v.name + " is the independent variable (time): it cannot be set");
      default:
        return refuse_set(v.name + " is " + (v.causality == Causality::kOutput ? "an output" : "calculated") +
                          " (computed by the FMU): it cannot be set");
    }
    if (strings) {
      if (!strings[i]) return refuse_set(v.name + ": a null string refused");
      continue;
    }
    const double x = numbers[i];
    if (!std::isfinite(x)) return refuse_set(v.name + " = " + number_text(x) + " refused: not a finite number");
    if ((v.min && x < *v.min) || (v.max && x > *v.max)) {
      return refuse_set(v.name + " = " + number_text(x) + " is outside [" + number_text(v.min.value_or(-HUGE_VAL)) +
                        ", " + number_text(v.max.value_or(HUGE_VAL)) + "]");
    }
  }
  const auto apply = [&](Values& to) {
    for (std::size_t i = 0; i < n; ++i) {
      if (strings) {
        to.text[vr[i]] = strings[i];
      } else {
        to.number[vr[i]] = numbers[i];
      }
    }
  };
  if (tunable) {  // the model takes them all or none
    Values next = values_;
    apply(next);
    std::vector<ValueReference> tunables;
    for (std::size_t i = 0; i < n; ++i) {
      if (md_.variables[vr[i]].variability == Variability::kTunable) tunables.push_back(vr[i]);
    }
    if (std::string err = model_->set_tunable(tunables, next); !err.empty()) return refuse_set(err);
    values_ = std::move(next);
  } else {
    apply(values_);
  }
  if (state_ == State::kInitialization) outputs_stale_ = true;
  return Status::kOK;
}

Status Slave::get_real(const ValueReference* vr, std::size_t n, double* values) {
  return get_numbers(vr, n, VariableType::kReal, values);
}

Status Slave::get_integer(const ValueReference* vr, std::size_t n, std::int32_t* values) {
  return get_numbers(vr, n, VariableType::kInteger, values);
}

Status Slave::get_boolean(const ValueReference* vr, std::size_t n, bool* values) {
  return get_numbers(vr, n, VariableType::kBoolean, values);  // stored as 0 or 1
}

Status Slave::get_string(const ValueReference* vr, std::size_t n, const char** values) {
  if (state_ == State::kInstantiated) return refuse("getString is not allowed before enterInitializationMode");
  if (n > 0 && !vr) return refuse("getString: null value reference array");
  for (std::size_t i = 0; i < n; ++i) {
    if (!valid(vr[i], VariableType::kString)) return refuse(check_vr(vr[i], VariableType::kString));
  }
  for (std::size_t i = 0; i < n; ++i) values[i] = values_.text[vr[i]].c_str();
  return Status::kOK;
}

Status Slave::set_real(const ValueReference* vr, std::size_t n, const double* values) {
  return set_values(vr, n, VariableType::kReal, values, nullptr);
}

Status Slave::set_integer(const ValueReference* vr, std::size_t n, const std::int32_t* values) {
  std::vector<double> numbers(n);
  for (std::size_t i = 0; i < n && values; ++i) numbers[i] = values[i];
  return set_values(vr, n, VariableType::kInteger, values ? numbers.data() : nullptr, nullptr);
}

Status Slave::set_boolean(const ValueReference* vr, std::size_t n, const bool* values) {
  std::vector<double> numbers(n);
  for (std::size_t i = 0; i < n && values; ++i) numbers[i] = values[i] ? 1.0 : 0.0;
  return set_values(vr, n, VariableType::kBoolean, values ? numbers.data() : nullptr, nullptr);
}

Status Slave::set_string(const ValueReference* vr, std::size_t n, const char* const* values) {
  return set_values(vr, n, VariableType::kString, nullptr, values);
}

Status Slave::get_state(Snapshot** out) {
  if (!out) return refuse("getFMUstate: null state pointer");
  auto s = std::make_unique<Snapshot>(Snapshot{values_, model_->clone(), state_, tick_, start_tick_, outputs_stale_});
  if (*out) {
    **out = std::move(*s);  // the standard lets a master pass a state to be overwritten
  } else {
    *out = s.release();
  }
  return Status::kOK;
}

Status Slave::set_state(const Snapshot* s) {
  if (!s) return refuse("setFMUstate: null state");
  values_ = s->values;
  model_ = s->model->clone();
  state_ = s->state;
  tick_ = s->tick;
  start_tick_ = s->start_tick;
  outputs_stale_ = s->outputs_stale;
  return Status::kOK;
}

void Slave::free_state(Snapshot* s) { delete s; }

}  // namespace quadcosim::fmi::exported
