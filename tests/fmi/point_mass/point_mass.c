/* A co-simulation FMU for the master's tests: a point mass moving vertically, lifted by four rotors.
 *
 *   thrust = k_thrust * (w1^2 + w2^2 + w3^2 + w4^2)      [N], w = omega_cmd[i] [rad/s]
 *   a      = thrust / mass_kg - g                        [m/s^2]
 *
 * The commands hold over a communication step, so a is constant within it and the step is exact:
 * z += v h + a h^2 / 2, v += a h. Outputs are named like quadcosim's plant FMU (p_W, v_W, q_WB),
 * so the mass can stand in for a plant.
 *
 * Written from the FMI standard's text alone, with its own declarations of the few types it needs
 * (it includes nothing of quadcosim), so that it checks the master's side of the C interface
 * independently. Built as FMI 2.0 by default, as FMI 3.0 with -DPOINT_MASS_FMI3, without fmi2DoStep
 * with -DPOINT_MASS_OMIT_DO_STEP (a binary the master must refuse).
 *
 * Besides the physics it has test hooks: fail_at_step (doStep number n answers Error and logs why),
 * fatal_at_step (likewise Fatal), a rotor command above 2000 rad/s (Warning, the step is taken),
 * log_steps (logs every step and the termination), label (a String parameter echoed in the log), resources_ok (1 when
 * resources/point_mass.txt was found through the resource location the master passed). */
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

#ifdef POINT_MASS_FMI3
#define TOKEN "{6f1d1b54-3c2a-4b8e-9a51-point-mass-3}"
#else
#define TOKEN "{6f1d1b54-3c2a-4b8e-9a51-point-mass-2}"
#endif

/* Status codes of both versions: OK, Warning, Discard, Error, Fatal. */
enum { kOK = 0, kWarning = 1, kDiscard = 2, kError = 3, kFatal = 4 };

/* Value references, as in modelDescription.xml. */
enum {
  VR_OMEGA_CMD = 0, /* 0..3 */
  VR_MASS = 10,
  VR_K_THRUST = 11,
  VR_G = 12,
  VR_Z0 = 13,
  VR_VZ0 = 14,
  VR_P = 20, /* 20..22 */
  VR_V = 23, /* 23..25 */
  VR_Q = 26, /* 26..29 */
  VR_STEPS = 30,
  VR_FAIL_AT_STEP = 31,
  VR_LOG_STEPS = 32,
  VR_LABEL = 33,
  VR_RESOURCES_OK = 34,
  VR_TIME = 35, /* FMI 3's independent variable */
  VR_FATAL_AT_STEP = 36,
  VR_MODE = 37 /* an Enumeration in FMI 2 (read and written as an Integer) */
};

typedef enum { kInstantiated, kInitializing, kStepping, kTerminated, kBroken } Phase;

#ifndef POINT_MASS_FMI3
/* FMI 2.0: the callbacks the environment passes to fmi2Instantiate. */
typedef void (*Fmi2Logger)(void* env, const char* instance, int status, const char* category, const char* format, ...);
typedef struct {
  Fmi2Logger logger;
  void* (*allocate)(size_t n, size_t size);
  void (*free)(void* p);
  void (*step_finished)(void* env, int status);
  void* env;
} Fmi2Callbacks;
#else
typedef void (*Fmi3Logger)(void* env, int status, const char* category, const char* message);
#endif

typedef struct {
  char name[64];
  char label[64];
#ifndef POINT_MASS_FMI3
  Fmi2Callbacks cb;
#else
  Fmi3Logger logger;
  void* env;
#endif
  Phase phase;
  double omega[4];
  double mass, k_thrust, g, z0, vz0;
  double t, z, vz;
  int steps, fail_at_step, fatal_at_step, mode;
  bool log_steps;
  int resources_ok;
} PointMass;

static void log_message(PointMass* m, int status, const char* category, const char* format, ...) {
  char text[512];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof text, format, args);
  va_end(args);
