// quadcosim as an FMI master: loading a co-simulation FMU (FMI 2.0 or 3.0) and stepping its
// instances. An .fmu is unpacked (minizip) into a private temporary directory, its
// modelDescription.xml parsed (libxml2, fmi/model_description.hpp), its binary for this platform
// (binaries/linux64/<modelIdentifier>.so, FMI 3: binaries/x86_64-linux/) dlopen'ed and every function
// the master calls resolved. What does not fit (no CoSimulation element, a GUID or token mismatch,
// a missing symbol, a variable of the wrong type) is refused with an FmuError naming it.
//
// Calls and their order (FMI 2): fmi2Instantiate, fmi2SetupExperiment, set parameters,
// fmi2EnterInitializationMode, fmi2ExitInitializationMode, then per step set inputs, fmi2DoStep,
// get outputs; fmi2Terminate and fmi2FreeInstance at the end. FMI 3 likewise with
// fmi3InstantiateCoSimulation, fmi3EnterInitializationMode, fmi3ExitInitializationMode, fmi3DoStep.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fmi/model_description.hpp"

namespace quadcosim::fmi {

/// What an FMU logs through its logger callback: category, status ("OK", "Warning", "Error", ...)
/// and message.
using LogSink = std::function<void(const std::string& category, const std::string& status, const std::string& message)>;

class Instance;

/// A loaded FMU: its description and its binary. Shared by its instances (which keep it alive); the
/// unpacked directory is removed when the last of them is gone.
class Fmu : public std::enable_shared_from_this<Fmu> {
 public:
  /// `path`: an .fmu file, or a directory an .fmu was unpacked into. Throws FmuError.
  static std::shared_ptr<Fmu> load(const std::string& path);
  virtual ~Fmu() = default;

  const ModelDescription& description() const { return description_; }
  const std::string& path() const { return path_; }
  /// A new co-simulation instance (fmi2Instantiate / fmi3InstantiateCoSimulation), in the
  /// instantiated state. `log` receives the FMU's log; null: messages go to stderr. Throws FmuError.
  virtual std::unique_ptr<Instance> instantiate(const std::string& instance_name, LogSink log = {}) = 0;

 protected:
  ModelDescription description_;
  std::string path_;
};

/// One co-simulation instance. Every call throws FmuError (naming the call, the variables and what
/// the FMU logged) when the FMU answers Error or Fatal, and after Fatal every further call does too;
/// Warning is passed to the log and goes on; Discard from do_step throws as well.
///
/// Calls out of FMI's order (do_step before exit_initialization, a second enter_initialization) and
/// value references that are not variables of the call's type are refused before the FMU sees them.
/// After Error or Discard the destructor only frees; after Fatal nothing but free is called.
/// Instances are created with logging off (FMI's "debug logging"): FMUs still log their errors.
/// Thread-safety: one instance is used by one thread at a time; instances of one FMU may run on
/// different threads as far as the FMU itself allows (FMI requires it, not every FMU honours it).
class Instance {
 public:
  virtual ~Instance() = default;  ///< terminates (when initialised) and frees the instance

  /// FMI 2: fmi2SetupExperiment + fmi2EnterInitializationMode; FMI 3: fmi3EnterInitializationMode.
  /// Parameters and start values are set between instantiate and this, or between this and
  /// exit_initialization.
  virtual void enter_initialization(double start_time_s, std::optional<double> stop_time_s = std::nullopt) = 0;
  virtual void exit_initialization() = 0;
  /// One communication step from t (the current communication point) to t + h.
  virtual void do_step(double t_s, double h_s) = 0;
  virtual void terminate() = 0;
  virtual void reset() = 0;

  /// Real (FMI 3: Float64), Integer (Int32; FMI 2: also Enumeration), Boolean and String values by
  /// value reference; the spans have equal lengths.
  virtual void get_real(std::span<const ValueReference> vr, std::span<double> values) = 0;
  virtual void set_real(std::span<const ValueReference> vr, std::span<const double> values) = 0;
  virtual void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) = 0;
  virtual void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) = 0;
  virtual void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) = 0;
  virtual void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) = 0;
  virtual void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) = 0;

  const ModelDescription& description() const { return fmu_->description(); }
  const std::shared_ptr<Fmu>& fmu() const { return fmu_; }

 protected:
  explicit Instance(std::shared_ptr<Fmu> fmu) : fmu_(std::move(fmu)) {}
  std::shared_ptr<Fmu> fmu_;
};

}  // namespace quadcosim::fmi
