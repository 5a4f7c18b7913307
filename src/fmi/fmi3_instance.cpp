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

class Fmi3Fmu final : public LoadedFmu {
 public:
  Fmi3Fmu(ModelDescription md, std::string path, FmuFiles files)
      : LoadedFmu(std::move(md), std::move(path), std::move(files)) {
    const Library& l = library();
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
    check_version(f_.get_version(), "fmi3GetVersion", "3.");
    // FMI 3 passes a directory path ending in a separator, or null when there is no resources/.
    const std::filesystem::path resources = std::filesystem::path(root()) / "resources";
    std::error_code ec;
    if (std::filesystem::is_directory(resources, ec)) resource_path_ = resources.string() + "/";
  }

  std::unique_ptr<Instance> instantiate(const std::string& instance_name, LogSink log) override;

  const Fmi3Functions& functions() const { return f_; }
  const std::string& resource_path() const { return resource_path_; }

 private:
  Fmi3Functions f_{};
  std::string resource_path_;  ///< "" when the FMU has no resources
};

class Fmi3Instance final : public CheckedInstance {
 public:
  Fmi3Instance(const std::shared_ptr<Fmi3Fmu>& fmu, const std::string& name, LogSink log)
      : CheckedInstance(fmu, name, std::move(log)), fmu3_(*fmu), f_(fmu->functions()) {
    const ModelDescription& md = fmu->description();
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
    terminate_quietly_by("fmi3Terminate", [&] { return f_.terminate(instance_); });
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
    exit_initialization_by("fmi3ExitInitializationMode", [&] { return f_.exit_initialization_mode(instance_); });
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
    terminate_by("fmi3Terminate", [&] { return f_.terminate(instance_); });
  }

  void reset() override {
    reset_by("fmi3Reset", [&] { return f_.reset(instance_); });
  }

  // FMI 3 takes the number of values too: one per value reference here (no arrays).
  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    get_by("fmi3GetFloat64", vr, values, VariableType::kReal,
           [&] { return f_.get_float64(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    set_by("fmi3SetFloat64", vr, values, VariableType::kReal,
           [&] { return f_.set_float64(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    get_by("fmi3GetInt32", vr, values, VariableType::kInteger,
           [&] { return f_.get_int32(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    set_by("fmi3SetInt32", vr, values, VariableType::kInteger,
           [&] { return f_.set_int32(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    get_by("fmi3GetBoolean", vr, values, VariableType::kBoolean,
           [&] { return f_.get_boolean(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    set_by("fmi3SetBoolean", vr, values, VariableType::kBoolean,
           [&] { return f_.set_boolean(instance_, vr.data(), vr.size(), values.data(), values.size()); });
  }

  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    set_by("fmi3SetString", vr, values, VariableType::kString, [&] {
      strings_.resize(vr.size());
      for (std::size_t i = 0; i < vr.size(); ++i) strings_[i] = values[i].c_str();
      return f_.set_string(instance_, vr.data(), vr.size(), strings_.data(), strings_.size());
    });
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

  Fmi3Fmu& fmu3_;
  const Fmi3Functions& f_;
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
