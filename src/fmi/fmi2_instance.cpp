// FMI 2.0 co-simulation: the loaded FMU (its binary and the functions the master calls) and its
// instances (fmi/fmu.hpp). Calls are checked against the master's own view of the state machine
// before the FMU sees them, and every status is checked after.
#include <fmt/format.h>

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "fmi/api/fmi2.h"
#include "fmi/fmu_internal.hpp"

namespace quadcosim::fmi::detail {
namespace {

/// The FMI 2 functions the master calls, all resolved when the FMU is loaded.
struct Fmi2Functions {
  fmi2GetTypesPlatformTYPE* get_types_platform;
  fmi2GetVersionTYPE* get_version;
  fmi2InstantiateTYPE* instantiate;
  fmi2FreeInstanceTYPE* free_instance;
  fmi2SetupExperimentTYPE* setup_experiment;
  fmi2EnterInitializationModeTYPE* enter_initialization_mode;
  fmi2ExitInitializationModeTYPE* exit_initialization_mode;
  fmi2DoStepTYPE* do_step;
  fmi2TerminateTYPE* terminate;
  fmi2ResetTYPE* reset;
  fmi2GetRealTYPE* get_real;
  fmi2SetRealTYPE* set_real;
  fmi2GetIntegerTYPE* get_integer;
  fmi2SetIntegerTYPE* set_integer;
  fmi2GetBooleanTYPE* get_boolean;
  fmi2SetBooleanTYPE* set_boolean;
  fmi2SetStringTYPE* set_string;
};

Status status_of(fmi2Status s) { return static_cast<Status>(static_cast<int>(s)); }

class Fmi2Fmu final : public Fmu {
 public:
  Fmi2Fmu(ModelDescription md, std::string path, FmuFiles files)
      : files_(std::move(files)), library_(binary_path(md, files_.root, path)) {
    const Library& l = library_;
    f_ = Fmi2Functions{
        l.function<fmi2GetTypesPlatformTYPE>("fmi2GetTypesPlatform"),
        l.function<fmi2GetVersionTYPE>("fmi2GetVersion"),
        l.function<fmi2InstantiateTYPE>("fmi2Instantiate"),
        l.function<fmi2FreeInstanceTYPE>("fmi2FreeInstance"),
        l.function<fmi2SetupExperimentTYPE>("fmi2SetupExperiment"),
        l.function<fmi2EnterInitializationModeTYPE>("fmi2EnterInitializationMode"),
        l.function<fmi2ExitInitializationModeTYPE>("fmi2ExitInitializationMode"),
        l.function<fmi2DoStepTYPE>("fmi2DoStep"),
        l.function<fmi2TerminateTYPE>("fmi2Terminate"),
        l.function<fmi2ResetTYPE>("fmi2Reset"),
        l.function<fmi2GetRealTYPE>("fmi2GetReal"),
        l.function<fmi2SetRealTYPE>("fmi2SetReal"),
        l.function<fmi2GetIntegerTYPE>("fmi2GetInteger"),
        l.function<fmi2SetIntegerTYPE>("fmi2SetInteger"),
        l.function<fmi2GetBooleanTYPE>("fmi2GetBoolean"),
        l.function<fmi2SetBooleanTYPE>("fmi2SetBoolean"),
        l.function<fmi2SetStringTYPE>("fmi2SetString"),
    };
    const char* version = f_.get_version();
    if (version == nullptr || std::string_view(version).substr(0, 2) != "2.") {
      throw FmuError(fmt::format("{}: fmi2GetVersion() answers '{}', not 2.x as its modelDescription.xml says",
                                 library_.file(), version != nullptr ? version : "(null)"));
    }
    const char* platform = f_.get_types_platform();
    if (platform == nullptr || std::string_view(platform) != fmi2TypesPlatform) {
      throw FmuError(fmt::format("{}: fmi2GetTypesPlatform() answers '{}', not '{}'", library_.file(),
                                 platform != nullptr ? platform : "(null)", fmi2TypesPlatform));
    }
    resource_uri_ = file_uri((std::filesystem::path(files_.root) / "resources").string());
    description_ = std::move(md);
    path_ = std::move(path);
  }

  std::unique_ptr<Instance> instantiate(const std::string& instance_name, LogSink log) override;

  const Fmi2Functions& functions() const { return f_; }
  const std::string& resource_uri() const { return resource_uri_; }
  std::atomic<int> live_instances{0};

