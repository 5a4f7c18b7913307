// The FMI 2.0 API of the exported FMU: every function of fmi2.h (common, Co-Simulation and Model
// Exchange, so that an importer resolving every symbol loads the library), over exported::Slave.
// Co-Simulation only: Model Exchange functions, directional and input/output derivatives, cancelStep
// and the asynchronous status calls answer fmi2Error with a logged message. FMU states can be got,
// set and freed (canGetAndSetFMUstate), not serialized. No exception leaves a function.
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fmi/api/fmi2.h"
#include "fmi/export/fmu_config.hpp"
#include "fmi/export/slave.hpp"

namespace {

using quadcosim::fmi::exported::Slave;
using quadcosim::fmi::exported::Status;

struct Instance {
  std::string name;
  fmi2CallbackFunctions callbacks{};
  std::unique_ptr<Slave> slave;

  void log(fmi2Status status, const char* category, const std::string& message) const {
    if (callbacks.logger) {
      // The message is a format: pass it as an argument so a '%' in it is printed, not interpreted.
      callbacks.logger(callbacks.componentEnvironment, name.c_str(), status, category, "%s", message.c_str());
    }
  }
};

fmi2Status to_fmi2(Status s) { return static_cast<fmi2Status>(static_cast<int>(s)); }

/// Runs `f` on the instance: a null instance is an error, an exception is logged as one.
template <class F>
fmi2Status call(fmi2Component c, const char* function, F&& f) {
  auto* inst = static_cast<Instance*>(c);
  if (!inst) return fmi2Error;
  try {
    return to_fmi2(f(*inst->slave));
  } catch (const std::exception& e) {
    inst->log(fmi2Error, "logStatusError", std::string(function) + ": " + e.what());
  } catch (...) {
    inst->log(fmi2Error, "logStatusError", std::string(function) + ": unknown failure");
  }
  return fmi2Error;
}

fmi2Status unsupported(fmi2Component c, const char* function, const char* why) {
  auto* inst = static_cast<Instance*>(c);
  if (inst) inst->log(fmi2Error, "logStatusError", std::string(function) + " is not supported: " + why);
  return fmi2Error;
}

constexpr const char* kCoSimulationOnly = "this FMU is for co-simulation only (no model exchange)";

/// The directory of a file: URI ("file:///a/b", "file:/a/b", "file://localhost/a/b"), %-escapes decoded.
bool uri_to_path(const char* uri, std::string& path, std::string& error) {
  std::string u = uri ? uri : "";
  if (u.rfind("file:", 0) != 0) {
    error = "fmuResourceLocation '" + u + "' is not a file: URI";
    return false;
  }
  u = u.substr(5);
  if (u.rfind("//", 0) == 0) {  // an authority: empty or localhost
    const auto slash = u.find('/', 2);
    const std::string host = u.substr(2, slash == std::string::npos ? std::string::npos : slash - 2);
    if (!host.empty() && host != "localhost") {
      error = "fmuResourceLocation '" + std::string(uri) + "' names a host ('" + host + "'), not this machine";
      return false;
    }
    u = slash == std::string::npos ? "/" : u.substr(slash);
  }
  path.clear();
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (u[i] == '%' && i + 2 < u.size() + 0 && std::isxdigit(static_cast<unsigned char>(u[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(u[i + 2]))) {
      path += static_cast<char>(std::stoi(u.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      path += u[i];
    }
  }
  return true;
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean, size_t, const fmi2String[]) {
  return c ? fmi2OK : fmi2Error;  // errors are always logged; there is nothing more to tell
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions, fmi2Boolean,
                              fmi2Boolean) {
  if (!functions) return nullptr;
  auto inst = std::make_unique<Instance>();
  inst->name = instanceName ? instanceName : "";
  inst->callbacks = *functions;
  const auto refuse = [&](const std::string& message) -> fmi2Component {
    inst->log(fmi2Error, "logStatusError", "fmi2Instantiate: " + message);
    return nullptr;
  };
  try {
    if (!instanceName || !*instanceName) return refuse("the instance name is missing");
    if (fmuType != fmi2CoSimulation) return refuse(kCoSimulationOnly);
    std::string dir, error;
    if (!uri_to_path(fmuResourceLocation, dir, error)) return refuse(error);
    quadcosim::fmi::FmuConfig config = quadcosim::fmi::read_config(dir);
    if (config.fmi_version != quadcosim::fmi::FmiVersion::k2) {
      return refuse(
          "this FMU is an FMI 3.0 FMU (its resources say so); instantiate it with fmi3InstantiateCoSimulation");
    }
    if (!fmuGUID || config.guid != fmuGUID) {
      return refuse("GUID mismatch: the FMU's is '" + config.guid + "', the importer gave '" +
                    std::string(fmuGUID ? fmuGUID : "(null)") + "'");
    }
    Instance* raw = inst.get();
    inst->slave = std::make_unique<Slave>(
        std::move(config),
        [raw](Status s, const char* category, const std::string& message) { raw->log(to_fmi2(s), category, message); });
  } catch (const std::exception& e) {
    return refuse(e.what());
  } catch (...) {
    return refuse("unknown failure");
  }
  return inst.release();
}

void fmi2FreeInstance(fmi2Component c) { delete static_cast<Instance*>(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean, fmi2Real, fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
  return call(c, "fmi2SetupExperiment", [&](Slave& s) {
    return s.setup_experiment(startTime, stopTimeDefined ? std::optional<double>(stopTime) : std::nullopt);
  });
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return call(c, "fmi2EnterInitializationMode", [](Slave& s) { return s.enter_initialization(); });
}
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return call(c, "fmi2ExitInitializationMode", [](Slave& s) { return s.exit_initialization(); });
}
fmi2Status fmi2Terminate(fmi2Component c) {
  return call(c, "fmi2Terminate", [](Slave& s) { return s.terminate(); });
}
fmi2Status fmi2Reset(fmi2Component c) {
  return call(c, "fmi2Reset", [](Slave& s) { return s.reset(); });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
  return call(c, "fmi2GetReal", [&](Slave& s) { return s.get_real(vr, nvr, value); });
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
  return call(c, "fmi2GetInteger", [&](Slave& s) { return s.get_integer(vr, nvr, value); });
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
  return call(c, "fmi2GetBoolean", [&](Slave& s) {
    std::unique_ptr<bool[]> b(new bool[nvr]);
    const Status st = s.get_boolean(vr, nvr, b.get());
    if (st == Status::kOK) {
      for (size_t i = 0; i < nvr; ++i) value[i] = b[i] ? fmi2True : fmi2False;
    }
    return st;
  });
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
  return call(c, "fmi2GetString", [&](Slave& s) { return s.get_string(vr, nvr, value); });
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
  return call(c, "fmi2SetReal", [&](Slave& s) { return s.set_real(vr, nvr, value); });
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
  return call(c, "fmi2SetInteger", [&](Slave& s) { return s.set_integer(vr, nvr, value); });
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
  return call(c, "fmi2SetBoolean", [&](Slave& s) {
    std::unique_ptr<bool[]> b(new bool[nvr]);
    for (size_t i = 0; i < nvr && value; ++i) b[i] = value[i] != fmi2False;
    return s.set_boolean(vr, nvr, b.get());
  });
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
  return call(c, "fmi2SetString", [&](Slave& s) { return s.set_string(vr, nvr, value); });
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* FMUstate) {
  return call(c, "fmi2GetFMUstate",
              [&](Slave& s) { return s.get_state(reinterpret_cast<Slave::Snapshot**>(FMUstate)); });
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
  return call(c, "fmi2SetFMUstate", [&](Slave& s) { return s.set_state(static_cast<Slave::Snapshot*>(FMUstate)); });
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* FMUstate) {
  if (!c) return fmi2Error;
  if (FMUstate) {
    Slave::free_state(static_cast<Slave::Snapshot*>(*FMUstate));
    *FMUstate = nullptr;
  }
  return fmi2OK;
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate, size_t*) {
  return unsupported(c, "fmi2SerializedFMUstateSize",
                     "the FMU state cannot be serialized (canSerializeFMUstate false)");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate, fmi2Byte[], size_t) {
  return unsupported(c, "fmi2SerializeFMUstate", "the FMU state cannot be serialized (canSerializeFMUstate false)");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte[], size_t, fmi2FMUstate*) {
  return unsupported(c, "fmi2DeSerializeFMUstate", "the FMU state cannot be serialized (canSerializeFMUstate false)");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2ValueReference[],
                                        size_t, const fmi2Real[], fmi2Real[]) {
  return unsupported(c, "fmi2GetDirectionalDerivative",
                     "no directional derivatives (providesDirectionalDerivative false)");
}

// Model Exchange.
fmi2Status fmi2EnterEventMode(fmi2Component c) { return unsupported(c, "fmi2EnterEventMode", kCoSimulationOnly); }
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo*) {
  return unsupported(c, "fmi2NewDiscreteStates", kCoSimulationOnly);
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
  return unsupported(c, "fmi2EnterContinuousTimeMode", kCoSimulationOnly);
}
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean, fmi2Boolean*, fmi2Boolean*) {
  return unsupported(c, "fmi2CompletedIntegratorStep", kCoSimulationOnly);
}
fmi2Status fmi2SetTime(fmi2Component c, fmi2Real) { return unsupported(c, "fmi2SetTime", kCoSimulationOnly); }
fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real[], size_t) {
  return unsupported(c, "fmi2SetContinuousStates", kCoSimulationOnly);
}
fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real[], size_t) {
  return unsupported(c, "fmi2GetDerivatives", kCoSimulationOnly);
}
fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real[], size_t) {
  return unsupported(c, "fmi2GetEventIndicators", kCoSimulationOnly);
}
fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real[], size_t) {
  return unsupported(c, "fmi2GetContinuousStates", kCoSimulationOnly);
}
fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real[], size_t) {
  return unsupported(c, "fmi2GetNominalsOfContinuousStates", kCoSimulationOnly);
}

