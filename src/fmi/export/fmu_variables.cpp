// The FMI variables an FMU's configuration gives it (describe(): what modelDescription.xml lists).
#include <array>
#include <charconv>

#include "controllers/registry.hpp"
#include "fmi/export/fmu_config.hpp"
#include "fmi/quadrotor_variables.hpp"
#include "model/attitude.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::fmi {

static_assert(names::kRotorNames == static_cast<std::size_t>(model::kMaxRotors), "one FMU variable name per rotor");

namespace {

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round trip
  return std::string(buf, r.ptr);
}

struct Builder {
  ModelDescription& md;

  Variable& add(std::string_view name, Causality causality, Variability variability, std::string_view unit,
                std::string description) {
    Variable v;
    v.name = std::string(name);
    v.vr = static_cast<ValueReference>(md.variables.size());
    v.causality = causality;
    v.variability = variability;
    v.unit = std::string(unit);
    v.description = std::move(description);
    md.variables.push_back(std::move(v));
    if (causality == Causality::kOutput) {
      // No direct feedthrough: outputs are computed at the end of doStep, from the inputs held over
      // the step, so a plant and a controller FMU coupled both ways form no algebraic loop.
      md.variables.back().dependencies.emplace();
      md.outputs.push_back(md.variables.size() - 1);
    }
    return md.variables.back();
  }
  void input(std::string_view name, std::string_view unit, std::string description, double start) {
    add(name, Causality::kInput, Variability::kContinuous, unit, std::move(description)).start = number_text(start);
  }
  void output(std::string_view name, Variability variability, std::string_view unit, std::string description) {
    add(name, Causality::kOutput, variability, unit, std::move(description)).initial = Initial::kCalculated;
  }
  Variable& parameter(std::string_view name, Variability variability, std::string_view unit, std::string description,
                      std::string start) {
    Variable& v = add(name, Causality::kParameter, variability, unit, std::move(description));
    v.initial = Initial::kExact;
    v.start = std::move(start);
    return v;
  }
  template <std::size_t N>
  void inputs(const std::array<std::string_view, N>& names, std::string_view unit, const std::string& what,
              const Eigen::Matrix<double, static_cast<int>(N), 1>& start) {
    for (std::size_t i = 0; i < N; ++i) input(names[i], unit, what, start[static_cast<Eigen::Index>(i)]);
  }
  template <std::size_t N>
  void outputs(const std::array<std::string_view, N>& names, Variability variability, std::string_view unit,
               const std::string& what) {
    for (auto n : names) output(n, variability, unit, what);
  }
};

Eigen::Vector4d wxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

constexpr std::string_view kCommandInput =
    "rotor speed command, held over the step; clamped to [omega_min, omega_max]; NaN/Inf refused";
constexpr std::string_view kCommandOutput = "rotor speed command of the latest control step (0 before the first step)";
constexpr std::string_view kSpeedOutput = "rotor speeds reached (after the motors' lag)";
constexpr std::string_view kSpeedInitial = "rotor speeds (and the command before the first one is set)";

