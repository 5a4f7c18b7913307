// FMI 3.0 co-simulation: the loaded FMU (its binary and the functions the master calls) and its
// instances (fmi/fmu.hpp). Real is Float64 and Integer is Int32 here; no event mode, no early
// return, no intermediate update (the master asks for none of them at instantiation).
#include <fmt/format.h>

#include <atomic>
#include <filesystem>
#include <vector>

#include "fmi/api/fmi3.h"
#include "fmi/fmu_internal.hpp"

namespace quadcosim::fmi::detail {
namespace {

/// The FMI 3 functions the master calls, all resolved when the FMU is loaded.
struct Fmi3Functions {
  fmi3GetVersionTYPE* get_version;
  fmi3InstantiateCoSimulationTYPE* instantiate;
  fmi3FreeInstanceTYPE* free_instance;
  fmi3EnterInitializationModeTYPE* enter_initialization_mode;
  fmi3ExitInitializationModeTYPE* exit_initialization_mode;
  fmi3DoStepTYPE* do_step;
  fmi3TerminateTYPE* terminate;
  fmi3ResetTYPE* reset;
  fmi3GetFloat64TYPE* get_float64;
  fmi3SetFloat64TYPE* set_float64;
  fmi3GetInt32TYPE* get_int32;
  fmi3SetInt32TYPE* set_int32;
  fmi3GetBooleanTYPE* get_boolean;
  fmi3SetBooleanTYPE* set_boolean;
  fmi3SetStringTYPE* set_string;
};

Status status_of(fmi3Status s) { return static_cast<Status>(static_cast<int>(s)); }

class Fmi3Fmu final : public Fmu {
 public:
  Fmi3Fmu(ModelDescription md, std::string path, FmuFiles files)
      : files_(std::move(files)), library_(binary_path(md, files_.root, path)) {
    const Library& l = library_;
    f_ = Fmi3Functions{
        l.function<fmi3GetVersionTYPE>("fmi3GetVersion"),
        l.function<fmi3InstantiateCoSimulationTYPE>("fmi3InstantiateCoSimulation"),
        l.function<fmi3FreeInstanceTYPE>("fmi3FreeInstance"),
        l.function<fmi3EnterInitializationModeTYPE>("fmi3EnterInitializationMode"),
        l.function<fmi3ExitInitializationModeTYPE>("fmi3ExitInitializationMode"),
        l.function<fmi3DoStepTYPE>("fmi3DoStep"),
        l.function<fmi3TerminateTYPE>("fmi3Terminate"),
        l.function<fmi3ResetTYPE>("fmi3Reset"),
        l.function<fmi3GetFloat64TYPE>("fmi3GetFloat64"),
        l.function<fmi3SetFloat64TYPE>("fmi3SetFloat64"),
        l.function<fmi3GetInt32TYPE>("fmi3GetInt32"),
        l.function<fmi3SetInt32TYPE>("fmi3SetInt32"),
        l.function<fmi3GetBooleanTYPE>("fmi3GetBoolean"),
        l.function<fmi3SetBooleanTYPE>("fmi3SetBoolean"),
        l.function<fmi3SetStringTYPE>("fmi3SetString"),
    };
    const char* version = f_.get_version();
    if (version == nullptr || std::string_view(version).substr(0, 2) != "3.") {
      throw FmuError(fmt::format("{}: fmi3GetVersion() answers '{}', not 3.x as its modelDescription.xml says",
                                 library_.file(), version != nullptr ? version : "(null)"));
    }
    // FMI 3 passes a directory path ending in a separator, or null when there is no resources/.
    const std::filesystem::path resources = std::filesystem::path(files_.root) / "resources";
    std::error_code ec;
    if (std::filesystem::is_directory(resources, ec)) resource_path_ = resources.string() + "/";
    description_ = std::move(md);
    path_ = std::move(path);
  }

  std::unique_ptr<Instance> instantiate(const std::string& instance_name, LogSink log) override;

  const Fmi3Functions& functions() const { return f_; }
  const std::string& resource_path() const { return resource_path_; }
  std::atomic<int> live_instances{0};

