// For the tests of the FMU binary: loads build/lib/quadcosim_fmu.so with dlopen (as an importer
// does), writes a configuration into a temporary resources folder, and captures what the FMU logs.
#pragma once

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdarg>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fmi/api/fmi2.h"
#include "fmi/api/fmi3.h"
#include "fmi/export/fmu_config.hpp"

namespace quadcosim::fmi::test {

/// The FMU binary, loaded once per test process and never unloaded.
inline void* fmu_library() {
  static void* handle = [] {
    void* h = dlopen(QUADCOSIM_FMU_PATH, RTLD_NOW | RTLD_LOCAL);
    if (!h) throw std::runtime_error(std::string("dlopen ") + QUADCOSIM_FMU_PATH + ": " + dlerror());
    return h;
  }();
  return handle;
}

/// The function `name` of the FMU binary, as its function type F (fmi2DoStepTYPE, ...).
template <class F>
F* fmu_function(const char* name) {
  auto* f = reinterpret_cast<F*>(dlsym(fmu_library(), name));
  if (!f) throw std::runtime_error(std::string("the FMU does not export ") + name);
  return f;
}
#define QC_FMI(name) ::quadcosim::fmi::test::fmu_function<name##TYPE>(#name)

/// A temporary resources folder holding `config` as quadcosim.json; removed with this.
class Resources {
 public:
  explicit Resources(const FmuConfig& config) {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() / ("quadcosim_fmu_test_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / std::string(kConfigFileName)) << to_json(config);
  }
  ~Resources() { std::filesystem::remove_all(dir_); }
  Resources(const Resources&) = delete;
  Resources& operator=(const Resources&) = delete;
  /// FMI 2 fmuResourceLocation.
  std::string uri() const { return "file://" + dir_.string() + "/"; }
  /// FMI 3 resourcePath.
  std::string path() const { return dir_.string() + "/"; }

 private:
  std::filesystem::path dir_;
};

/// What the FMU logged, one line per message: "<status> <category>: <message>".
struct Log {
  std::vector<std::string> lines;
  std::string last() const { return lines.empty() ? std::string() : lines.back(); }
  bool contains(const std::string& text) const {
    for (const auto& l : lines) {
      if (l.find(text) != std::string::npos) return true;
    }
    return false;
  }
  static void fmi2_logger(fmi2ComponentEnvironment env, fmi2String, fmi2Status status, fmi2String category,
                          fmi2String message, ...) {
    char buf[4096];
    va_list args;
    va_start(args, message);
    std::vsnprintf(buf, sizeof buf, message, args);
    va_end(args);
    static_cast<Log*>(env)->lines.push_back(std::to_string(status) + " " + category + ": " + buf);
  }
  static void fmi3_logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    static_cast<Log*>(env)->lines.push_back(std::to_string(status) + " " + category + ": " + message);
  }
  fmi2CallbackFunctions fmi2_callbacks() { return {&fmi2_logger, nullptr, nullptr, nullptr, this}; }
};

/// One FMI 2 co-simulation instance of the FMU binary with `config` in a temporary resources folder,
/// what it logs in log_; freed with this.
class Fmi2Instance {
 public:
  Fmi2Instance(const char* instance_name, const FmuConfig& config) : md_(describe(config)), resources_(config) {
    callbacks_ = log_.fmi2_callbacks();
    c_ = QC_FMI(fmi2Instantiate)(instance_name, fmi2CoSimulation, config.guid.c_str(), resources_.uri().c_str(),
                                 &callbacks_, fmi2False, fmi2False);
    if (!c_) throw std::runtime_error("instantiate failed: " + log_.last());
  }
  ~Fmi2Instance() { QC_FMI(fmi2FreeInstance)(c_); }
  Fmi2Instance(const Fmi2Instance&) = delete;
  Fmi2Instance& operator=(const Fmi2Instance&) = delete;

  /// fmi2SetupExperiment (unless `setup_experiment` is false: an importer may leave it out), then
  /// fmi2EnterInitializationMode and fmi2ExitInitializationMode, each asserted fmi2OK.
  void init(bool setup_experiment = true) {
    if (setup_experiment) {
      ASSERT_EQ(QC_FMI(fmi2SetupExperiment)(c_, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK) << log_.last();
    }
    ASSERT_EQ(QC_FMI(fmi2EnterInitializationMode)(c_), fmi2OK) << log_.last();
    ASSERT_EQ(QC_FMI(fmi2ExitInitializationMode)(c_), fmi2OK) << log_.last();
  }
  fmi2ValueReference vr(std::string_view name) const {
    for (const Variable& v : md_.variables) {
      if (v.name == name) return v.vr;
    }
    throw std::runtime_error("no variable " + std::string(name));
  }
  fmi2Status set(std::string_view name, double value) {
    const fmi2ValueReference r = vr(name);
    return QC_FMI(fmi2SetReal)(c_, &r, 1, &value);
  }
  fmi2Status set_boolean(std::string_view name, bool value) {
    const fmi2ValueReference r = vr(name);
    const fmi2Boolean b = value ? fmi2True : fmi2False;
    return QC_FMI(fmi2SetBoolean)(c_, &r, 1, &b);
  }
  double get(std::string_view name) {
    const fmi2ValueReference r = vr(name);
    double value = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(QC_FMI(fmi2GetReal)(c_, &r, 1, &value), fmi2OK) << log_.last();
    return value;
  }
  fmi2Status step(double t, double h) { return QC_FMI(fmi2DoStep)(c_, t, h, fmi2True); }

  fmi2Component c_ = nullptr;
  Log log_;

 private:
  ModelDescription md_;
  Resources resources_;
  fmi2CallbackFunctions callbacks_{};
};

/// The value reference of `name` in the description of `config`.
inline fmi2ValueReference vr_of(const FmuConfig& config, std::string_view name) {
  for (const Variable& v : describe(config).variables) {
    if (v.name == name) return v.vr;
  }
  throw std::runtime_error("no variable " + std::string(name));
}

/// A plant FMU configuration with the given kind and version and a GUID.
inline FmuConfig config_for(FmuKind kind, FmiVersion version = FmiVersion::k2) {
  FmuConfig c;
  c.kind = kind;
  c.fmi_version = version;
  c.guid = make_guid(c);
  return c;
}

}  // namespace quadcosim::fmi::test