void plant_variables(const FmuConfig& c, Builder& b) {
  for (std::size_t i = 0; i < 4; ++i) {
    b.input(names::kOmegaCmd[i], "rad/s", std::string(kCommandInput),
            c.initial.omega_rad_s[static_cast<Eigen::Index>(i)]);
  }
  const Variability cont = Variability::kContinuous;
  b.outputs(names::kPosition, cont, "m", "position, world frame (z up)");
  b.outputs(names::kVelocity, cont, "m/s", "velocity, world frame");
  b.outputs(names::kAttitude, cont, "1", "attitude quaternion body to world, w x y z");
  b.outputs(names::kEuler, cont, "rad", "roll, pitch, yaw (Z-Y-X Euler angles of q_WB)");
  b.outputs(names::kRates, cont, "rad/s", "body angular velocity");
  b.outputs(names::kSpecificForce, cont, "m/s2", "specific force, body frame (what an accelerometer reads)");
  b.outputs(names::kRotorSpeed, cont, "rad/s", std::string(kSpeedOutput));
  // The extra sensors the scenario configures: each column of the newest sample, held between samples.
  sensors::for_each_configured(c.realism.extra_sensors, [&]<class Kind>(const typename Kind::Config&) {
    for (const auto& col : Kind::kColumns) {
      for (int i = 0; i < col.width; ++i) {
        b.output(names::sensor_variable(Kind::kName, col.name, col.width, i), Variability::kDiscrete, col.unit,
                 std::string(Kind::kName) + ": " + std::string(col.description) + " (the newest sample)");
      }
    }
  });

  const Variability fixed = Variability::kFixed;
  for (const auto& p : model::vehicle_parameters()) {
    if (p.kind != model::VehicleParameter::Kind::kNumber) continue;
    Variable& v = b.parameter(std::string(names::kVehiclePrefix) + std::string(p.name), fixed, p.unit,
                              std::string(p.meaning) + ", in " + p.range.text() + " (takes effect at initialisation)",
                              number_text(p.get(c.vehicle)));
    v.min = p.range.min;
    v.max = p.range.max;
  }
  const std::string pre(names::kInitialPrefix);
  const model::State& x = c.initial;
  auto initial = [&](const auto& names, std::string_view unit, const std::string& what, const auto& values) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      b.parameter(pre + std::string(names[i]), fixed, unit, "initial " + what,
                  number_text(values[static_cast<Eigen::Index>(i)]));
    }
  };
  initial(names::kPosition, "m", "position", x.p_W);
  initial(names::kVelocity, "m/s", "velocity", x.v_W);
  initial(names::kAttitude, "1", "attitude quaternion (w x y z, unit norm)", wxyz(x.q_WB));
  initial(names::kRates, "rad/s", "body angular velocity", x.w_B);
  initial(names::kRotorSpeed, "rad/s", std::string(kSpeedInitial), x.omega_rad_s);

  auto flag = [&](std::string_view name, bool on, std::string what) {
    b.parameter(name, fixed, "", std::move(what), on ? "true" : "false").type = VariableType::kBoolean;
  };
  const auto& r = c.realism;
  flag("realism.wind", r.wind.active(), "wind and gusts as configured act on the vehicle");
  flag("realism.rotor_faults", !r.faults.empty(), "the configured rotor faults happen at their ticks");
  const bool sensors = [&] {
    sim::RealismConfig s = r;
    s.wind = {};
    s.faults.clear();
    return s.active();
  }();
  flag("realism.sensor_noise", sensors,
       "outputs p_W, v_W, q_WB, euler, w_B, f_B are the sensors' latest samples (noise, bias, rate, latency as "
       "configured; euler from the IMU's attitude) instead of the true values; omega stays true");
  Variable& seed =
      b.parameter("realism.seed", fixed, "", "seed of every random stream (noise, gusts)", std::to_string(r.seed));
  seed.type = VariableType::kInteger;
  seed.min = 0;
  seed.max = std::numeric_limits<std::int32_t>::max();
  if (r.seed > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    throw FmuError("realism.seed " + std::to_string(r.seed) + " does not fit an FMI Integer (at most 2147483647)");
  }
}