 private:
  FmuFiles files_;  // removed after the library is closed (members go in reverse order)
  Library library_;
  Fmi3Functions f_{};
  std::string resource_path_;  ///< "" when the FMU has no resources
};

class Fmi3Instance final : public Instance {
 public:
  Fmi3Instance(std::shared_ptr<Fmi3Fmu> fmu, const std::string& name, LogSink log)
      : Instance(fmu), fmu3_(*fmu), f_(fmu->functions()), core_(*fmu, name, std::move(log)) {
    const ModelDescription& md = fmu->description();
    if (md.can_be_instantiated_only_once_per_process && fmu3_.live_instances.load() > 0) {
      throw FmuError(
          fmt::format("FMU '{}' ({}): can be instantiated only once per process, and an instance "
                      "exists: refused instance '{}'",
                      md.model_name, fmu->path(), name));
    }
    core_.begin("fmi3InstantiateCoSimulation");
    const std::string& resources = fmu3_.resource_path();
    instance_ = f_.instantiate(name.c_str(), md.guid.c_str(), resources.empty() ? nullptr : resources.c_str(),
                               fmi3False, fmi3False, /*eventModeUsed=*/fmi3False, /*earlyReturnAllowed=*/fmi3False,
                               nullptr, 0, this, &Fmi3Instance::log_message, nullptr);
    if (instance_ == nullptr) {
      throw FmuError(core_.failure(fmt::format("fmi3InstantiateCoSimulation(instantiationToken {}, resources {})",
                                               md.guid, resources.empty() ? "none" : resources),
                                   "returned no instance"));
    }
    ++fmu3_.live_instances;
  }

  ~Fmi3Instance() override {
    if (instance_ == nullptr) return;
    // Terminate a running instance that did not fail. Nothing may escape a destructor.
    if (!core_.broken() && !core_.errored && core_.phase == InstanceCore::Phase::kStepping) {
      try {
        core_.begin("fmi3Terminate");
        f_.terminate(instance_);
      } catch (...) {
      }
    }
    f_.free_instance(instance_);
    --fmu3_.live_instances;
  }

  void enter_initialization(double start_time_s, std::optional<double> stop_time_s) override {
    core_.expect(InstanceCore::Phase::kInstantiated, "fmi3EnterInitializationMode");
    core_.begin("fmi3EnterInitializationMode");
    core_.check(status_of(f_.enter_initialization_mode(instance_, fmi3False, 0.0, start_time_s,
                                                       stop_time_s ? fmi3True : fmi3False, stop_time_s.value_or(0.0))),
                [&] {
                  return stop_time_s ? fmt::format("fmi3EnterInitializationMode(start = {}, stop = {})", start_time_s,
                                                   *stop_time_s)
                                     : fmt::format("fmi3EnterInitializationMode(start = {})", start_time_s);
                });
    core_.phase = InstanceCore::Phase::kInitializing;
  }

  void exit_initialization() override {
    core_.expect(InstanceCore::Phase::kInitializing, "fmi3ExitInitializationMode");
    core_.begin("fmi3ExitInitializationMode");
    core_.check(status_of(f_.exit_initialization_mode(instance_)), [] { return "fmi3ExitInitializationMode"; });
    core_.phase = InstanceCore::Phase::kStepping;
  }

  void do_step(double t_s, double h_s) override {
    core_.expect(InstanceCore::Phase::kStepping, "fmi3DoStep");
    core_.begin("fmi3DoStep");
    fmi3Boolean event_handling_needed = fmi3False, terminate_simulation = fmi3False, early_return = fmi3False;
    fmi3Float64 last_successful_time = 0.0;
    core_.check(status_of(f_.do_step(instance_, t_s, h_s, fmi3True, &event_handling_needed, &terminate_simulation,
                                     &early_return, &last_successful_time)),
                [&] { return fmt::format("fmi3DoStep(t = {}, h = {})", t_s, h_s); });
    if (terminate_simulation) {
      core_.errored = true;
      throw FmuError(
          core_.failure(fmt::format("fmi3DoStep(t = {}, h = {})", t_s, h_s), "asked to terminate the simulation"));
    }
    if (early_return) {  // not allowed at instantiation, so the step is incomplete against the standard
      core_.errored = true;
      throw FmuError(core_.failure(
          fmt::format("fmi3DoStep(t = {}, h = {})", t_s, h_s),
          fmt::format("returned early at t = {} though early return was not allowed", last_successful_time)));
    }
  }

