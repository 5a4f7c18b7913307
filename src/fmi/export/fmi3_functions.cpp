// The FMI 3.0 API of the exported FMU: every function of fmi3.h, over exported::Slave. Co-Simulation
// without event mode: after fmi3ExitInitializationMode the instance is in Step Mode. Float64, Int32,
// Boolean and String variables are exchanged; the other types, clocks, Model Exchange, Scheduled
// Execution, configuration mode, derivatives and dependencies answer fmi3Error with a logged message.
// FMU states can be got, set and freed, not serialized. No exception leaves a function.
#include <memory>
#include <string>

#include "fmi/api/fmi3.h"
#include "fmi/export/fmu_config.hpp"
#include "fmi/export/slave.hpp"

namespace {

using quadcosim::fmi::exported::Slave;
using quadcosim::fmi::exported::Status;

struct Instance {
  std::string name;
  fmi3InstanceEnvironment environment = nullptr;
  fmi3LogMessageCallback log_message = nullptr;
  std::unique_ptr<Slave> slave;

  void log(fmi3Status status, const char* category, const std::string& message) const {
    if (log_message) log_message(environment, status, category, message.c_str());
  }
};

fmi3Status to_fmi3(Status s) { return static_cast<fmi3Status>(static_cast<int>(s)); }

/// Runs `f` on the instance: a null instance is an error, an exception is logged as one.
template <class F>
fmi3Status call(fmi3Instance instance, const char* function, F&& f) {
  auto* inst = static_cast<Instance*>(instance);
  if (!inst) return fmi3Error;
  try {
    return to_fmi3(f(*inst->slave));
  } catch (const std::exception& e) {
    inst->log(fmi3Error, "logStatusError", std::string(function) + ": " + e.what());
  } catch (...) {
    inst->log(fmi3Error, "logStatusError", std::string(function) + ": unknown failure");
  }
  return fmi3Error;
}

fmi3Status unsupported(fmi3Instance instance, const char* function, const std::string& why) {
  auto* inst = static_cast<Instance*>(instance);
  if (inst) inst->log(fmi3Error, "logStatusError", std::string(function) + " is not supported: " + why);
  return fmi3Error;
}

/// Get/Set of a type the FMU has no variables of: nothing to do for no value references, else an error.
fmi3Status no_such_type(fmi3Instance instance, const char* function, const char* type, size_t n) {
  if (n == 0) return instance ? fmi3OK : fmi3Error;
  return unsupported(instance, function,
                     std::string("the FMU has no ") + type + " variables (only Float64, Int32, Boolean and String)");
}

/// Scalars only: one value per value reference.
template <class F>
fmi3Status scalars(fmi3Instance instance, const char* function, size_t nvr, size_t nValues, F&& f) {
  if (nvr != nValues) {
    return unsupported(instance, function,
                       std::to_string(nvr) + " value references but " + std::to_string(nValues) +
                           " values: every variable of this FMU is a scalar");
  }
  return call(instance, function, std::forward<F>(f));
}

constexpr const char* kCoSimulationOnly = "this FMU is for co-simulation only";
constexpr const char* kNoEventMode = "this co-simulation FMU has no event mode (hasEventMode false)";
constexpr const char* kNoClocks = "the FMU has no clocks";

}  // namespace

extern "C" {

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean, size_t, const fmi3String[]) {
  return instance ? fmi3OK : fmi3Error;  // errors are always logged; there is nothing more to tell
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                          fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage) {
  if (logMessage) {
    logMessage(environment, fmi3Error, "logStatusError",
               "fmi3InstantiateModelExchange: this FMU is for co-simulation only (fmi3InstantiateCoSimulation)");
  }
  return nullptr;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                               fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback, fmi3LockPreemptionCallback,
                                               fmi3UnlockPreemptionCallback) {
  if (logMessage) {
    logMessage(environment, fmi3Error, "logStatusError",
               "fmi3InstantiateScheduledExecution: this FMU is for co-simulation only (fmi3InstantiateCoSimulation)");
  }
  return nullptr;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean, fmi3Boolean, fmi3Boolean eventModeUsed,
                                         fmi3Boolean, const fmi3ValueReference[], size_t,
                                         fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback) {
  auto inst = std::make_unique<Instance>();
  inst->name = instanceName ? instanceName : "";
  inst->environment = instanceEnvironment;
  inst->log_message = logMessage;
  const auto refuse = [&](const std::string& message) -> fmi3Instance {
    inst->log(fmi3Error, "logStatusError", "fmi3InstantiateCoSimulation: " + message);
    return nullptr;
  };
  try {
    if (!instanceName || !*instanceName) return refuse("the instance name is missing");
    if (eventModeUsed) return refuse(kNoEventMode);
    if (!resourcePath || !*resourcePath) return refuse("no resourcePath: the FMU's configuration is in its resources");
    quadcosim::fmi::FmuConfig config = quadcosim::fmi::read_config(resourcePath);
    if (config.fmi_version != quadcosim::fmi::FmiVersion::k3) {
      return refuse("this FMU is an FMI 2.0 FMU (its resources say so); instantiate it with fmi2Instantiate");
    }
    if (!instantiationToken || config.guid != instantiationToken) {
      return refuse("instantiationToken mismatch: the FMU's is '" + config.guid + "', the importer gave '" +
                    std::string(instantiationToken ? instantiationToken : "(null)") + "'");
    }
    Instance* raw = inst.get();
    inst->slave = std::make_unique<Slave>(
        std::move(config),
        [raw](Status s, const char* category, const std::string& message) { raw->log(to_fmi3(s), category, message); });
  } catch (const std::exception& e) {
    return refuse(e.what());
  } catch (...) {
    return refuse("unknown failure");
  }
  return inst.release();
}