void controller_variables(const FmuConfig& c, Builder& b) {
  const model::Quadrotor quad(c.vehicle);
  const model::Outputs y = quad.outputs(0.0, c.initial, quad.rotor_input(c.initial.omega_rad_s));
  b.inputs(names::kPosition, "m", "measured position, world frame", y.p_W);
  b.inputs(names::kVelocity, "m/s", "measured velocity, world frame", y.v_W);
  b.inputs(names::kAttitude, "1", "measured attitude quaternion body to world, w x y z", wxyz(y.q_WB));
  b.inputs(names::kRates, "rad/s", "measured body angular velocity", y.w_B);
  b.inputs(names::kSpecificForce, "m/s2", "measured specific force, body frame", y.specific_force_B);
  // The reference inputs start at the reference the FMU flies at t = 0: the setpoint, or the
  // trajectory's first point (which they are then only used for with ref.external).
  const control::Setpoint& s = c.setpoint;
  trajectory::FlatOutput start;
  start.p_W = s.p_des_W;
  start.yaw_rad = s.yaw_des_rad;
  double roll = s.roll_des_rad, pitch = s.pitch_des_rad;
  std::string used;
  if (c.trajectory) {
    try {
      start = trajectory::make_trajectory(*c.trajectory)->at(0.0);
    } catch (const std::invalid_argument& e) {
      throw FmuError(std::string("trajectory: ") + e.what());
    }
    roll = pitch = 0.0;
    used = " (used when ref.external is true; otherwise the FMU's trajectory is the reference)";
  }
  b.inputs(
      names::kRefPosition, "m",
      (c.trajectory ? std::string("reference position") : "reference position (attitude mode: only z is held)") + used,
      start.p_W);
  b.inputs(names::kRefVelocity, "m/s", "reference velocity" + used, start.v_W);
  b.inputs(names::kRefAcceleration, "m/s2", "reference acceleration" + used, start.a_W);
  const std::array<std::string_view, 3> jerk = {"ref.j_W[1]", "ref.j_W[2]", "ref.j_W[3]"};
  b.inputs(jerk, "m/s3", "reference jerk" + used, start.j_W);
  b.input(names::kRefYaw, "rad", "reference yaw" + used, start.yaw_rad);
  b.input("ref.yaw_rate", "rad/s", "reference yaw rate" + used, start.yaw_rate_rad_s);
  b.input("ref.roll", "rad", c.trajectory ? "unused (position mode)" : "roll setpoint (attitude mode)", roll);
  b.input("ref.pitch", "rad", c.trajectory ? "unused (position mode)" : "pitch setpoint (attitude mode)", pitch);
  b.outputs(names::kOmegaCmd, Variability::kDiscrete, "rad/s", std::string(kCommandOutput));

  const control::ControllerConfig cc = controllers::make_config(c.controller_type, c.vehicle);
  std::unique_ptr<control::Controller> ctl = cc.controller->clone();
  if (std::string err = ctl->set_parameters(c.controller_parameters); !err.empty()) {
    throw FmuError("controller '" + c.controller_type + "': " + err);
  }
  // What the controller tracks and its own figures, under the names a controller that decides rotor
  // speeds reports them by (control::ReportedOutputs): an importer shows its attitude setpoint, tilt
  // flag and figures as quadcosim shows the native controller's.
  for (const std::string_view name : names::kReportedAttitude) {
    b.output(name, Variability::kDiscrete, "rad",
             "attitude the latest control step tracked (Z-Y-X angles of its desired attitude; 0 before the first "
             "step)");
  }
  b.output(names::kTiltSaturated, Variability::kDiscrete, "1",
           "1 when the latest control step's tilt limit cut the attitude it asked for, else 0");
  for (const std::string& name : ctl->output_names()) {
    b.output(name, Variability::kDiscrete, "", "the controller's own figure " + name + " at the latest control step");
  }

  if (c.trajectory) {
    b.parameter(names::kRefExternal, Variability::kFixed, "",
                "false: the reference is the trajectory this FMU carries (" +
                    trajectory::make_trajectory(*c.trajectory)->describe() +
                    "), at the FMU's own time; true: the inputs ref.* are, in position mode (takes effect at "
                    "initialisation)",
                "false")
        .type = VariableType::kBoolean;
  }

  for (const control::ParameterSpec& p : ctl->parameters()) {
    const control::ParameterValue value = *ctl->get_parameter(p.name);
    const std::string name = std::string(names::kControllerPrefix) + std::string(p.name);
    if (p.is_choice()) {
      std::string choices;
      for (auto ch : p.choices) choices += (choices.empty() ? "" : ", ") + std::string(ch);
      b.parameter(name, Variability::kTunable, "", std::string(p.description) + " (one of: " + choices + ")",
                  std::get<std::string>(value))
          .type = VariableType::kString;
    } else {
      Variable& v = b.parameter(name, Variability::kTunable, p.unit, std::string(p.description),
                                number_text(std::get<double>(value)));
      v.min = p.min;
      v.max = p.max;
    }
  }
}

