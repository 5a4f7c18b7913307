/* A co-simulation FMU (FMI 2.0) that misbehaves on purpose, for tests/foreign: a vertical point-mass
 * quadrotor plant (FAULTY_PLANT: inputs omega_cmd[1..4] [rad/s], outputs p_W[1..3] [m], v_W[1..3]
 * [m/s]; thrust kt sum(omega^2) against gravity, explicit Euler per step) or a hover controller
 * (FAULTY_CONTROLLER: inputs p_W, v_W; outputs omega_cmd[1..4], PD on z around the hover speed).
 * At the first doStep whose time reaches $FAULTY_FMU_AT [s], it does what $FAULTY_FMU_FAULT names:
 * segv (writes through a null pointer), abort, exit (exit(0)), hang (sleeps for ever) or error
 * (answers fmi2Error). Without them it behaves. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi/api/fmi2.h"

#define KT 2.06e-7
#define MASS 1.96
#define G 9.81

typedef struct {
  double omega[4]; /* vr 1..4 */
  double p[3];     /* vr 5..7 */
  double v[3];     /* vr 8..10 */
  const char* fault;
  double fault_at;
} Model;

static void misbehave(Model* m, double t) {
  if (m->fault == NULL || t + 1e-9 < m->fault_at) return;
  if (strcmp(m->fault, "segv") == 0) {
    volatile int* nowhere = NULL;
    *nowhere = 1;
  } else if (strcmp(m->fault, "abort") == 0) {
    abort();
  } else if (strcmp(m->fault, "exit") == 0) {
    exit(0);
  } else if (strcmp(m->fault, "hang") == 0) {
    for (;;) pause();
  }
}

static double* value(Model* m, fmi2ValueReference vr) {
  if (vr >= 1 && vr <= 4) return &m->omega[vr - 1];
  if (vr >= 5 && vr <= 7) return &m->p[vr - 5];
  if (vr >= 8 && vr <= 10) return &m->v[vr - 8];
  return NULL;
}

QUADCOSIM_FMI_EXPORT const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
QUADCOSIM_FMI_EXPORT const char* fmi2GetVersion(void) { return fmi2Version; }

QUADCOSIM_FMI_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions* cb, fmi2Boolean visible, fmi2Boolean logging) {
  Model* m = calloc(1, sizeof(Model));
  if (m == NULL) return NULL;
  m->p[2] = 1.0; /* the hover height of tests/faults/hover.yaml */
  for (int i = 0; i < 4; ++i) m->omega[i] = sqrt(MASS * G / (4.0 * KT));
  m->fault = getenv("FAULTY_FMU_FAULT");
  const char* at = getenv("FAULTY_FMU_AT");
  m->fault_at = at != NULL ? atof(at) : 0.0;
  return m;
}
QUADCOSIM_FMI_EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol, fmi2Real t0,
                                           fmi2Boolean stop_defined, fmi2Real stop) {
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
QUADCOSIM_FMI_EXPORT fmi2Status fmi2Reset(fmi2Component c) { return fmi2OK; }

QUADCOSIM_FMI_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
  Model* m = c;
  misbehave(m, t);
  if (m->fault != NULL && strcmp(m->fault, "error") == 0 && t + 1e-9 >= m->fault_at) return fmi2Error;
#ifdef FAULTY_CONTROLLER
  const double hover = sqrt(MASS * G / (4.0 * KT));
  const double u = hover * (1.0 + 0.5 * (1.0 - m->p[2]) - 0.3 * m->v[2]);
  for (int i = 0; i < 4; ++i) m->omega[i] = u;
#else
  double thrust = 0.0;
  for (int i = 0; i < 4; ++i) thrust += KT * m->omega[i] * m->omega[i];
  const double a = thrust / MASS - G;
  m->p[2] += h * m->v[2];
  m->v[2] += h * a;
#endif
  return fmi2OK;
}

QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real out[]) {
  for (size_t i = 0; i < n; ++i) {
    double* v = value(c, vr[i]);
    if (v == NULL) return fmi2Error;
    out[i] = *v;
  }
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real in[]) {
  for (size_t i = 0; i < n; ++i) {
    double* v = value(c, vr[i]);
    if (v == NULL) return fmi2Error;
    *v = in[i];
  }
  return fmi2OK;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer out[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean out[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
QUADCOSIM_FMI_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String in[]) {
  return n == 0 ? fmi2OK : fmi2Error;
}