  void terminate() override {
    core_.expect(InstanceCore::Phase::kStepping, "fmi3Terminate");
    core_.begin("fmi3Terminate");
    core_.phase = InstanceCore::Phase::kTerminated;  // also when it fails: not again at destruction
    core_.check(status_of(f_.terminate(instance_)), [] { return "fmi3Terminate"; });
  }

  void reset() override {
    core_.begin("fmi3Reset");
    core_.check(status_of(f_.reset(instance_)), [] { return "fmi3Reset"; });
    core_.phase = InstanceCore::Phase::kInstantiated;
    core_.errored = false;
  }

  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    prepare("fmi3GetFloat64", vr, values.size(), VariableType::kReal);
    core_.check(status_of(f_.get_float64(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3GetFloat64({})", describe(core_, vr, VariableType::kReal)); });
  }

  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    prepare("fmi3SetFloat64", vr, values.size(), VariableType::kReal);
    core_.check(status_of(f_.set_float64(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3SetFloat64({})", describe(core_, vr, VariableType::kReal, values)); });
  }

  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    prepare("fmi3GetInt32", vr, values.size(), VariableType::kInteger);
    core_.check(status_of(f_.get_int32(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3GetInt32({})", describe(core_, vr, VariableType::kInteger)); });
  }

  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    prepare("fmi3SetInt32", vr, values.size(), VariableType::kInteger);
    core_.check(status_of(f_.set_int32(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3SetInt32({})", describe(core_, vr, VariableType::kInteger, values)); });
  }

  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    prepare("fmi3GetBoolean", vr, values.size(), VariableType::kBoolean);
    core_.check(status_of(f_.get_boolean(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3GetBoolean({})", describe(core_, vr, VariableType::kBoolean)); });
  }

  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    prepare("fmi3SetBoolean", vr, values.size(), VariableType::kBoolean);
    core_.check(status_of(f_.set_boolean(instance_, vr.data(), vr.size(), values.data(), values.size())),
                [&] { return fmt::format("fmi3SetBoolean({})", describe(core_, vr, VariableType::kBoolean, values)); });
  }

  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    prepare("fmi3SetString", vr, values.size(), VariableType::kString);
    strings_.resize(vr.size());
    for (std::size_t i = 0; i < vr.size(); ++i) strings_[i] = values[i].c_str();
    core_.check(status_of(f_.set_string(instance_, vr.data(), vr.size(), strings_.data(), strings_.size())),
                [&] { return fmt::format("fmi3SetString({})", describe(core_, vr, VariableType::kString, values)); });
  }

 private:
  static void log_message(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                          fmi3String message) {
    if (environment == nullptr) return;
    try {
      static_cast<Fmi3Instance*>(environment)->core_.on_log(status_of(status), category, message);
    } catch (...) {  // nothing may unwind into the FMU's C code
    }
  }

  /// Checks the call may be made: the instance is usable, the spans match, the variables exist.
  void prepare(std::string_view call, std::span<const ValueReference> vr, std::size_t n_values, VariableType type) {
    core_.begin(call);
    if (vr.size() != n_values) {
      throw FmuError(fmt::format("{} of FMU '{}' instance '{}': {} value references but {} values", call,
                                 description().model_name, core_.instance_name(), vr.size(), n_values));
    }
    core_.check_known(call, vr, type);
  }

  Fmi3Fmu& fmu3_;
  const Fmi3Functions& f_;
  InstanceCore core_;
  fmi3Instance instance_ = nullptr;
  std::vector<fmi3String> strings_;
};

std::unique_ptr<Instance> Fmi3Fmu::instantiate(const std::string& instance_name, LogSink log) {
  return std::make_unique<Fmi3Instance>(std::static_pointer_cast<Fmi3Fmu>(shared_from_this()), instance_name,
                                        std::move(log));
}

}  // namespace

std::shared_ptr<Fmu> make_fmi3_fmu(ModelDescription md, std::string path, FmuFiles files) {
  return std::make_shared<Fmi3Fmu>(std::move(md), std::move(path), std::move(files));
}

}  // namespace quadcosim::fmi::detail