#ifndef POINT_MASS_FMI3
  /* The logger is printf-like: pass the text through "%s" so that a '%' in it is not a format. */
  if (m->cb.logger != NULL) m->cb.logger(m->cb.env, m->name, status, category, "%s", text);
#else
  if (m->logger != NULL) m->logger(m->env, status, category, text);
#endif
}

static int fail(PointMass* m, const char* format, ...) {
  char text[512];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof text, format, args);
  va_end(args);
  log_message(m, kError, "logStatusError", "%s", text);
  return kError;
}

/* Percent-decodes a file URI's path ("file:///a%20b/resources" -> "/a b/resources"). */
static void uri_to_path(const char* uri, char* path, size_t size) {
  const char* p = uri;
  if (strncmp(p, "file://", 7) == 0) {
    p += 7;
  } else if (strncmp(p, "file:", 5) == 0) {
    p += 5;
  }
  size_t n = 0;
  while (*p != '\0' && n + 1 < size) {
    unsigned int c = 0;
    if (p[0] == '%' && sscanf(p + 1, "%2x", &c) == 1) {
      path[n++] = (char)c;
      p += 3;
    } else {
      path[n++] = *p++;
    }
  }
  path[n] = '\0';
}

static void check_resources(PointMass* m, const char* location) {
  char path[1024];
  char file[1100];
  if (location == NULL) return;
#ifndef POINT_MASS_FMI3
  uri_to_path(location, path, sizeof path);
  snprintf(file, sizeof file, "%s/point_mass.txt", path);
#else
  (void)uri_to_path;
  snprintf(path, sizeof path, "%s", location); /* a directory path ending in a separator */
  snprintf(file, sizeof file, "%spoint_mass.txt", path);
#endif
  FILE* f = fopen(file, "r");
  if (f != NULL) {
    m->resources_ok = 1;
    fclose(f);
  }
}

static void set_defaults(PointMass* m) {
  for (int i = 0; i < 4; ++i) m->omega[i] = 0.0;
  m->mass = 1.0;
  m->k_thrust = 1e-5;
  m->g = 9.81;
  m->z0 = 0.0;
  m->vz0 = 0.0;
  m->t = 0.0;
  m->z = 0.0;
  m->vz = 0.0;
  m->steps = 0;
  m->fail_at_step = -1;
  m->fatal_at_step = -1;
  m->mode = 1;
  m->log_steps = false;
  m->label[0] = '\0';
  m->phase = kInstantiated;
}

static bool is_parameter(unsigned int vr) {
  return vr == VR_MASS || vr == VR_K_THRUST || vr == VR_G || vr == VR_Z0 || vr == VR_VZ0;
}

static int set_real(PointMass* m, unsigned int vr, double value) {
  if (is_parameter(vr) && m->phase != kInstantiated && m->phase != kInitializing) {
    return fail(m, "value reference %u is a fixed parameter: set it before ExitInitializationMode", vr);
  }
  if (vr < VR_OMEGA_CMD + 4) {
    m->omega[vr - VR_OMEGA_CMD] = value;
    return kOK;
  }
  switch (vr) {
    case VR_MASS: m->mass = value; return kOK;
    case VR_K_THRUST: m->k_thrust = value; return kOK;
    case VR_G: m->g = value; return kOK;
    case VR_Z0: m->z0 = value; return kOK;
    case VR_VZ0: m->vz0 = value; return kOK;
    default: return fail(m, "SetReal: value reference %u is no Real input or parameter", vr);
  }
}

