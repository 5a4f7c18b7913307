/* The FMI 2.0 C API (Functional Mock-up Interface 2.0.4, Modelica Association), declared from the
 * standard's text: the platform types ("default" platform), the status and kind enumerations, the
 * callback functions, one function type per API function (fmi2DoStepTYPE, ...: what an importer
 * resolves with dlsym) and the functions themselves, as an FMU exports them (no function prefix).
 * Common functions, Model Exchange and Co-Simulation. Usable from C and C++. */
#ifndef QUADCOSIM_FMI_API_FMI2_H_
#define QUADCOSIM_FMI_API_FMI2_H_

#include <stddef.h>

#include "fmi/api/fmi_export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Platform types ---------------------------------------------------------------------------- */
#define fmi2TypesPlatform "default"
#define fmi2Version "2.0"

typedef void* fmi2Component;            /* an FMU instance */
typedef void* fmi2ComponentEnvironment; /* the importer's context, handed back to its callbacks */
typedef void* fmi2FMUstate;             /* a copy of an instance's internal state */
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean; /* fmi2True or fmi2False */
typedef char fmi2Char;
typedef const fmi2Char* fmi2String; /* NUL-terminated, UTF-8 */
typedef char fmi2Byte;

#define fmi2True 1
#define fmi2False 0

/* ---- Enumerations and structures --------------------------------------------------------------- */
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;

typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;

typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

/* The message is a printf format; the variadic arguments fill it. */
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment componentEnvironment, fmi2String instanceName,
                                   fmi2Status status, fmi2String category, fmi2String message, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t nobj, size_t size);
typedef void (*fmi2CallbackFreeMemory)(void* obj);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment componentEnvironment, fmi2Status status);

#if defined(_MSC_VER) || defined(__GNUC__)
#pragma pack(push, 8)
#endif
typedef struct {
  fmi2CallbackLogger logger;
  fmi2CallbackAllocateMemory allocateMemory;
  fmi2CallbackFreeMemory freeMemory;
  fmi2StepFinished stepFinished; /* asynchronous doStep only; may be NULL */
  fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef struct {
  fmi2Boolean newDiscreteStatesNeeded;
  fmi2Boolean terminateSimulation;
  fmi2Boolean nominalsOfContinuousStatesChanged;
  fmi2Boolean valuesOfContinuousStatesChanged;
  fmi2Boolean nextEventTimeDefined;
  fmi2Real nextEventTime;
} fmi2EventInfo;
#if defined(_MSC_VER) || defined(__GNUC__)
#pragma pack(pop)
#endif

/* ---- Function types: common functions ---------------------------------------------------------- */
typedef const char* fmi2GetTypesPlatformTYPE(void);
typedef const char* fmi2GetVersionTYPE(void);
typedef fmi2Status fmi2SetDebugLoggingTYPE(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                           const fmi2String categories[]);

typedef fmi2Component fmi2InstantiateTYPE(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                          fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn);
typedef void fmi2FreeInstanceTYPE(fmi2Component c);

typedef fmi2Status fmi2SetupExperimentTYPE(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                           fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime);
typedef fmi2Status fmi2EnterInitializationModeTYPE(fmi2Component c);
typedef fmi2Status fmi2ExitInitializationModeTYPE(fmi2Component c);
typedef fmi2Status fmi2TerminateTYPE(fmi2Component c);
typedef fmi2Status fmi2ResetTYPE(fmi2Component c);

typedef fmi2Status fmi2GetRealTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]);
typedef fmi2Status fmi2GetIntegerTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]);
typedef fmi2Status fmi2GetBooleanTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]);
typedef fmi2Status fmi2GetStringTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]);
typedef fmi2Status fmi2SetRealTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]);
typedef fmi2Status fmi2SetIntegerTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                      const fmi2Integer value[]);
typedef fmi2Status fmi2SetBooleanTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                      const fmi2Boolean value[]);
typedef fmi2Status fmi2SetStringTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                     const fmi2String value[]);