 private:
  FmuFiles files_;  // removed after the library is closed (members go in reverse order)
  Library library_;
  Fmi2Functions f_{};
  std::string resource_uri_;
};

class Fmi2Instance final : public Instance {
 public:
  Fmi2Instance(std::shared_ptr<Fmi2Fmu> fmu, const std::string& name, LogSink log)
      : Instance(fmu), fmu2_(*fmu), f_(fmu->functions()), core_(*fmu, name, std::move(log)) {
    callbacks_.logger = &Fmi2Instance::logger;
    callbacks_.allocateMemory = [](std::size_t n, std::size_t size) { return std::calloc(n, size); };
    callbacks_.freeMemory = [](void* p) { std::free(p); };
    callbacks_.stepFinished = nullptr;
    callbacks_.componentEnvironment = this;
    const ModelDescription& md = fmu->description();
    if (md.can_be_instantiated_only_once_per_process && fmu2_.live_instances.load() > 0) {
      throw FmuError(
          fmt::format("FMU '{}' ({}): can be instantiated only once per process, and an instance "
                      "exists: refused instance '{}'",
                      md.model_name, fmu->path(), name));
    }
    core_.begin("fmi2Instantiate");
    component_ = f_.instantiate(name.c_str(), fmi2CoSimulation, md.guid.c_str(), fmu2_.resource_uri().c_str(),
                                &callbacks_, fmi2False, fmi2False);
    if (component_ == nullptr) {
      throw FmuError(core_.failure(fmt::format("fmi2Instantiate(GUID {}, resources {})", md.guid, fmu2_.resource_uri()),
                                   "returned no instance"));
    }
    ++fmu2_.live_instances;
  }

  ~Fmi2Instance() override {
    if (component_ == nullptr) return;
    // Terminate a running instance that did not fail; never after Error or Fatal (FMI 2 allows only
    // reset and free then). Nothing may escape a destructor.
    if (!core_.broken() && !core_.errored && core_.phase == InstanceCore::Phase::kStepping) {
      try {
        core_.begin("fmi2Terminate");
        f_.terminate(component_);
      } catch (...) {
      }
    }
    f_.free_instance(component_);
    --fmu2_.live_instances;
  }

  void enter_initialization(double start_time_s, std::optional<double> stop_time_s) override {
    core_.expect(InstanceCore::Phase::kInstantiated, "fmi2SetupExperiment");
    core_.begin("fmi2SetupExperiment");
    core_.check(status_of(f_.setup_experiment(component_, fmi2False, 0.0, start_time_s,
                                              stop_time_s ? fmi2True : fmi2False, stop_time_s.value_or(0.0))),
                [&] {
                  return stop_time_s
                             ? fmt::format("fmi2SetupExperiment(start = {}, stop = {})", start_time_s, *stop_time_s)
                             : fmt::format("fmi2SetupExperiment(start = {})", start_time_s);
                });
    core_.begin("fmi2EnterInitializationMode");
    core_.check(status_of(f_.enter_initialization_mode(component_)), [] { return "fmi2EnterInitializationMode"; });
    core_.phase = InstanceCore::Phase::kInitializing;
  }

  void exit_initialization() override {
    core_.expect(InstanceCore::Phase::kInitializing, "fmi2ExitInitializationMode");
    core_.begin("fmi2ExitInitializationMode");
    core_.check(status_of(f_.exit_initialization_mode(component_)), [] { return "fmi2ExitInitializationMode"; });
    core_.phase = InstanceCore::Phase::kStepping;
  }

  void do_step(double t_s, double h_s) override {
    core_.expect(InstanceCore::Phase::kStepping, "fmi2DoStep");
    core_.begin("fmi2DoStep");
    core_.check(status_of(f_.do_step(component_, t_s, h_s, fmi2True)),
                [&] { return fmt::format("fmi2DoStep(t = {}, h = {})", t_s, h_s); });
  }

  void terminate() override {
    core_.expect(InstanceCore::Phase::kStepping, "fmi2Terminate");
    core_.begin("fmi2Terminate");
    core_.phase = InstanceCore::Phase::kTerminated;  // also when it fails: not again at destruction
    core_.check(status_of(f_.terminate(component_)), [] { return "fmi2Terminate"; });
  }