static int get_real(PointMass* m, unsigned int vr, double* value) {
  /* Before ExitInitializationMode the state is the initial one. */
  const bool initial = m->phase == kInstantiated || m->phase == kInitializing;
  const double z = initial ? m->z0 : m->z;
  const double vz = initial ? m->vz0 : m->vz;
  if (vr < VR_OMEGA_CMD + 4) {
    *value = m->omega[vr - VR_OMEGA_CMD];
    return kOK;
  }
  switch (vr) {
    case VR_MASS: *value = m->mass; return kOK;
    case VR_K_THRUST: *value = m->k_thrust; return kOK;
    case VR_G: *value = m->g; return kOK;
    case VR_Z0: *value = m->z0; return kOK;
    case VR_VZ0: *value = m->vz0; return kOK;
    case VR_P: case VR_P + 1: case VR_V: case VR_V + 1: *value = 0.0; return kOK;
    case VR_P + 2: *value = z; return kOK;
    case VR_V + 2: *value = vz; return kOK;
    case VR_Q: *value = 1.0; return kOK;
    case VR_Q + 1: case VR_Q + 2: case VR_Q + 3: *value = 0.0; return kOK;
    case VR_TIME: *value = m->t; return kOK;
    default: return fail(m, "GetReal: value reference %u is no Real variable", vr);
  }
}

static int set_integer(PointMass* m, unsigned int vr, int value) {
  if (vr == VR_FAIL_AT_STEP) {
    m->fail_at_step = value;
  } else if (vr == VR_FATAL_AT_STEP) {
    m->fatal_at_step = value;
  } else if (vr == VR_MODE) {
    m->mode = value;
  } else {
    return fail(m, "SetInteger: value reference %u is no Integer parameter", vr);
  }
  return kOK;
}

static int get_integer(PointMass* m, unsigned int vr, int* value) {
  switch (vr) {
    case VR_STEPS: *value = m->steps; return kOK;
    case VR_FAIL_AT_STEP: *value = m->fail_at_step; return kOK;
    case VR_FATAL_AT_STEP: *value = m->fatal_at_step; return kOK;
    case VR_MODE: *value = m->mode; return kOK;
    case VR_RESOURCES_OK: *value = m->resources_ok; return kOK;
    default: return fail(m, "GetInteger: value reference %u is no Integer variable", vr);
  }
}

static int set_boolean(PointMass* m, unsigned int vr, bool value) {
  if (vr != VR_LOG_STEPS) return fail(m, "SetBoolean: value reference %u is no Boolean parameter", vr);
  m->log_steps = value;
  return kOK;
}

static int get_boolean(PointMass* m, unsigned int vr, bool* value) {
  if (vr != VR_LOG_STEPS) return fail(m, "GetBoolean: value reference %u is no Boolean variable", vr);
  *value = m->log_steps;
  return kOK;
}

static int set_string(PointMass* m, unsigned int vr, const char* value) {
  if (vr != VR_LABEL) return fail(m, "SetString: value reference %u is no String parameter", vr);
  snprintf(m->label, sizeof m->label, "%s", value != NULL ? value : "");
  return kOK;
}

static int enter_initialization(PointMass* m, double start_time) {
  if (m->phase != kInstantiated) return fail(m, "EnterInitializationMode: not in the instantiated state");
  m->t = start_time;
  m->phase = kInitializing;
  return kOK;
}

static int exit_initialization(PointMass* m) {
  if (m->phase != kInitializing) return fail(m, "ExitInitializationMode: not in initialization mode");
  if (!(m->mass > 0.0)) return fail(m, "mass_kg = %g must be positive", m->mass);
  m->z = m->z0;
  m->vz = m->vz0;
  m->phase = kStepping;
  return kOK;
}