typedef fmi2Status fmi2GetFMUstateTYPE(fmi2Component c, fmi2FMUstate* FMUstate);
typedef fmi2Status fmi2SetFMUstateTYPE(fmi2Component c, fmi2FMUstate FMUstate);
typedef fmi2Status fmi2FreeFMUstateTYPE(fmi2Component c, fmi2FMUstate* FMUstate);
typedef fmi2Status fmi2SerializedFMUstateSizeTYPE(fmi2Component c, fmi2FMUstate FMUstate, size_t* size);
typedef fmi2Status fmi2SerializeFMUstateTYPE(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                             size_t size);
typedef fmi2Status fmi2DeSerializeFMUstateTYPE(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                               fmi2FMUstate* FMUstate);

typedef fmi2Status fmi2GetDirectionalDerivativeTYPE(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                                    size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                                    size_t nKnown, const fmi2Real dvKnown[], fmi2Real dvUnknown[]);

/* ---- Function types: Model Exchange ------------------------------------------------------------ */
typedef fmi2Status fmi2EnterEventModeTYPE(fmi2Component c);
typedef fmi2Status fmi2NewDiscreteStatesTYPE(fmi2Component c, fmi2EventInfo* fmi2eventInfo);
typedef fmi2Status fmi2EnterContinuousTimeModeTYPE(fmi2Component c);
typedef fmi2Status fmi2CompletedIntegratorStepTYPE(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi2Boolean* enterEventMode, fmi2Boolean* terminateSimulation);
typedef fmi2Status fmi2SetTimeTYPE(fmi2Component c, fmi2Real time);
typedef fmi2Status fmi2SetContinuousStatesTYPE(fmi2Component c, const fmi2Real x[], size_t nx);
typedef fmi2Status fmi2GetDerivativesTYPE(fmi2Component c, fmi2Real derivatives[], size_t nx);
typedef fmi2Status fmi2GetEventIndicatorsTYPE(fmi2Component c, fmi2Real eventIndicators[], size_t ni);
typedef fmi2Status fmi2GetContinuousStatesTYPE(fmi2Component c, fmi2Real x[], size_t nx);
typedef fmi2Status fmi2GetNominalsOfContinuousStatesTYPE(fmi2Component c, fmi2Real x_nominal[], size_t nx);

/* ---- Function types: Co-Simulation ------------------------------------------------------------- */
typedef fmi2Status fmi2SetRealInputDerivativesTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[], const fmi2Real value[]);
typedef fmi2Status fmi2GetRealOutputDerivativesTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[], fmi2Real value[]);
typedef fmi2Status fmi2DoStepTYPE(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentPoint);
typedef fmi2Status fmi2CancelStepTYPE(fmi2Component c);
typedef fmi2Status fmi2GetStatusTYPE(fmi2Component c, const fmi2StatusKind s, fmi2Status* value);
typedef fmi2Status fmi2GetRealStatusTYPE(fmi2Component c, const fmi2StatusKind s, fmi2Real* value);
typedef fmi2Status fmi2GetIntegerStatusTYPE(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value);
typedef fmi2Status fmi2GetBooleanStatusTYPE(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value);
typedef fmi2Status fmi2GetStringStatusTYPE(fmi2Component c, const fmi2StatusKind s, fmi2String* value);

