/* The FMI 3.0 C API (Functional Mock-up Interface 3.0.2, Modelica Association), declared from the
 * standard's text: the platform types, the status and dependency enumerations, the callbacks, one
 * function type per API function (fmi3DoStepTYPE, ...: what an importer resolves with dlsym) and the
 * functions themselves, as an FMU exports them (no function prefix). Common functions, Model
 * Exchange, Co-Simulation and Scheduled Execution. Usable from C and C++. */
#ifndef QUADCOSIM_FMI_API_FMI3_H_
#define QUADCOSIM_FMI_API_FMI3_H_

#include <stddef.h>
#include <stdint.h>
#ifndef __cplusplus
#include <stdbool.h>
#endif

#include "fmi/api/fmi_export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Platform types ---------------------------------------------------------------------------- */
#define fmi3Version "3.0"

typedef void* fmi3Instance;            /* an FMU instance */
typedef void* fmi3InstanceEnvironment; /* the importer's context, handed back to its callbacks */
typedef void* fmi3FMUState;            /* a copy of an instance's internal state */
typedef uint32_t fmi3ValueReference;
typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char* fmi3String; /* NUL-terminated, UTF-8 */
typedef uint8_t fmi3Byte;
typedef const fmi3Byte* fmi3Binary;
typedef bool fmi3Clock; /* fmi3ClockActive or fmi3ClockInactive */

#define fmi3True true
#define fmi3False false
#define fmi3ClockActive true
#define fmi3ClockInactive false

/* ---- Enumerations and callbacks ---------------------------------------------------------------- */
typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;

typedef enum { fmi3Independent, fmi3Constant, fmi3Fixed, fmi3Tunable, fmi3Discrete, fmi3Dependent } fmi3DependencyKind;

typedef enum { fmi3IntervalNotYetKnown, fmi3IntervalUnchanged, fmi3IntervalChanged } fmi3IntervalQualifier;

/* Unlike FMI 2's logger, the message is plain text (no format, no variadic arguments). */
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment instanceEnvironment, fmi3Status status,
                                       fmi3String category, fmi3String message);
typedef void (*fmi3ClockUpdateCallback)(fmi3InstanceEnvironment instanceEnvironment);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3Float64 intermediateUpdateTime,
                                               fmi3Boolean intermediateVariableSetRequested,
                                               fmi3Boolean intermediateVariableGetAllowed,
                                               fmi3Boolean intermediateStepFinished, fmi3Boolean canReturnEarly,
                                               fmi3Boolean* earlyReturnRequested, fmi3Float64* earlyReturnTime);
typedef void (*fmi3LockPreemptionCallback)(void);
typedef void (*fmi3UnlockPreemptionCallback)(void);

/* ---- Function types: common functions ---------------------------------------------------------- */
typedef const char* fmi3GetVersionTYPE(void);
typedef fmi3Status fmi3SetDebugLoggingTYPE(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                                           const fmi3String categories[]);

/* resourcePath: an absolute directory path (ending in a separator), or NULL when the FMU has no resources. */
typedef fmi3Instance fmi3InstantiateModelExchangeTYPE(fmi3String instanceName, fmi3String instantiationToken,
                                                      fmi3String resourcePath, fmi3Boolean visible,
                                                      fmi3Boolean loggingOn,
                                                      fmi3InstanceEnvironment instanceEnvironment,
                                                      fmi3LogMessageCallback logMessage);
typedef fmi3Instance fmi3InstantiateCoSimulationTYPE(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[], size_t nRequiredIntermediateVariables,
    fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3IntermediateUpdateCallback intermediateUpdate);
typedef fmi3Instance fmi3InstantiateScheduledExecutionTYPE(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption);
typedef void fmi3FreeInstanceTYPE(fmi3Instance instance);

typedef fmi3Status fmi3EnterInitializationModeTYPE(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance, fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined, fmi3Float64 stopTime);
typedef fmi3Status fmi3ExitInitializationModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3EnterEventModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3TerminateTYPE(fmi3Instance instance);
typedef fmi3Status fmi3ResetTYPE(fmi3Instance instance);

