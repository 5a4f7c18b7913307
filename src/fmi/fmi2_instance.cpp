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

class Fmi2Fmu final : public LoadedFmu {
 public:
  Fmi2Fmu(ModelDescription md, std::string path, FmuFiles files)
      : LoadedFmu(std::move(md), std::move(path), std::move(files)) {
    const Library& l = library();
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
    check_version(f_.get_version(), "fmi2GetVersion", "2.");
    const char* platform = f_.get_types_platform();
    if (platform == nullptr || std::string_view(platform) != fmi2TypesPlatform) {
      throw FmuError(fmt::format("{}: fmi2GetTypesPlatform() answers '{}', not '{}'", l.file(),
                                 platform != nullptr ? platform : "(null)", fmi2TypesPlatform));
    }
    resource_uri_ = file_uri((std::filesystem::path(root()) / "resources").string());
  }

  std::unique_ptr<Instance> instantiate(const std::string& instance_name, LogSink log) override;

  const Fmi2Functions& functions() const { return f_; }
  const std::string& resource_uri() const { return resource_uri_; }

 private:
  Fmi2Functions f_{};
  std::string resource_uri_;
};

class Fmi2Instance final : public CheckedInstance {
 public:
  Fmi2Instance(const std::shared_ptr<Fmi2Fmu>& fmu, const std::string& name, LogSink log)
      : CheckedInstance(fmu, name, std::move(log)), fmu2_(*fmu), f_(fmu->functions()) {
    callbacks_.logger = &Fmi2Instance::logger;
    callbacks_.allocateMemory = [](std::size_t n, std::size_t size) { return std::calloc(n, size); };
    callbacks_.freeMemory = [](void* p) { std::free(p); };
    callbacks_.stepFinished = nullptr;
    callbacks_.componentEnvironment = this;
    const ModelDescription& md = fmu->description();
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
    terminate_quietly_by("fmi2Terminate", [&] { return f_.terminate(component_); });
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
    call_by("fmi2EnterInitializationMode", [&] { return f_.enter_initialization_mode(component_); });
    core_.phase = InstanceCore::Phase::kInitializing;
  }

  void exit_initialization() override {
    exit_initialization_by("fmi2ExitInitializationMode", [&] { return f_.exit_initialization_mode(component_); });
  }

  void do_step(double t_s, double h_s) override {
    core_.expect(InstanceCore::Phase::kStepping, "fmi2DoStep");
    core_.begin("fmi2DoStep");
    core_.check(status_of(f_.do_step(component_, t_s, h_s, fmi2True)),
                [&] { return fmt::format("fmi2DoStep(t = {}, h = {})", t_s, h_s); });
  }

  void terminate() override {
    terminate_by("fmi2Terminate", [&] { return f_.terminate(component_); });
  }

  void reset() override {
    reset_by("fmi2Reset", [&] { return f_.reset(component_); });
  }

  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    get_by("fmi2GetReal", vr, values, VariableType::kReal,
           [&] { return f_.get_real(component_, vr.data(), vr.size(), values.data()); });
  }

  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    set_by("fmi2SetReal", vr, values, VariableType::kReal,
           [&] { return f_.set_real(component_, vr.data(), vr.size(), values.data()); });
  }

  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    get_by("fmi2GetInteger", vr, values, VariableType::kInteger,
           [&] { return f_.get_integer(component_, vr.data(), vr.size(), values.data()); });
  }

  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    set_by("fmi2SetInteger", vr, values, VariableType::kInteger,
           [&] { return f_.set_integer(component_, vr.data(), vr.size(), values.data()); });
  }

  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    get_by("fmi2GetBoolean", vr, values, VariableType::kBoolean, [&] {
      booleans_.resize(vr.size());
      return f_.get_boolean(component_, vr.data(), vr.size(), booleans_.data());
    });
    for (std::size_t i = 0; i < vr.size(); ++i) values[i] = booleans_[i] != fmi2False;
  }

  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    set_by("fmi2SetBoolean", vr, values, VariableType::kBoolean, [&] {
      booleans_.resize(vr.size());
      for (std::size_t i = 0; i < vr.size(); ++i) booleans_[i] = values[i] ? fmi2True : fmi2False;
      return f_.set_boolean(component_, vr.data(), vr.size(), booleans_.data());
    });
  }

  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    set_by("fmi2SetString", vr, values, VariableType::kString, [&] {
      strings_.resize(vr.size());
      for (std::size_t i = 0; i < vr.size(); ++i) strings_[i] = values[i].c_str();
      return f_.set_string(component_, vr.data(), vr.size(), strings_.data());
    });
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

  Fmi2Fmu& fmu2_;
  const Fmi2Functions& f_;
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