void fmi3FreeInstance(fmi3Instance instance) { delete static_cast<Instance*>(instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean, fmi3Float64, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
  return call(instance, "fmi3EnterInitializationMode", [&](Slave& s) {
    const Status st = s.setup_experiment(startTime, stopTimeDefined ? std::optional<double>(stopTime) : std::nullopt);
    return st == Status::kOK ? s.enter_initialization() : st;
  });
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  return call(instance, "fmi3ExitInitializationMode", [](Slave& s) { return s.exit_initialization(); });
}
fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
  return unsupported(instance, "fmi3EnterEventMode", kNoEventMode);
}
fmi3Status fmi3Terminate(fmi3Instance instance) {
  return call(instance, "fmi3Terminate", [](Slave& s) { return s.terminate(); });
}
fmi3Status fmi3Reset(fmi3Instance instance) {
  return call(instance, "fmi3Reset", [](Slave& s) { return s.reset(); });
}

// ---- Values -------------------------------------------------------------------------------------

// The types the FMU has: each get and set checks one value per value reference and hands on.
#define QC_SCALARS(TYPE, GET, SET)                                                                                \
  fmi3Status fmi3Get##TYPE(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3##TYPE values[], \
                           size_t nValues) {                                                                      \
    return scalars(instance, "fmi3Get" #TYPE, nvr, nValues, [&](Slave& s) { return s.GET(vr, nvr, values); });    \
  }                                                                                                               \
  fmi3Status fmi3Set##TYPE(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,                      \
                           const fmi3##TYPE values[], size_t nValues) {                                           \
    return scalars(instance, "fmi3Set" #TYPE, nvr, nValues, [&](Slave& s) { return s.SET(vr, nvr, values); });    \
  }
QC_SCALARS(Float64, get_real, set_real)
QC_SCALARS(Int32, get_integer, set_integer)
QC_SCALARS(Boolean, get_boolean, set_boolean)
QC_SCALARS(String, get_string, set_string)
#undef QC_SCALARS

#define QC_NO_SUCH_TYPE(TYPE)                                                                                     \
  fmi3Status fmi3Get##TYPE(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, fmi3##TYPE[], size_t) { \
    return no_such_type(instance, "fmi3Get" #TYPE, #TYPE, nvr);                                                   \
  }                                                                                                               \
  fmi3Status fmi3Set##TYPE(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, const fmi3##TYPE[],     \
                           size_t) {                                                                              \
    return no_such_type(instance, "fmi3Set" #TYPE, #TYPE, nvr);                                                   \
  }
QC_NO_SUCH_TYPE(Float32)
QC_NO_SUCH_TYPE(Int8)
QC_NO_SUCH_TYPE(UInt8)
QC_NO_SUCH_TYPE(Int16)
QC_NO_SUCH_TYPE(UInt16)
QC_NO_SUCH_TYPE(UInt32)
QC_NO_SUCH_TYPE(Int64)
QC_NO_SUCH_TYPE(UInt64)
#undef QC_NO_SUCH_TYPE

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, size_t[], fmi3Binary[],
                         size_t) {
  return no_such_type(instance, "fmi3GetBinary", "Binary", nvr);
}
fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, const size_t[],
                         const fmi3Binary[], size_t) {
  return no_such_type(instance, "fmi3SetBinary", "Binary", nvr);
}
fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, fmi3Clock[]) {
  return no_such_type(instance, "fmi3GetClock", "Clock", nvr);
}
fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference[], size_t nvr, const fmi3Clock[]) {
  return no_such_type(instance, "fmi3SetClock", "Clock", nvr);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference, size_t*) {
  return unsupported(instance, "fmi3GetNumberOfVariableDependencies", "no dependency information is provided");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference, size_t[], fmi3ValueReference[],
                                       size_t[], fmi3DependencyKind[], size_t) {
  return unsupported(instance, "fmi3GetVariableDependencies", "no dependency information is provided");
}