  void reset() override {
    core_.begin("fmi2Reset");
    core_.check(status_of(f_.reset(component_)), [] { return "fmi2Reset"; });
    core_.phase = InstanceCore::Phase::kInstantiated;
    core_.errored = false;
  }

  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    prepare("fmi2GetReal", vr, values.size(), VariableType::kReal);
    core_.check(status_of(f_.get_real(component_, vr.data(), vr.size(), values.data())),
                [&] { return fmt::format("fmi2GetReal({})", describe(core_, vr, VariableType::kReal)); });
  }

  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    prepare("fmi2SetReal", vr, values.size(), VariableType::kReal);
    core_.check(status_of(f_.set_real(component_, vr.data(), vr.size(), values.data())),
                [&] { return fmt::format("fmi2SetReal({})", describe(core_, vr, VariableType::kReal, values)); });
  }

  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    prepare("fmi2GetInteger", vr, values.size(), VariableType::kInteger);
    core_.check(status_of(f_.get_integer(component_, vr.data(), vr.size(), values.data())),
                [&] { return fmt::format("fmi2GetInteger({})", describe(core_, vr, VariableType::kInteger)); });
  }

  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    prepare("fmi2SetInteger", vr, values.size(), VariableType::kInteger);
    core_.check(status_of(f_.set_integer(component_, vr.data(), vr.size(), values.data())),
                [&] { return fmt::format("fmi2SetInteger({})", describe(core_, vr, VariableType::kInteger, values)); });
  }

  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    prepare("fmi2GetBoolean", vr, values.size(), VariableType::kBoolean);
    booleans_.resize(vr.size());
    core_.check(status_of(f_.get_boolean(component_, vr.data(), vr.size(), booleans_.data())),
                [&] { return fmt::format("fmi2GetBoolean({})", describe(core_, vr, VariableType::kBoolean)); });
    for (std::size_t i = 0; i < vr.size(); ++i) values[i] = booleans_[i] != fmi2False;
  }

  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    prepare("fmi2SetBoolean", vr, values.size(), VariableType::kBoolean);
    booleans_.resize(vr.size());
    for (std::size_t i = 0; i < vr.size(); ++i) booleans_[i] = values[i] ? fmi2True : fmi2False;
    core_.check(status_of(f_.set_boolean(component_, vr.data(), vr.size(), booleans_.data())),
                [&] { return fmt::format("fmi2SetBoolean({})", describe(core_, vr, VariableType::kBoolean, values)); });
  }

  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    prepare("fmi2SetString", vr, values.size(), VariableType::kString);
    strings_.resize(vr.size());
    for (std::size_t i = 0; i < vr.size(); ++i) strings_[i] = values[i].c_str();
    core_.check(status_of(f_.set_string(component_, vr.data(), vr.size(), strings_.data())),
                [&] { return fmt::format("fmi2SetString({})", describe(core_, vr, VariableType::kString, values)); });
  }

 private:
  /// FMI 2's logger: a printf format and its arguments, formatted here.
  static void logger(fmi2ComponentEnvironment environment, fmi2String /*instance_name*/, fmi2Status status,
                     fmi2String category, fmi2String message, ...) {
    if (environment == nullptr) return;
    try {
      std::string text;
      if (message != nullptr) {
        va_list args;
        va_start(args, message);
        va_list measure;
        va_copy(measure, args);
        const int size = std::vsnprintf(nullptr, 0, message, measure);
        va_end(measure);
        if (size > 0) {
          text.resize(static_cast<std::size_t>(size) + 1);
          std::vsnprintf(text.data(), text.size(), message, args);
          text.resize(static_cast<std::size_t>(size));
        } else if (size < 0) {
          text = message;  // not a valid format: the text as it came
        }
        va_end(args);
      }
      static_cast<Fmi2Instance*>(environment)->core_.on_log(status_of(status), category, text.c_str());
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

  Fmi2Fmu& fmu2_;
  const Fmi2Functions& f_;
  InstanceCore core_;
  fmi2CallbackFunctions callbacks_{};  // the FMU may keep a pointer to it until it is freed
  fmi2Component component_ = nullptr;
  std::vector<fmi2Boolean> booleans_;
  std::vector<fmi2String> strings_;
};

std::unique_ptr<Instance> Fmi2Fmu::instantiate(const std::string& instance_name, LogSink log) {
  return std::make_unique<Fmi2Instance>(std::static_pointer_cast<Fmi2Fmu>(shared_from_this()), instance_name,
                                        std::move(log));
}

}  // namespace

std::shared_ptr<Fmu> make_fmi2_fmu(ModelDescription md, std::string path, FmuFiles files) {
  return std::make_shared<Fmi2Fmu>(std::move(md), std::move(path), std::move(files));
}

}  // namespace quadcosim::fmi::detail