/* Getting and setting values: nValues counts the scalar values (arrays have several per reference). */
typedef fmi3Status fmi3GetFloat32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, fmi3Float32 values[], size_t nValues);
typedef fmi3Status fmi3GetFloat64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, fmi3Float64 values[], size_t nValues);
typedef fmi3Status fmi3GetInt8TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3Int8 values[], size_t nValues);
typedef fmi3Status fmi3GetUInt8TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3UInt8 values[], size_t nValues);
typedef fmi3Status fmi3GetInt16TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Int16 values[], size_t nValues);
typedef fmi3Status fmi3GetUInt16TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3UInt16 values[], size_t nValues);
typedef fmi3Status fmi3GetInt32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Int32 values[], size_t nValues);
typedef fmi3Status fmi3GetUInt32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3UInt32 values[], size_t nValues);
typedef fmi3Status fmi3GetInt64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Int64 values[], size_t nValues);
typedef fmi3Status fmi3GetUInt64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3UInt64 values[], size_t nValues);
typedef fmi3Status fmi3GetBooleanTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, fmi3Boolean values[], size_t nValues);
typedef fmi3Status fmi3GetStringTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3String values[], size_t nValues);
typedef fmi3Status fmi3SetFloat32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, const fmi3Float32 values[], size_t nValues);
typedef fmi3Status fmi3SetFloat64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, const fmi3Float64 values[], size_t nValues);
typedef fmi3Status fmi3SetInt8TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3Int8 values[], size_t nValues);
typedef fmi3Status fmi3SetUInt8TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3UInt8 values[], size_t nValues);
typedef fmi3Status fmi3SetInt16TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int16 values[], size_t nValues);
typedef fmi3Status fmi3SetUInt16TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3UInt16 values[], size_t nValues);
typedef fmi3Status fmi3SetInt32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 values[], size_t nValues);
typedef fmi3Status fmi3SetUInt32TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3UInt32 values[], size_t nValues);
typedef fmi3Status fmi3SetInt64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int64 values[], size_t nValues);
typedef fmi3Status fmi3SetUInt64TYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3UInt64 values[], size_t nValues);
typedef fmi3Status fmi3SetBooleanTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, const fmi3Boolean values[], size_t nValues);
typedef fmi3Status fmi3SetStringTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3String values[], size_t nValues);
typedef fmi3Status fmi3GetBinaryTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, size_t valueSizes[], fmi3Binary values[], size_t nValues);
typedef fmi3Status fmi3SetBinaryTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[],
                                     size_t nValues);
typedef fmi3Status fmi3GetClockTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Clock values[]);
typedef fmi3Status fmi3SetClockTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Clock values[]);

typedef fmi3Status fmi3GetNumberOfVariableDependenciesTYPE(fmi3Instance instance, fmi3ValueReference valueReference,
                                                           size_t* nDependencies);
typedef fmi3Status fmi3GetVariableDependenciesTYPE(fmi3Instance instance, fmi3ValueReference dependent,
                                                   size_t elementIndicesOfDependent[],
                                                   fmi3ValueReference independents[],
                                                   size_t elementIndicesOfIndependents[],
                                                   fmi3DependencyKind dependencyKinds[], size_t nDependencies);

typedef fmi3Status fmi3GetFMUStateTYPE(fmi3Instance instance, fmi3FMUState* FMUState);
typedef fmi3Status fmi3SetFMUStateTYPE(fmi3Instance instance, fmi3FMUState FMUState);
typedef fmi3Status fmi3FreeFMUStateTYPE(fmi3Instance instance, fmi3FMUState* FMUState);
typedef fmi3Status fmi3SerializedFMUStateSizeTYPE(fmi3Instance instance, fmi3FMUState FMUState, size_t* size);
typedef fmi3Status fmi3SerializeFMUStateTYPE(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                             size_t size);
typedef fmi3Status fmi3DeserializeFMUStateTYPE(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                               fmi3FMUState* FMUState);

typedef fmi3Status fmi3GetDirectionalDerivativeTYPE(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                    size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                                    const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                                    size_t nSensitivity);
typedef fmi3Status fmi3GetAdjointDerivativeTYPE(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                                const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                                size_t nSensitivity);

typedef fmi3Status fmi3EnterConfigurationModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3ExitConfigurationModeTYPE(fmi3Instance instance);

