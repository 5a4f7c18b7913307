// What fmu.cpp, fmi2_instance.cpp and fmi3_instance.cpp share: the FMU's binary (dlopen), the loaded
// FMU's files, the log an instance keeps of what its FMU said, the instance's state and the checks
// the master makes around every FMI call, whichever the version. Not part of the library's interface.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>

#include "fmi/fmu.hpp"
#include "fmi/unzip.hpp"

namespace quadcosim::fmi::detail {

/// An FMU's shared library, dlopen'ed with RTLD_NOW | RTLD_LOCAL and closed on destruction.
class Library {
 public:
  /// Throws FmuError with dlerror()'s text.
  explicit Library(const std::string& file);
  ~Library();
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;

  /// The function `name` (an FMI function type such as fmi2DoStepTYPE). Throws FmuError naming the
  /// symbol and the file when the library lacks it.
  template <typename FunctionType>
  FunctionType* function(const char* name) const {
    return reinterpret_cast<FunctionType*>(symbol(name));
  }
  const std::string& file() const { return file_; }

 private:
  void* symbol(const char* name) const;
  void* handle_ = nullptr;
  std::string file_;
};

/// Where a loaded FMU's files are: `root` is the directory with modelDescription.xml (the unpacked
/// archive, or the directory given), `unpacked` owns it when it was unpacked here.
struct FmuFiles {
  std::string root;
  std::unique_ptr<TempDir> unpacked;
};

/// The binary of `md` below `root` for this platform (FMI 2: binaries/linux64, FMI 3:
/// binaries/x86_64-linux), checked to exist; FmuError naming the path and the platforms present.
std::string binary_path(const ModelDescription& md, const std::string& root, const std::string& fmu_path);

std::shared_ptr<Fmu> make_fmi2_fmu(ModelDescription md, std::string path, FmuFiles files);
std::shared_ptr<Fmu> make_fmi3_fmu(ModelDescription md, std::string path, FmuFiles files);

/// file:///... URI of an absolute path, percent-encoding every byte but unreserved characters and '/'.
std::string file_uri(const std::string& absolute_path);

/// Status codes as FMI 2 and 3 both number them.
enum class Status { kOk = 0, kWarning = 1, kDiscard = 2, kError = 3, kFatal = 4, kPending = 5 };
std::string_view to_string(Status s);

/// What every instance does besides its calls: keeps what its FMU logged, forwards it to the sink,
/// looks up variables' names for messages and checks a call's status.
class InstanceCore {
 public:
  InstanceCore(const Fmu& fmu, std::string instance_name, LogSink sink);

  /// The FMU's logger callbacks land here.
  void on_log(Status status, const char* category, const char* message);

  /// Before an FMI call: remembers where the log stood, and throws if the instance is broken (a call
  /// answered Fatal before).
  void begin(std::string_view call);
  /// After it: OK passes, Warning is logged and passes, anything else throws FmuError naming the call
  /// (`call()` makes its text with the arguments, e.g. "fmi2DoStep(t = 1, h = 0.01)", only when
  /// needed) and what the FMU logged during it. Fatal breaks the instance for good.
  template <typename Call>
  void check(Status status, Call&& call) {
    if (status != Status::kOk) handle(status, std::string(call()));
  }
  void handle(Status status, const std::string& call);
  /// FmuError text for a failed call (also used when instantiation returns null).
  std::string failure(const std::string& call, std::string_view what) const;

  /// "mass_kg = 2, g = 9.81" for a call's message: names by value reference and type.
  std::string name(ValueReference vr, VariableType type) const;
  /// Throws FmuError unless every `vr` is a variable of `type` in the description.
  void check_known(std::string_view call, std::span<const ValueReference> vrs, VariableType type) const;

  const std::string& instance_name() const { return instance_name_; }
  bool broken() const { return broken_; }
  /// Where the instance is in FMI's state machine, as far as the master's calls go.
  enum class Phase { kInstantiated, kInitializing, kStepping, kTerminated };
  Phase phase = Phase::kInstantiated;
  /// Throws FmuError naming `call` unless the instance is in `wanted` (the FMU is not asked then:
  /// not every FMU survives a call out of order).
  void expect(Phase wanted, std::string_view call) const;
  /// Set when a call answered Error or Discard (cleared by reset): no terminate at destruction then.
  bool errored = false;

 private:
  struct Message {
    Status status;
    std::string category, text;
  };
  const ModelDescription& md_;
  std::string instance_name_;
  LogSink sink_;
  std::deque<Message> recent_;  ///< the last messages, for errors
  std::size_t logged_ = 0;      ///< messages logged so far
  std::size_t call_start_ = 0;  ///< logged_ when the current call began
  bool broken_ = false;
  std::string broken_by_;
  std::unordered_map<std::uint64_t, std::size_t> by_vr_;  ///< (type, vr) -> index into variables
  /// Per value reference below kDenseLimit, one bit per VariableType it is known as: the check every
  /// get and set makes, without a hash lookup per value (value references above it use by_vr_).
  static constexpr ValueReference kDenseLimit = 1u << 16;
  std::vector<std::uint8_t> known_;
};

/// The variables of a call for its message: "p_W[3], v_W[3]", or with `values` "mass_kg = 2, g = 9.81"
/// (the first eight, then how many more).
template <typename T = double>
std::string describe(const InstanceCore& core, std::span<const ValueReference> vrs, VariableType type,
                     std::span<const T> values = {}) {
  std::string text;
  const std::size_t shown = std::min<std::size_t>(vrs.size(), 8);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) text += ", ";
    text += core.name(vrs[i], type);
    if (i < values.size()) text += fmt::format(" = {}", values[i]);
  }
  if (shown < vrs.size()) text += fmt::format(" and {} more", vrs.size() - shown);
  return text;
}

