#include "fmi/export/slave.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>

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
      v.number[var.vr] = std::strtod(var.start->c_str(), nullptr);  // shortest round-trip text: exact
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

std::unique_ptr<Model> make_model(const FmuConfig& config, const ModelDescription& md) {
  return config.kind == FmuKind::kPlant ? make_plant_model(config, md) : make_controller_model(config, md);
}

Slave::Slave(FmuConfig config, Log log) : config_(std::move(config)), md_(describe(config_)), log_(std::move(log)) {
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

Status Slave::get_numbers(const ValueReference* vr, std::size_t n, VariableType type,
                          const std::function<void(std::size_t, double)>& out) {
  if (state_ == State::kInstantiated) {
    return refuse(std::string("get") + std::string(type_name(type)) + " is not allowed before enterInitializationMode");
  }
  if (n > 0 && (!vr)) return refuse("get" + std::string(type_name(type)) + ": null value reference array");
  for (std::size_t i = 0; i < n; ++i) {
    if (std::string err = check_vr(vr[i], type); !err.empty()) return refuse(err);
  }
  if (state_ == State::kInitialization && outputs_stale_) {
    if (Status s = refresh_outputs(); s != Status::kOK) return s;
  }
  for (std::size_t i = 0; i < n; ++i) out(i, values_.number[vr[i]]);
  return Status::kOK;
}

Status Slave::set_values(const ValueReference* vr, std::size_t n, VariableType type,
                         const std::function<std::string(std::size_t, Values&)>& put) {
  const std::string call = "set" + std::string(type_name(type));
  if (state_ == State::kTerminated || state_ == State::kError) {
    return refuse(call + " is not allowed in " + state_name(state_));
  }
  if (n > 0 && !vr) return refuse(call + ": null value reference array");
  // Every value is checked before any is applied: a refused call changes nothing.
  Values next = values_;
  std::vector<ValueReference> tunables;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::string err = check_vr(vr[i], type); !err.empty()) return refuse(call + ": " + err);
    const Variable& v = md_.variables[vr[i]];
    switch (v.causality) {
      case Causality::kInput: break;
      case Causality::kParameter:
        if (v.variability == Variability::kConstant) return refuse(call + ": " + v.name + " is a constant");
        if (v.variability == Variability::kFixed && state_ == State::kStepMode) {
          return refuse(call + ": " + v.name +
                        " is a fixed parameter: it can be set only before exitInitializationMode");
        }
        if (v.variability == Variability::kTunable) tunables.push_back(vr[i]);
        break;
      case Causality::kIndependent:
        return refuse(call + ": " + v.name + " is the independent variable (time): it cannot be set");
      default:
        return refuse(call + ": " + v.name + " is " + (v.causality == Causality::kOutput ? "an output" : "calculated") +
                      " (computed by the FMU): it cannot be set");
    }
    if (std::string err = put(i, next); !err.empty()) return refuse(call + ": " + v.name + " " + err);
    if (type != VariableType::kString) {
      const double x = next.number[vr[i]];
      if ((v.min && x < *v.min) || (v.max && x > *v.max)) {
        return refuse(call + ": " + v.name + " = " + number_text(x) + " is outside [" +
                      number_text(v.min.value_or(-HUGE_VAL)) + ", " + number_text(v.max.value_or(HUGE_VAL)) + "]");
      }
    }
  }
  if (!tunables.empty()) {
    if (std::string err = model_->set_tunable(tunables, next); !err.empty()) return refuse(call + ": " + err);
  }
  values_ = std::move(next);
  if (state_ == State::kInitialization) outputs_stale_ = true;
  return Status::kOK;
}

Status Slave::get_real(const ValueReference* vr, std::size_t n, double* values) {
  return get_numbers(vr, n, VariableType::kReal, [&](std::size_t i, double x) { values[i] = x; });
}

Status Slave::get_integer(const ValueReference* vr, std::size_t n, std::int32_t* values) {
  return get_numbers(vr, n, VariableType::kInteger,
                     [&](std::size_t i, double x) { values[i] = static_cast<std::int32_t>(x); });
}

Status Slave::get_boolean(const ValueReference* vr, std::size_t n, bool* values) {
  return get_numbers(vr, n, VariableType::kBoolean, [&](std::size_t i, double x) { values[i] = x != 0.0; });
}

Status Slave::get_string(const ValueReference* vr, std::size_t n, const char** values) {
  if (state_ == State::kInstantiated) return refuse("getString is not allowed before enterInitializationMode");
  if (n > 0 && !vr) return refuse("getString: null value reference array");
  for (std::size_t i = 0; i < n; ++i) {
    if (std::string err = check_vr(vr[i], VariableType::kString); !err.empty()) return refuse(err);
  }
  for (std::size_t i = 0; i < n; ++i) values[i] = values_.text[vr[i]].c_str();
  return Status::kOK;
}

Status Slave::set_real(const ValueReference* vr, std::size_t n, const double* values) {
  return set_values(vr, n, VariableType::kReal, [&](std::size_t i, Values& next) -> std::string {
    if (!std::isfinite(values[i])) return "= " + number_text(values[i]) + " refused: not a finite number";
    next.number[vr[i]] = values[i];
    return {};
  });
}

Status Slave::set_integer(const ValueReference* vr, std::size_t n, const std::int32_t* values) {
  return set_values(vr, n, VariableType::kInteger, [&](std::size_t i, Values& next) -> std::string {
    next.number[vr[i]] = values[i];
    return {};
  });
}

Status Slave::set_boolean(const ValueReference* vr, std::size_t n, const bool* values) {
  return set_values(vr, n, VariableType::kBoolean, [&](std::size_t i, Values& next) -> std::string {
    next.number[vr[i]] = values[i] ? 1.0 : 0.0;
    return {};
  });
}

Status Slave::set_string(const ValueReference* vr, std::size_t n, const char* const* values) {
  return set_values(vr, n, VariableType::kString, [&](std::size_t i, Values& next) -> std::string {
    if (!values[i]) return "refused: a null string";
    next.text[vr[i]] = values[i];
    return {};
  });
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