/* unused where fmi2DoStep is left out on purpose */
__attribute__((unused)) static int do_step(PointMass* m, double t, double h) {
  if (m->phase != kStepping) return fail(m, "DoStep: the FMU is not initialized");
  if (!(h > 0.0)) return fail(m, "DoStep: step size %g is not positive", h);
  if (fabs(t - m->t) > 1e-9 * (1.0 + fabs(t))) {
    return fail(m, "DoStep: communication point %.17g is not the FMU's time %.17g", t, m->t);
  }
  double sum = 0.0;
  int status = kOK;
  for (int i = 0; i < 4; ++i) {
    if (!isfinite(m->omega[i])) return fail(m, "omega_cmd[%d] = %g is not finite", i + 1, m->omega[i]);
    if (m->omega[i] > 2000.0) {
      log_message(m, kWarning, "logStatusWarning", "omega_cmd[%d] = %g exceeds 2000 rad/s; stepping on", i + 1,
                  m->omega[i]);
      status = kWarning;
    }
    sum += m->omega[i] * m->omega[i];
  }
  m->steps += 1;
  if (m->steps == m->fail_at_step) {
    return fail(m, "step %d fails as fail_at_step = %d asks (100%% on purpose)", m->steps, m->fail_at_step);
  }
  if (m->steps == m->fatal_at_step) {
    log_message(m, kFatal, "logStatusFatal", "step %d: fatal_at_step reached", m->steps);
    m->phase = kBroken;
    return kFatal;
  }
  const double a = m->k_thrust * sum / m->mass - m->g;
  m->z += m->vz * h + a * h * h / 2.0;
  m->vz += a * h;
  m->t = t + h;
  if (m->log_steps) log_message(m, kOK, "logAll", "%s step %d to t = %g: z = %g", m->label, m->steps, m->t, m->z);
  return status;
}

static int terminate(PointMass* m) {
  if (m->phase == kBroken) return fail(m, "Terminate: the FMU is broken");
  if (m->log_steps) log_message(m, kOK, "logAll", "%s terminated after %d steps", m->label, m->steps);
  m->phase = kTerminated;
  return kOK;
}

/* The master's calls that hand over arrays: each element, stopping at the first failure. */
#define FOR_EACH(call)                           \
  do {                                           \
    for (size_t i = 0; i < nvr; ++i) {           \
      const int status = (call);                 \
      if (status != kOK) return status;          \
    }                                            \
    return kOK;                                  \
  } while (0)