/// What the FMI 2 and FMI 3 FMUs share: their files, their binary and the count of live instances.
class LoadedFmu : public Fmu {
 public:
  std::atomic<int> live_instances{0};

 protected:
  LoadedFmu(ModelDescription md, std::string path, FmuFiles files)
      : files_(std::move(files)), library_(binary_path(md, files_.root, path)) {
    description_ = std::move(md);
    path_ = std::move(path);
  }
  const Library& library() const { return library_; }
  const std::string& root() const { return files_.root; }
  /// Throws FmuError unless `version`, what `function`() answered, starts with `major` ("2.", "3.").
  void check_version(const char* version, std::string_view function, std::string_view major) const {
    if (version == nullptr || std::string_view(version).substr(0, major.size()) != major) {
      throw FmuError(fmt::format("{}: {}() answers '{}', not {}x as its modelDescription.xml says", library_.file(),
                                 function, version != nullptr ? version : "(null)", major));
    }
  }

 private:
  FmuFiles files_;  // removed after the library is closed (members go in reverse order)
  Library library_;
};

/// What the FMI 2 and FMI 3 instances share: the master's checks around each call (the state
/// machine, the spans, the variables), the rule of one instance per process and the status checks.
/// The `*_by` calls take the FMI call itself, a function returning the standard's status.
class CheckedInstance : public Instance {
 protected:
  /// Refuses a second instance of an FMU that can be instantiated only once per process.
  CheckedInstance(const std::shared_ptr<LoadedFmu>& fmu, const std::string& name, LogSink log)
      : Instance(fmu), core_(*fmu, name, std::move(log)) {
    const ModelDescription& md = fmu->description();
    if (md.can_be_instantiated_only_once_per_process && fmu->live_instances.load() > 0) {
      throw FmuError(
          fmt::format("FMU '{}' ({}): can be instantiated only once per process, and an instance "
                      "exists: refused instance '{}'",
                      md.model_name, fmu->path(), name));
    }
  }

  template <typename FmiStatus>
  static Status status_of(FmiStatus s) {
    return static_cast<Status>(static_cast<int>(s));
  }

  /// The call `name`, made by `call` and checked.
  template <typename Call>
  void call_by(std::string_view name, Call&& call) {
    core_.begin(name);
    core_.check(status_of(call()), [name] { return name; });
  }

  template <typename Call>
  void exit_initialization_by(std::string_view name, Call&& call) {
    core_.expect(InstanceCore::Phase::kInitializing, name);
    call_by(name, call);
    core_.phase = InstanceCore::Phase::kStepping;
  }

  template <typename Call>
  void terminate_by(std::string_view name, Call&& call) {
    core_.expect(InstanceCore::Phase::kStepping, name);
    core_.begin(name);
    core_.phase = InstanceCore::Phase::kTerminated;  // also when it fails: not again at destruction
    core_.check(status_of(call()), [name] { return name; });
  }

  template <typename Call>
  void reset_by(std::string_view name, Call&& call) {
    call_by(name, call);
    core_.phase = InstanceCore::Phase::kInstantiated;
    core_.errored = false;
  }

  /// At destruction: terminates a running instance that did not fail (never after Error or Fatal).
  /// Nothing may escape a destructor.
  template <typename Call>
  void terminate_quietly_by(std::string_view name, Call&& call) noexcept {
    if (core_.broken() || core_.errored || core_.phase != InstanceCore::Phase::kStepping) return;
    try {
      core_.begin(name);
      call();
    } catch (...) {
    }
  }

  /// A get call: `values` are written by `call`.
  template <typename T, typename Call>
  void get_by(std::string_view name, std::span<const ValueReference> vr, std::span<T> values, VariableType type,
              Call&& call) {
    prepare(name, vr, values.size(), type);
    core_.check(status_of(call()), [&] { return fmt::format("{}({})", name, describe(core_, vr, type)); });
  }

  /// A set call: the message names the values.
  template <typename T, typename Call>
  void set_by(std::string_view name, std::span<const ValueReference> vr, std::span<const T> values, VariableType type,
              Call&& call) {
    prepare(name, vr, values.size(), type);
    core_.check(status_of(call()), [&] { return fmt::format("{}({})", name, describe(core_, vr, type, values)); });
  }

  InstanceCore core_;

 private:
  /// Checks the call may be made: the instance is usable, the spans match, the variables exist.
  void prepare(std::string_view call, std::span<const ValueReference> vr, std::size_t n_values, VariableType type) {
    core_.begin(call);
    if (vr.size() != n_values) {
      throw FmuError(fmt::format("{} of FMU '{}' instance '{}': {} value references but {} values", call,
                                 description().model_name, core_.instance_name(), vr.size(), n_values));
    }
    core_.check_known(call, vr, type);
  }
};

}  // namespace quadcosim::fmi::detail