/* ---- The exported functions -------------------------------------------------------------------- */
QUADCOSIM_FMI_EXPORT fmi2GetTypesPlatformTYPE fmi2GetTypesPlatform;
QUADCOSIM_FMI_EXPORT fmi2GetVersionTYPE fmi2GetVersion;
QUADCOSIM_FMI_EXPORT fmi2SetDebugLoggingTYPE fmi2SetDebugLogging;
QUADCOSIM_FMI_EXPORT fmi2InstantiateTYPE fmi2Instantiate;
QUADCOSIM_FMI_EXPORT fmi2FreeInstanceTYPE fmi2FreeInstance;
QUADCOSIM_FMI_EXPORT fmi2SetupExperimentTYPE fmi2SetupExperiment;
QUADCOSIM_FMI_EXPORT fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
QUADCOSIM_FMI_EXPORT fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
QUADCOSIM_FMI_EXPORT fmi2TerminateTYPE fmi2Terminate;
QUADCOSIM_FMI_EXPORT fmi2ResetTYPE fmi2Reset;
QUADCOSIM_FMI_EXPORT fmi2GetRealTYPE fmi2GetReal;
QUADCOSIM_FMI_EXPORT fmi2GetIntegerTYPE fmi2GetInteger;
QUADCOSIM_FMI_EXPORT fmi2GetBooleanTYPE fmi2GetBoolean;
QUADCOSIM_FMI_EXPORT fmi2GetStringTYPE fmi2GetString;
QUADCOSIM_FMI_EXPORT fmi2SetRealTYPE fmi2SetReal;
QUADCOSIM_FMI_EXPORT fmi2SetIntegerTYPE fmi2SetInteger;
QUADCOSIM_FMI_EXPORT fmi2SetBooleanTYPE fmi2SetBoolean;
QUADCOSIM_FMI_EXPORT fmi2SetStringTYPE fmi2SetString;
QUADCOSIM_FMI_EXPORT fmi2GetFMUstateTYPE fmi2GetFMUstate;
QUADCOSIM_FMI_EXPORT fmi2SetFMUstateTYPE fmi2SetFMUstate;
QUADCOSIM_FMI_EXPORT fmi2FreeFMUstateTYPE fmi2FreeFMUstate;
QUADCOSIM_FMI_EXPORT fmi2SerializedFMUstateSizeTYPE fmi2SerializedFMUstateSize;
QUADCOSIM_FMI_EXPORT fmi2SerializeFMUstateTYPE fmi2SerializeFMUstate;
QUADCOSIM_FMI_EXPORT fmi2DeSerializeFMUstateTYPE fmi2DeSerializeFMUstate;
QUADCOSIM_FMI_EXPORT fmi2GetDirectionalDerivativeTYPE fmi2GetDirectionalDerivative;

QUADCOSIM_FMI_EXPORT fmi2EnterEventModeTYPE fmi2EnterEventMode;
QUADCOSIM_FMI_EXPORT fmi2NewDiscreteStatesTYPE fmi2NewDiscreteStates;
QUADCOSIM_FMI_EXPORT fmi2EnterContinuousTimeModeTYPE fmi2EnterContinuousTimeMode;
QUADCOSIM_FMI_EXPORT fmi2CompletedIntegratorStepTYPE fmi2CompletedIntegratorStep;
QUADCOSIM_FMI_EXPORT fmi2SetTimeTYPE fmi2SetTime;
QUADCOSIM_FMI_EXPORT fmi2SetContinuousStatesTYPE fmi2SetContinuousStates;
QUADCOSIM_FMI_EXPORT fmi2GetDerivativesTYPE fmi2GetDerivatives;
QUADCOSIM_FMI_EXPORT fmi2GetEventIndicatorsTYPE fmi2GetEventIndicators;
QUADCOSIM_FMI_EXPORT fmi2GetContinuousStatesTYPE fmi2GetContinuousStates;
QUADCOSIM_FMI_EXPORT fmi2GetNominalsOfContinuousStatesTYPE fmi2GetNominalsOfContinuousStates;

QUADCOSIM_FMI_EXPORT fmi2SetRealInputDerivativesTYPE fmi2SetRealInputDerivatives;
QUADCOSIM_FMI_EXPORT fmi2GetRealOutputDerivativesTYPE fmi2GetRealOutputDerivatives;
QUADCOSIM_FMI_EXPORT fmi2DoStepTYPE fmi2DoStep;
QUADCOSIM_FMI_EXPORT fmi2CancelStepTYPE fmi2CancelStep;
QUADCOSIM_FMI_EXPORT fmi2GetStatusTYPE fmi2GetStatus;
QUADCOSIM_FMI_EXPORT fmi2GetRealStatusTYPE fmi2GetRealStatus;
QUADCOSIM_FMI_EXPORT fmi2GetIntegerStatusTYPE fmi2GetIntegerStatus;
QUADCOSIM_FMI_EXPORT fmi2GetBooleanStatusTYPE fmi2GetBooleanStatus;
QUADCOSIM_FMI_EXPORT fmi2GetStringStatusTYPE fmi2GetStringStatus;

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* QUADCOSIM_FMI_API_FMI2_H_ */