typedef fmi3Status fmi3GetIntervalDecimalTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences, fmi3Float64 intervals[],
                                              fmi3IntervalQualifier qualifiers[]);
typedef fmi3Status fmi3GetIntervalFractionTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                               fmi3IntervalQualifier qualifiers[]);
typedef fmi3Status fmi3GetShiftDecimalTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences, fmi3Float64 shifts[]);
typedef fmi3Status fmi3GetShiftFractionTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]);
typedef fmi3Status fmi3SetIntervalDecimalTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences, const fmi3Float64 intervals[]);
typedef fmi3Status fmi3SetIntervalFractionTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences, const fmi3UInt64 counters[],
                                               const fmi3UInt64 resolutions[]);
typedef fmi3Status fmi3SetShiftDecimalTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences, const fmi3Float64 shifts[]);
typedef fmi3Status fmi3SetShiftFractionTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences, const fmi3UInt64 counters[],
                                            const fmi3UInt64 resolutions[]);

typedef fmi3Status fmi3EvaluateDiscreteStatesTYPE(fmi3Instance instance);
typedef fmi3Status fmi3UpdateDiscreteStatesTYPE(fmi3Instance instance, fmi3Boolean* discreteStatesNeedUpdate,
                                                fmi3Boolean* terminateSimulation,
                                                fmi3Boolean* nominalsOfContinuousStatesChanged,
                                                fmi3Boolean* valuesOfContinuousStatesChanged,
                                                fmi3Boolean* nextEventTimeDefined, fmi3Float64* nextEventTime);

/* ---- Function types: Model Exchange ------------------------------------------------------------ */
typedef fmi3Status fmi3EnterContinuousTimeModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3CompletedIntegratorStepTYPE(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi3Boolean* enterEventMode, fmi3Boolean* terminateSimulation);
typedef fmi3Status fmi3SetTimeTYPE(fmi3Instance instance, fmi3Float64 time);
typedef fmi3Status fmi3SetContinuousStatesTYPE(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                               size_t nContinuousStates);
typedef fmi3Status fmi3GetContinuousStateDerivativesTYPE(fmi3Instance instance, fmi3Float64 derivatives[],
                                                         size_t nContinuousStates);
typedef fmi3Status fmi3GetEventIndicatorsTYPE(fmi3Instance instance, fmi3Float64 eventIndicators[],
                                              size_t nEventIndicators);
typedef fmi3Status fmi3GetContinuousStatesTYPE(fmi3Instance instance, fmi3Float64 continuousStates[],
                                               size_t nContinuousStates);
typedef fmi3Status fmi3GetNominalsOfContinuousStatesTYPE(fmi3Instance instance, fmi3Float64 nominals[],
                                                         size_t nContinuousStates);
typedef fmi3Status fmi3GetNumberOfEventIndicatorsTYPE(fmi3Instance instance, size_t* nEventIndicators);
typedef fmi3Status fmi3GetNumberOfContinuousStatesTYPE(fmi3Instance instance, size_t* nContinuousStates);

/* ---- Function types: Co-Simulation ------------------------------------------------------------- */
typedef fmi3Status fmi3EnterStepModeTYPE(fmi3Instance instance);
typedef fmi3Status fmi3GetOutputDerivativesTYPE(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                                size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                                size_t nValues);
typedef fmi3Status fmi3DoStepTYPE(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                                  fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime);

/* ---- Function types: Scheduled Execution ------------------------------------------------------- */
typedef fmi3Status fmi3ActivateModelPartitionTYPE(fmi3Instance instance, fmi3ValueReference clockReference,
                                                  fmi3Float64 activationTime);

/* ---- The exported functions -------------------------------------------------------------------- */
QUADCOSIM_FMI_EXPORT fmi3GetVersionTYPE fmi3GetVersion;
QUADCOSIM_FMI_EXPORT fmi3SetDebugLoggingTYPE fmi3SetDebugLogging;
QUADCOSIM_FMI_EXPORT fmi3InstantiateModelExchangeTYPE fmi3InstantiateModelExchange;
QUADCOSIM_FMI_EXPORT fmi3InstantiateCoSimulationTYPE fmi3InstantiateCoSimulation;
QUADCOSIM_FMI_EXPORT fmi3InstantiateScheduledExecutionTYPE fmi3InstantiateScheduledExecution;
QUADCOSIM_FMI_EXPORT fmi3FreeInstanceTYPE fmi3FreeInstance;