/* The rest of the API, which a master that resolves every symbol needs (fmusim does): Error. */
static int unsupported(void* c, const char* function) {
  if (c == NULL) return kError;
  return fail((PointMass*)c, "%s is not supported by the point mass", function);
}
#define UNSUPPORTED(function, params) \
  EXPORT int function params { return unsupported(c, #function); }

#ifndef POINT_MASS_FMI3
/* ---- FMI 2.0 -------------------------------------------------------------------------------------- */
EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

EXPORT void* fmi2Instantiate(const char* name, int type, const char* guid, const char* resources,
                             const Fmi2Callbacks* cb, int visible, int logging_on) {
  (void)visible;
  (void)logging_on;
  if (cb == NULL || cb->allocate == NULL || cb->free == NULL) return NULL;
  if (type != 1) {
    if (cb->logger != NULL) cb->logger(cb->env, name, kError, "logStatusError", "%s is a co-simulation FMU only", name);
    return NULL;
  }
  if (guid == NULL || strcmp(guid, TOKEN) != 0) {
    if (cb->logger != NULL) {
      cb->logger(cb->env, name, kError, "logStatusError", "fmi2Instantiate: GUID %s is not this binary's %s",
                 guid != NULL ? guid : "(null)", TOKEN);
    }
    return NULL;
  }
  PointMass* m = (PointMass*)cb->allocate(1, sizeof(PointMass));
  if (m == NULL) return NULL;
  snprintf(m->name, sizeof m->name, "%s", name != NULL ? name : "");
  m->cb = *cb;
  set_defaults(m);
  check_resources(m, resources);
  return m;
}

EXPORT void fmi2FreeInstance(void* c) {
  PointMass* m = (PointMass*)c;
  if (m != NULL) m->cb.free(m);
}

EXPORT int fmi2SetDebugLogging(void* c, int on, size_t n, const char* const categories[]) {
  (void)c, (void)on, (void)n, (void)categories;
  return kOK;
}

EXPORT int fmi2SetupExperiment(void* c, int tolerance_defined, double tolerance, double start, int stop_defined,
                               double stop) {
  (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
  PointMass* m = (PointMass*)c;
  if (m->phase != kInstantiated) return fail(m, "fmi2SetupExperiment: not in the instantiated state");
  m->t = start;
  return kOK;
}

EXPORT int fmi2EnterInitializationMode(void* c) {
  PointMass* m = (PointMass*)c;
  return enter_initialization(m, m->t);
}
EXPORT int fmi2ExitInitializationMode(void* c) { return exit_initialization((PointMass*)c); }
EXPORT int fmi2Terminate(void* c) { return terminate((PointMass*)c); }
EXPORT int fmi2Reset(void* c) {
  set_defaults((PointMass*)c);
  return kOK;
}

EXPORT int fmi2SetReal(void* c, const unsigned int vr[], size_t nvr, const double v[]) {
  FOR_EACH(set_real((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi2GetReal(void* c, const unsigned int vr[], size_t nvr, double v[]) {
  FOR_EACH(get_real((PointMass*)c, vr[i], &v[i]));
}
EXPORT int fmi2SetInteger(void* c, const unsigned int vr[], size_t nvr, const int v[]) {
  FOR_EACH(set_integer((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi2GetInteger(void* c, const unsigned int vr[], size_t nvr, int v[]) {
  FOR_EACH(get_integer((PointMass*)c, vr[i], &v[i]));
}
EXPORT int fmi2SetBoolean(void* c, const unsigned int vr[], size_t nvr, const int v[]) {
  FOR_EACH(set_boolean((PointMass*)c, vr[i], v[i] != 0));
}
EXPORT int fmi2GetBoolean(void* c, const unsigned int vr[], size_t nvr, int v[]) {
  for (size_t i = 0; i < nvr; ++i) {
    bool b = false;
    const int status = get_boolean((PointMass*)c, vr[i], &b);
    if (status != kOK) return status;
    v[i] = b ? 1 : 0;
  }
  return kOK;
}
EXPORT int fmi2SetString(void* c, const unsigned int vr[], size_t nvr, const char* const v[]) {
  FOR_EACH(set_string((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi2GetString(void* c, const unsigned int vr[], size_t nvr, const char* v[]) {
  PointMass* m = (PointMass*)c;
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] != VR_LABEL) return fail(m, "fmi2GetString: value reference %u is no String variable", vr[i]);
    v[i] = m->label;
  }
  return kOK;
}

#ifndef POINT_MASS_OMIT_DO_STEP
EXPORT int fmi2DoStep(void* c, double t, double h, int no_set_state_prior) {
  (void)no_set_state_prior;
  return do_step((PointMass*)c, t, h);
}
#endif
EXPORT int fmi2CancelStep(void* c) { return fail((PointMass*)c, "fmi2CancelStep: steps are never asynchronous"); }

UNSUPPORTED(fmi2GetFMUstate, (void* c, void** state))
UNSUPPORTED(fmi2SetFMUstate, (void* c, void* state))
UNSUPPORTED(fmi2FreeFMUstate, (void* c, void** state))
UNSUPPORTED(fmi2SerializedFMUstateSize, (void* c, void* state, size_t* size))
UNSUPPORTED(fmi2SerializeFMUstate, (void* c, void* state, char bytes[], size_t size))
UNSUPPORTED(fmi2DeSerializeFMUstate, (void* c, const char bytes[], size_t size, void** state))
UNSUPPORTED(fmi2GetDirectionalDerivative, (void* c, const unsigned int u[], size_t nu, const unsigned int k[],
                                           size_t nk, const double dk[], double du[]))
UNSUPPORTED(fmi2SetRealInputDerivatives, (void* c, const unsigned int vr[], size_t n, const int order[],
                                          const double v[]))
UNSUPPORTED(fmi2GetRealOutputDerivatives, (void* c, const unsigned int vr[], size_t n, const int order[], double v[]))
UNSUPPORTED(fmi2GetStatus, (void* c, int kind, int* value))
UNSUPPORTED(fmi2GetRealStatus, (void* c, int kind, double* value))
UNSUPPORTED(fmi2GetIntegerStatus, (void* c, int kind, int* value))
UNSUPPORTED(fmi2GetBooleanStatus, (void* c, int kind, int* value))
UNSUPPORTED(fmi2GetStringStatus, (void* c, int kind, const char** value))

#else
/* ---- FMI 3.0 -------------------------------------------------------------------------------------- */
EXPORT const char* fmi3GetVersion(void) { return "3.0"; }

EXPORT void* fmi3InstantiateCoSimulation(const char* name, const char* token, const char* resources, bool visible,
                                         bool logging_on, bool event_mode_used, bool early_return_allowed,
                                         const uint32_t required_intermediate[], size_t n_required, void* env,
                                         Fmi3Logger logger, void* intermediate_update) {
  (void)visible, (void)logging_on, (void)required_intermediate, (void)n_required, (void)intermediate_update;
  if (event_mode_used || early_return_allowed) {
    if (logger != NULL) logger(env, kError, "logStatusError", "event mode and early return are not supported");
    return NULL;
  }
  if (token == NULL || strcmp(token, TOKEN) != 0) {
    if (logger != NULL) {
      char text[256];
      snprintf(text, sizeof text, "fmi3InstantiateCoSimulation: instantiation token %s is not this binary's %s",
               token != NULL ? token : "(null)", TOKEN);
      logger(env, kError, "logStatusError", text);
    }
    return NULL;
  }
  PointMass* m = (PointMass*)calloc(1, sizeof(PointMass));
  if (m == NULL) return NULL;
  snprintf(m->name, sizeof m->name, "%s", name != NULL ? name : "");
  m->logger = logger;
  m->env = env;
  set_defaults(m);
  check_resources(m, resources);
  return m;
}

EXPORT void fmi3FreeInstance(void* c) { free(c); }

EXPORT int fmi3SetDebugLogging(void* c, bool on, size_t n, const char* const categories[]) {
  (void)c, (void)on, (void)n, (void)categories;
  return kOK;
}

EXPORT int fmi3EnterInitializationMode(void* c, bool tolerance_defined, double tolerance, double start,
                                       bool stop_defined, double stop) {
  (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
  return enter_initialization((PointMass*)c, start);
}
EXPORT int fmi3ExitInitializationMode(void* c) { return exit_initialization((PointMass*)c); }
EXPORT int fmi3Terminate(void* c) { return terminate((PointMass*)c); }
EXPORT int fmi3Reset(void* c) {
  set_defaults((PointMass*)c);
  return kOK;
}

EXPORT int fmi3SetFloat64(void* c, const uint32_t vr[], size_t nvr, const double v[], size_t nv) {
  if (nv != nvr) return fail((PointMass*)c, "fmi3SetFloat64: %zu values for %zu scalars", nv, nvr);
  FOR_EACH(set_real((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi3GetFloat64(void* c, const uint32_t vr[], size_t nvr, double v[], size_t nv) {
  if (nv != nvr) return fail((PointMass*)c, "fmi3GetFloat64: %zu values for %zu scalars", nv, nvr);
  FOR_EACH(get_real((PointMass*)c, vr[i], &v[i]));
}
EXPORT int fmi3SetInt32(void* c, const uint32_t vr[], size_t nvr, const int32_t v[], size_t nv) {
  (void)nv;
  FOR_EACH(set_integer((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi3GetInt32(void* c, const uint32_t vr[], size_t nvr, int32_t v[], size_t nv) {
  (void)nv;
  FOR_EACH(get_integer((PointMass*)c, vr[i], &v[i]));
}
EXPORT int fmi3SetBoolean(void* c, const uint32_t vr[], size_t nvr, const bool v[], size_t nv) {
  (void)nv;
  FOR_EACH(set_boolean((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi3GetBoolean(void* c, const uint32_t vr[], size_t nvr, bool v[], size_t nv) {
  (void)nv;
  FOR_EACH(get_boolean((PointMass*)c, vr[i], &v[i]));
}
EXPORT int fmi3SetString(void* c, const uint32_t vr[], size_t nvr, const char* const v[], size_t nv) {
  (void)nv;
  FOR_EACH(set_string((PointMass*)c, vr[i], v[i]));
}
EXPORT int fmi3GetString(void* c, const uint32_t vr[], size_t nvr, const char* v[], size_t nv) {
  (void)nv;
  PointMass* m = (PointMass*)c;
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] != VR_LABEL) return fail(m, "fmi3GetString: value reference %u is no String variable", vr[i]);
    v[i] = m->label;
  }
  return kOK;
}

EXPORT int fmi3DoStep(void* c, double t, double h, bool no_set_state_prior, bool* event_handling_needed,
                      bool* terminate, bool* early_return, double* last_successful_time) {
  (void)no_set_state_prior;
  PointMass* m = (PointMass*)c;
  *event_handling_needed = false;
  *terminate = false;
  *early_return = false;
  const int status = do_step(m, t, h);
  *last_successful_time = m->t;
  return status;
}

EXPORT void* fmi3InstantiateModelExchange(const char* name, const char* token, const char* resources, bool visible,
                                          bool logging_on, void* env, Fmi3Logger logger) {
  (void)name, (void)token, (void)resources, (void)visible, (void)logging_on;
  if (logger != NULL) logger(env, kError, "logStatusError", "the point mass is a co-simulation FMU only");
  return NULL;
}
EXPORT void* fmi3InstantiateScheduledExecution(const char* name, const char* token, const char* resources,
                                               bool visible, bool logging_on, void* env, Fmi3Logger logger,
                                               void* clock_update, void* lock, void* unlock) {
  (void)clock_update, (void)lock, (void)unlock;
  return fmi3InstantiateModelExchange(name, token, resources, visible, logging_on, env, logger);
}

#define UNSUPPORTED_GET_SET(T, type)                                                                               \
  UNSUPPORTED(fmi3Get##T, (void* c, const uint32_t vr[], size_t nvr, type v[], size_t nv))                        \
  UNSUPPORTED(fmi3Set##T, (void* c, const uint32_t vr[], size_t nvr, const type v[], size_t nv))
UNSUPPORTED_GET_SET(Float32, float)
UNSUPPORTED_GET_SET(Int8, int8_t)
UNSUPPORTED_GET_SET(UInt8, uint8_t)
UNSUPPORTED_GET_SET(Int16, int16_t)
UNSUPPORTED_GET_SET(UInt16, uint16_t)
UNSUPPORTED_GET_SET(UInt32, uint32_t)
UNSUPPORTED_GET_SET(Int64, int64_t)
UNSUPPORTED_GET_SET(UInt64, uint64_t)
UNSUPPORTED(fmi3GetBinary, (void* c, const uint32_t vr[], size_t nvr, size_t sizes[], const uint8_t* v[], size_t nv))
UNSUPPORTED(fmi3SetBinary, (void* c, const uint32_t vr[], size_t nvr, const size_t sizes[], const uint8_t* const v[],
                            size_t nv))
UNSUPPORTED(fmi3GetClock, (void* c, const uint32_t vr[], size_t nvr, bool v[]))
UNSUPPORTED(fmi3SetClock, (void* c, const uint32_t vr[], size_t nvr, const bool v[]))
UNSUPPORTED(fmi3EnterEventMode, (void* c))
UNSUPPORTED(fmi3GetNumberOfVariableDependencies, (void* c, uint32_t vr, size_t* n))
UNSUPPORTED(fmi3GetVariableDependencies, (void* c, uint32_t dependent, size_t element_of_dependent[],
                                          uint32_t independents[], size_t elements_of_independents[], int kinds[],
                                          size_t n))
UNSUPPORTED(fmi3GetFMUState, (void* c, void** state))
UNSUPPORTED(fmi3SetFMUState, (void* c, void* state))
UNSUPPORTED(fmi3FreeFMUState, (void* c, void** state))
UNSUPPORTED(fmi3SerializedFMUStateSize, (void* c, void* state, size_t* size))
UNSUPPORTED(fmi3SerializeFMUState, (void* c, void* state, uint8_t bytes[], size_t size))
UNSUPPORTED(fmi3DeserializeFMUState, (void* c, const uint8_t bytes[], size_t size, void** state))
UNSUPPORTED(fmi3GetDirectionalDerivative, (void* c, const uint32_t unknowns[], size_t nu, const uint32_t knowns[],
                                           size_t nk, const double seed[], size_t ns, double sensitivity[],
                                           size_t nsens))
UNSUPPORTED(fmi3GetAdjointDerivative, (void* c, const uint32_t unknowns[], size_t nu, const uint32_t knowns[],
                                       size_t nk, const double seed[], size_t ns, double sensitivity[], size_t nsens))
UNSUPPORTED(fmi3EnterConfigurationMode, (void* c))
UNSUPPORTED(fmi3ExitConfigurationMode, (void* c))
UNSUPPORTED(fmi3GetIntervalDecimal, (void* c, const uint32_t vr[], size_t n, double intervals[], int qualifiers[]))
UNSUPPORTED(fmi3GetIntervalFraction, (void* c, const uint32_t vr[], size_t n, uint64_t counters[],
                                      uint64_t resolutions[], int qualifiers[]))
UNSUPPORTED(fmi3GetShiftDecimal, (void* c, const uint32_t vr[], size_t n, double shifts[]))
UNSUPPORTED(fmi3GetShiftFraction, (void* c, const uint32_t vr[], size_t n, uint64_t counters[], uint64_t resolutions[]))
UNSUPPORTED(fmi3SetIntervalDecimal, (void* c, const uint32_t vr[], size_t n, const double intervals[]))
UNSUPPORTED(fmi3SetIntervalFraction, (void* c, const uint32_t vr[], size_t n, const uint64_t counters[],
                                      const uint64_t resolutions[]))
UNSUPPORTED(fmi3SetShiftDecimal, (void* c, const uint32_t vr[], size_t n, const double shifts[]))
UNSUPPORTED(fmi3SetShiftFraction, (void* c, const uint32_t vr[], size_t n, const uint64_t counters[],
                                   const uint64_t resolutions[]))
UNSUPPORTED(fmi3EvaluateDiscreteStates, (void* c))
UNSUPPORTED(fmi3UpdateDiscreteStates, (void* c, bool* update, bool* terminate, bool* nominals_changed,
                                       bool* values_changed, bool* next_event_defined, double* next_event))
UNSUPPORTED(fmi3EnterContinuousTimeMode, (void* c))
UNSUPPORTED(fmi3CompletedIntegratorStep, (void* c, bool no_set_state_prior, bool* enter_event_mode, bool* terminate))
UNSUPPORTED(fmi3SetTime, (void* c, double time))
UNSUPPORTED(fmi3SetContinuousStates, (void* c, const double x[], size_t n))
UNSUPPORTED(fmi3GetContinuousStateDerivatives, (void* c, double dx[], size_t n))
UNSUPPORTED(fmi3GetEventIndicators, (void* c, double indicators[], size_t n))
UNSUPPORTED(fmi3GetContinuousStates, (void* c, double x[], size_t n))
UNSUPPORTED(fmi3GetNominalsOfContinuousStates, (void* c, double nominals[], size_t n))
UNSUPPORTED(fmi3GetNumberOfEventIndicators, (void* c, size_t* n))
UNSUPPORTED(fmi3GetNumberOfContinuousStates, (void* c, size_t* n))
UNSUPPORTED(fmi3EnterStepMode, (void* c))
UNSUPPORTED(fmi3GetOutputDerivatives, (void* c, const uint32_t vr[], size_t nvr, const int32_t orders[], double v[],
                                       size_t nv))
UNSUPPORTED(fmi3ActivateModelPartition, (void* c, uint32_t clock, double activation_time))
#endif