// Co-Simulation.
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                       const fmi2Real[]) {
  return unsupported(c, "fmi2SetRealInputDerivatives", "inputs are held over a step (canInterpolateInputs false)");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                        fmi2Real[]) {
  return unsupported(c, "fmi2GetRealOutputDerivatives", "no output derivatives (maxOutputDerivativeOrder 0)");
}
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean) {
  return call(c, "fmi2DoStep", [&](Slave& s) { return s.do_step(currentCommunicationPoint, communicationStepSize); });
}
fmi2Status fmi2CancelStep(fmi2Component c) {
  return unsupported(c, "fmi2CancelStep", "doStep always completes before it returns (never fmi2Pending)");
}
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind, fmi2Status*) {
  return unsupported(c, "fmi2GetStatus", "doStep always completes before it returns (never fmi2Pending)");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
  if (s != fmi2LastSuccessfulTime || !value) {
    return unsupported(c, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is answered");
  }
  return call(c, "fmi2GetRealStatus", [&](Slave& slave) {
    *value = slave.time_s();
    return Status::kOK;
  });
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind, fmi2Integer*) {
  return unsupported(c, "fmi2GetIntegerStatus", "there is no integer status");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
  if (s != fmi2Terminated || !value) return unsupported(c, "fmi2GetBooleanStatus", "only fmi2Terminated is answered");
  return call(c, "fmi2GetBooleanStatus", [&](Slave&) {
    *value = fmi2False;  // the FMU never asks to end the simulation
    return Status::kOK;
  });
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind, fmi2String*) {
  return unsupported(c, "fmi2GetStringStatus", "doStep always completes before it returns (never fmi2Pending)");
}

}  // extern "C"