QUADCOSIM_FMI_EXPORT fmi3EnterInitializationModeTYPE fmi3EnterInitializationMode;
QUADCOSIM_FMI_EXPORT fmi3ExitInitializationModeTYPE fmi3ExitInitializationMode;
QUADCOSIM_FMI_EXPORT fmi3EnterEventModeTYPE fmi3EnterEventMode;
QUADCOSIM_FMI_EXPORT fmi3TerminateTYPE fmi3Terminate;
QUADCOSIM_FMI_EXPORT fmi3ResetTYPE fmi3Reset;

QUADCOSIM_FMI_EXPORT fmi3GetFloat32TYPE fmi3GetFloat32;
QUADCOSIM_FMI_EXPORT fmi3GetFloat64TYPE fmi3GetFloat64;
QUADCOSIM_FMI_EXPORT fmi3GetInt8TYPE fmi3GetInt8;
QUADCOSIM_FMI_EXPORT fmi3GetUInt8TYPE fmi3GetUInt8;
QUADCOSIM_FMI_EXPORT fmi3GetInt16TYPE fmi3GetInt16;
QUADCOSIM_FMI_EXPORT fmi3GetUInt16TYPE fmi3GetUInt16;
QUADCOSIM_FMI_EXPORT fmi3GetInt32TYPE fmi3GetInt32;
QUADCOSIM_FMI_EXPORT fmi3GetUInt32TYPE fmi3GetUInt32;
QUADCOSIM_FMI_EXPORT fmi3GetInt64TYPE fmi3GetInt64;
QUADCOSIM_FMI_EXPORT fmi3GetUInt64TYPE fmi3GetUInt64;
QUADCOSIM_FMI_EXPORT fmi3GetBooleanTYPE fmi3GetBoolean;
QUADCOSIM_FMI_EXPORT fmi3GetStringTYPE fmi3GetString;
QUADCOSIM_FMI_EXPORT fmi3GetBinaryTYPE fmi3GetBinary;
QUADCOSIM_FMI_EXPORT fmi3GetClockTYPE fmi3GetClock;

QUADCOSIM_FMI_EXPORT fmi3SetFloat32TYPE fmi3SetFloat32;
QUADCOSIM_FMI_EXPORT fmi3SetFloat64TYPE fmi3SetFloat64;
QUADCOSIM_FMI_EXPORT fmi3SetInt8TYPE fmi3SetInt8;
QUADCOSIM_FMI_EXPORT fmi3SetUInt8TYPE fmi3SetUInt8;
QUADCOSIM_FMI_EXPORT fmi3SetInt16TYPE fmi3SetInt16;
QUADCOSIM_FMI_EXPORT fmi3SetUInt16TYPE fmi3SetUInt16;
QUADCOSIM_FMI_EXPORT fmi3SetInt32TYPE fmi3SetInt32;
QUADCOSIM_FMI_EXPORT fmi3SetUInt32TYPE fmi3SetUInt32;
QUADCOSIM_FMI_EXPORT fmi3SetInt64TYPE fmi3SetInt64;
QUADCOSIM_FMI_EXPORT fmi3SetUInt64TYPE fmi3SetUInt64;
QUADCOSIM_FMI_EXPORT fmi3SetBooleanTYPE fmi3SetBoolean;
QUADCOSIM_FMI_EXPORT fmi3SetStringTYPE fmi3SetString;
QUADCOSIM_FMI_EXPORT fmi3SetBinaryTYPE fmi3SetBinary;
QUADCOSIM_FMI_EXPORT fmi3SetClockTYPE fmi3SetClock;

QUADCOSIM_FMI_EXPORT fmi3GetNumberOfVariableDependenciesTYPE fmi3GetNumberOfVariableDependencies;
QUADCOSIM_FMI_EXPORT fmi3GetVariableDependenciesTYPE fmi3GetVariableDependencies;