// ---- FMU state ----------------------------------------------------------------------------------

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState* FMUState) {
  return call(instance, "fmi3GetFMUState",
              [&](Slave& s) { return s.get_state(reinterpret_cast<Slave::Snapshot**>(FMUState)); });
}
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
  return call(instance, "fmi3SetFMUState",
              [&](Slave& s) { return s.set_state(static_cast<Slave::Snapshot*>(FMUState)); });
}
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* FMUState) {
  if (!instance) return fmi3Error;
  if (FMUState) {
    Slave::free_state(static_cast<Slave::Snapshot*>(*FMUState));
    *FMUState = nullptr;
  }
  return fmi3OK;
}
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState, size_t*) {
  return unsupported(instance, "fmi3SerializedFMUStateSize", "the FMU state cannot be serialized");
}
fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState, fmi3Byte[], size_t) {
  return unsupported(instance, "fmi3SerializeFMUState", "the FMU state cannot be serialized");
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte[], size_t, fmi3FMUState*) {
  return unsupported(instance, "fmi3DeserializeFMUState", "the FMU state cannot be serialized");
}

// ---- Derivatives, configuration, clocks, discrete states ----------------------------------------

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference[], size_t,
                                        const fmi3ValueReference[], size_t, const fmi3Float64[], size_t, fmi3Float64[],
                                        size_t) {
  return unsupported(instance, "fmi3GetDirectionalDerivative", "no directional derivatives");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference[], size_t,
                                    const fmi3ValueReference[], size_t, const fmi3Float64[], size_t, fmi3Float64[],
                                    size_t) {
  return unsupported(instance, "fmi3GetAdjointDerivative", "no adjoint derivatives");
}
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
  return unsupported(instance, "fmi3EnterConfigurationMode", "the FMU has no structural parameters");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
  return unsupported(instance, "fmi3ExitConfigurationMode", "the FMU has no structural parameters");
}
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3Float64[],
                                  fmi3IntervalQualifier[]) {
  return unsupported(instance, "fmi3GetIntervalDecimal", kNoClocks);
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3UInt64[],
                                   fmi3UInt64[], fmi3IntervalQualifier[]) {
  return unsupported(instance, "fmi3GetIntervalFraction", kNoClocks);
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3Float64[]) {
  return unsupported(instance, "fmi3GetShiftDecimal", kNoClocks);
}
fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, fmi3UInt64[], fmi3UInt64[]) {
  return unsupported(instance, "fmi3GetShiftFraction", kNoClocks);
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Float64[]) {
  return unsupported(instance, "fmi3SetIntervalDecimal", kNoClocks);
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3UInt64[],
                                   const fmi3UInt64[]) {
  return unsupported(instance, "fmi3SetIntervalFraction", kNoClocks);
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Float64[]) {
  return unsupported(instance, "fmi3SetShiftDecimal", kNoClocks);
}
fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3UInt64[],
                                const fmi3UInt64[]) {
  return unsupported(instance, "fmi3SetShiftFraction", kNoClocks);
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
  return unsupported(instance, "fmi3EvaluateDiscreteStates", kNoEventMode);
}
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean*, fmi3Boolean*, fmi3Boolean*, fmi3Boolean*,
                                    fmi3Boolean*, fmi3Float64*) {
  return unsupported(instance, "fmi3UpdateDiscreteStates", kNoEventMode);
}

// ---- Model Exchange -----------------------------------------------------------------------------

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
  return unsupported(instance, "fmi3EnterContinuousTimeMode", kCoSimulationOnly);
}
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean, fmi3Boolean*, fmi3Boolean*) {
  return unsupported(instance, "fmi3CompletedIntegratorStep", kCoSimulationOnly);
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64) {
  return unsupported(instance, "fmi3SetTime", kCoSimulationOnly);
}
fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3SetContinuousStates", kCoSimulationOnly);
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3GetContinuousStateDerivatives", kCoSimulationOnly);
}
fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3GetEventIndicators", kCoSimulationOnly);
}
fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3GetContinuousStates", kCoSimulationOnly);
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3GetNominalsOfContinuousStates", kCoSimulationOnly);
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t*) {
  return unsupported(instance, "fmi3GetNumberOfEventIndicators", kCoSimulationOnly);
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t*) {
  return unsupported(instance, "fmi3GetNumberOfContinuousStates", kCoSimulationOnly);
}

// ---- Co-Simulation ------------------------------------------------------------------------------

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
  return unsupported(instance, "fmi3EnterStepMode",
                     std::string(kNoEventMode) + "; the instance is in Step Mode after fmi3ExitInitializationMode");
}
fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference[], size_t, const fmi3Int32[],
                                    fmi3Float64[], size_t) {
  return unsupported(instance, "fmi3GetOutputDerivatives", "no output derivatives (maxOutputDerivativeOrder 0)");
}
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean, fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                      fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime) {
  return call(instance, "fmi3DoStep", [&](Slave& s) {
    const Status st = s.do_step(currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (earlyReturn) *earlyReturn = false;
    if (lastSuccessfulTime) *lastSuccessfulTime = s.time_s();
    return st;
  });
}

// ---- Scheduled Execution ------------------------------------------------------------------------

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference, fmi3Float64) {
  return unsupported(instance, "fmi3ActivateModelPartition", kCoSimulationOnly);
}

}  // extern "C"