/// Rotors 5..N of a vehicle with more than four: after every other variable, so that each variable a
/// quadrotor's FMU has keeps its value reference (an importer that knows the quadrotor's numbers finds
/// them unchanged). The plant's commands, speeds and initial speeds; the controller's commands.
void rotors_beyond_four(const FmuConfig& c, Builder& b) {
  const auto n = static_cast<std::size_t>(c.vehicle.rotor_count);
  const std::string pre(names::kInitialPrefix);
  if (c.kind == FmuKind::kPlant) {
    for (std::size_t i = 4; i < n; ++i) {
      b.input(names::kOmegaCmdAll[i], "rad/s", std::string(kCommandInput),
              c.initial.omega_rad_s[static_cast<Eigen::Index>(i)]);
    }
    for (std::size_t i = 4; i < n; ++i) {
      b.output(names::kRotorSpeedAll[i], Variability::kContinuous, "rad/s", std::string(kSpeedOutput));
    }
    for (std::size_t i = 4; i < n; ++i) {
      b.parameter(pre + std::string(names::kRotorSpeedAll[i]), Variability::kFixed, "rad/s",
                  "initial " + std::string(kSpeedInitial),
                  number_text(c.initial.omega_rad_s[static_cast<Eigen::Index>(i)]));
    }
  } else {
    for (std::size_t i = 4; i < n; ++i) {
      b.output(names::kOmegaCmdAll[i], Variability::kDiscrete, "rad/s", std::string(kCommandOutput));
    }
  }
}

}  // namespace

ModelDescription describe(const FmuConfig& c) {
  const int rotors = c.vehicle.rotor_count;
  if (rotors < model::kMinRotors || rotors > model::kMaxRotors) {
    throw FmuError("vehicle.rotor_count " + std::to_string(rotors) + ": an FMU carries 4 to 8 rotors");
  }
  if (c.initial.omega_rad_s.size() != rotors) {
    throw FmuError("initial.omega has " + std::to_string(c.initial.omega_rad_s.size()) +
                   " rotor speeds; the vehicle has " + std::to_string(rotors) + " rotors");
  }
  ModelDescription md;
  md.version = c.fmi_version;
  md.fmi_version = c.fmi_version == FmiVersion::k2 ? "2.0" : "3.0";
  const bool plant = c.kind == FmuKind::kPlant;
  md.model_name = plant ? "quadcosim plant" : "quadcosim controller";
  if (rotors == 4) {
    md.description = plant ? "quadcosim's 6-DOF quadrotor plant (integer-tick RK4), co-simulation"
                           : "quadcosim's '" + c.controller_type + "' flight controller, co-simulation";
  } else {
    const std::string vehicle =
        std::to_string(rotors) + " rotors, layout " + std::string(model::to_string(c.vehicle.layout));
    md.description = plant
                         ? "quadcosim's 6-DOF multirotor plant (" + vehicle + "; integer-tick RK4), co-simulation"
                         : "quadcosim's '" + c.controller_type + "' flight controller (" + vehicle + "), co-simulation";
  }
  md.guid = c.guid;
  md.generation_tool = "quadcosim";
  md.model_identifier = std::string(model_identifier(c.kind));
  md.can_handle_variable_step = false;
  md.can_be_instantiated_only_once_per_process = false;
  md.can_get_and_set_fmu_state = true;  // fmi2GetFMUstate/SetFMUstate/FreeFMUstate (not serialisation)
  const std::int64_t period_ns = plant ? c.plant_period_ns : c.plant_period_ns * c.controller_divider;
  md.start_time = 0.0;
  md.stop_time = c.stop_time_s;
  md.step_size = static_cast<double>(period_ns) / 1e9;

  Builder b{md};
  b.add("time", Causality::kIndependent, Variability::kContinuous, "s", "simulated time");
  if (plant) {
    plant_variables(c, b);
  } else {
    controller_variables(c, b);
  }
  Variable& period = b.add("period", Causality::kLocal, Variability::kConstant, "s",
                           "the FMU's period: every communication step is a whole number of them");
  period.initial = Initial::kExact;
  period.start = number_text(static_cast<double>(period_ns) / 1e9);
  rotors_beyond_four(c, b);
  return md;
}

}  // namespace quadcosim::fmi