QUADCOSIM_FMI_EXPORT fmi3GetFMUStateTYPE fmi3GetFMUState;
QUADCOSIM_FMI_EXPORT fmi3SetFMUStateTYPE fmi3SetFMUState;
QUADCOSIM_FMI_EXPORT fmi3FreeFMUStateTYPE fmi3FreeFMUState;
QUADCOSIM_FMI_EXPORT fmi3SerializedFMUStateSizeTYPE fmi3SerializedFMUStateSize;
QUADCOSIM_FMI_EXPORT fmi3SerializeFMUStateTYPE fmi3SerializeFMUState;
QUADCOSIM_FMI_EXPORT fmi3DeserializeFMUStateTYPE fmi3DeserializeFMUState;

QUADCOSIM_FMI_EXPORT fmi3GetDirectionalDerivativeTYPE fmi3GetDirectionalDerivative;
QUADCOSIM_FMI_EXPORT fmi3GetAdjointDerivativeTYPE fmi3GetAdjointDerivative;

QUADCOSIM_FMI_EXPORT fmi3EnterConfigurationModeTYPE fmi3EnterConfigurationMode;
QUADCOSIM_FMI_EXPORT fmi3ExitConfigurationModeTYPE fmi3ExitConfigurationMode;
QUADCOSIM_FMI_EXPORT fmi3GetIntervalDecimalTYPE fmi3GetIntervalDecimal;
QUADCOSIM_FMI_EXPORT fmi3GetIntervalFractionTYPE fmi3GetIntervalFraction;
QUADCOSIM_FMI_EXPORT fmi3GetShiftDecimalTYPE fmi3GetShiftDecimal;
QUADCOSIM_FMI_EXPORT fmi3GetShiftFractionTYPE fmi3GetShiftFraction;
QUADCOSIM_FMI_EXPORT fmi3SetIntervalDecimalTYPE fmi3SetIntervalDecimal;
QUADCOSIM_FMI_EXPORT fmi3SetIntervalFractionTYPE fmi3SetIntervalFraction;
QUADCOSIM_FMI_EXPORT fmi3SetShiftDecimalTYPE fmi3SetShiftDecimal;
QUADCOSIM_FMI_EXPORT fmi3SetShiftFractionTYPE fmi3SetShiftFraction;
QUADCOSIM_FMI_EXPORT fmi3EvaluateDiscreteStatesTYPE fmi3EvaluateDiscreteStates;
QUADCOSIM_FMI_EXPORT fmi3UpdateDiscreteStatesTYPE fmi3UpdateDiscreteStates;

QUADCOSIM_FMI_EXPORT fmi3EnterContinuousTimeModeTYPE fmi3EnterContinuousTimeMode;
QUADCOSIM_FMI_EXPORT fmi3CompletedIntegratorStepTYPE fmi3CompletedIntegratorStep;
QUADCOSIM_FMI_EXPORT fmi3SetTimeTYPE fmi3SetTime;
QUADCOSIM_FMI_EXPORT fmi3SetContinuousStatesTYPE fmi3SetContinuousStates;
QUADCOSIM_FMI_EXPORT fmi3GetContinuousStateDerivativesTYPE fmi3GetContinuousStateDerivatives;
QUADCOSIM_FMI_EXPORT fmi3GetEventIndicatorsTYPE fmi3GetEventIndicators;
QUADCOSIM_FMI_EXPORT fmi3GetContinuousStatesTYPE fmi3GetContinuousStates;
QUADCOSIM_FMI_EXPORT fmi3GetNominalsOfContinuousStatesTYPE fmi3GetNominalsOfContinuousStates;
QUADCOSIM_FMI_EXPORT fmi3GetNumberOfEventIndicatorsTYPE fmi3GetNumberOfEventIndicators;
QUADCOSIM_FMI_EXPORT fmi3GetNumberOfContinuousStatesTYPE fmi3GetNumberOfContinuousStates;

QUADCOSIM_FMI_EXPORT fmi3EnterStepModeTYPE fmi3EnterStepMode;
QUADCOSIM_FMI_EXPORT fmi3GetOutputDerivativesTYPE fmi3GetOutputDerivatives;
QUADCOSIM_FMI_EXPORT fmi3DoStepTYPE fmi3DoStep;

QUADCOSIM_FMI_EXPORT fmi3ActivateModelPartitionTYPE fmi3ActivateModelPartition;

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* QUADCOSIM_FMI_API_FMI3_H_ */
