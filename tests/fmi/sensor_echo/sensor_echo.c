/* A controller FMU (FMI 2.0) for the tests of the extra sensors' inputs (docs/sensors.md, "In the
 * controller"): inputs p_W[1..3] and every extra sensor's column by the plant FMU's output names
 * (magnetometer.field[1..3], barometer.pressure, barometer.altitude, gnss.fix, gnss.latitude_deg,
 * gnss.longitude_deg, gnss.altitude_m, gnss.v[1..3]); it commands omega_cmd[1..4] = its tunable
 * parameter omega, and outputs what each doStep was given: seen.<input> = that input's value when
 * doStep was called. The inputs and outputs are in modelDescription.xml's order (value references
 * 10..22 and 30..42). */
#include <stdlib.h>
#include <string.h>

#include "fmi/api/fmi2.h"

enum { kSensorInputs = 13, kVrOmegaCmd = 1, kVrP = 5, kVrInput = 10, kVrSeen = 30, kVrOmega = 50 };

typedef struct {
  double omega_cmd[4];
  double p[3];
  double input[kSensorInputs];
  double seen[kSensorInputs];
  double omega;
} Model;

static double* value(Model* m, fmi2ValueReference vr) {
  if (vr >= kVrOmegaCmd && vr < kVrOmegaCmd + 4) return &m->omega_cmd[vr - kVrOmegaCmd];
  if (vr >= kVrP && vr < kVrP + 3) return &m->p[vr - kVrP];
  if (vr >= kVrInput && vr < kVrInput + kSensorInputs) return &m->input[vr - kVrInput];
  if (vr >= kVrSeen && vr < kVrSeen + kSensorInputs) return &m->seen[vr - kVrSeen];
  if (vr == kVrOmega) return &m->omega;
  return NULL;
}

QUADCOSIM_FMI_EXPORT const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
QUADCOSIM_FMI_EXPORT const char* fmi2GetVersion(void) { return fmi2Version; }

QUADCOSIM_FMI_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                                   fmi2String resources, const fmi2CallbackFunctions* cb,
                                                   fmi2Boolean visible, fmi2Boolean logging) {
  return calloc(1, sizeof(Model));
}
QUADCOSIM_FMI_EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol,
                                                    fmi2Real t0, fmi2Boolean stop_defined, fmi2Real stop) {
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  memset(c, 0, sizeof(Model));
  return fmi2OK;
}

QUADCOSIM_FMI_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
  Model* m = c;
  for (int i = 0; i < 4; ++i) m->omega_cmd[i] = m->omega;
  memcpy(m->seen, m->input, sizeof m->seen);
  return fmi2OK;
}

QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                            fmi2Real out[]) {
  for (size_t i = 0; i < n; ++i) {
    double* v = value(c, vr[i]);
    if (v == NULL) return fmi2Error;
    out[i] = *v;
  }
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                            const fmi2Real in[]) {
  for (size_t i = 0; i < n; ++i) {
    double* v = value(c, vr[i]);
    if (v == NULL) return fmi2Error;
    *v = in[i];
  }
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               fmi2Integer out[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Integer in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               fmi2Boolean out[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Boolean in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2String in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
