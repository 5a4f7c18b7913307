// python/embedded/isolated_controller.hpp: a Python controller served by a child process.
#include "python/embedded/isolated_controller.hpp"

#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "isolation/child.hpp"
#include "sim/controller_node.hpp"

namespace py = pybind11;

namespace quadcosim::embedded_python {

namespace {

using isolation::Child;
using isolation::Reader;
using isolation::Writer;

enum class Op : std::uint8_t { kStep = 1, kReset, kSetParameters };
constexpr std::uint8_t kAnswer = 'A', kFailed = 'F';

void put_settings(Writer& w, std::span<const control::Setting> settings) {
  w.put(static_cast<std::uint64_t>(settings.size()));
  for (const control::Setting& s : settings) {
    w.text(s.name);
    if (const double* d = std::get_if<double>(&s.value)) {
      w.put(std::uint8_t{0}).put(*d);
    } else {
      w.put(std::uint8_t{1}).text(std::get<std::string>(s.value));
    }
  }
}

std::vector<control::Setting> get_settings(Reader& r) {
  std::vector<control::Setting> out(static_cast<std::size_t>(r.get<std::uint64_t>()));
  for (control::Setting& s : out) {
    s.name = r.text();
    if (r.get<std::uint8_t>() == 0) {
      s.value = r.get<double>();
    } else {
      s.value = r.text();
    }
  }
  return out;
}

/// What the controller printed reaches the terminal before its process answers (or ends).
void flush_python_streams() {
  const py::gil_scoped_acquire gil;
  try {
    const py::module_ sys = py::module_::import("sys");
    for (const char* stream : {"stdout", "stderr"}) {
      if (const py::object s = sys.attr(stream); !s.is_none()) s.attr("flush")();
    }
  } catch (const py::error_already_set&) {
    // a stream that cannot be flushed: nothing to report it to
  }
}

// ---- the child: flies its copy of the prototype until the parent closes the socket ----------------

void serve(int fd, const python::PyController& prototype, const std::vector<control::Setting>& applied) {
  PyOS_AfterFork_Child();  // this thread holds the GIL, taken before the fork
  const auto fail = [fd](const std::string& what) {
    Writer w;
    w.put(kFailed).text(what);
    isolation::send_all(fd, w.bytes);
  };
  std::unique_ptr<control::Controller> c;
  try {
    c = prototype.clone();
    if (!applied.empty()) {
      if (const std::string why = c->set_parameters(applied); !why.empty()) throw std::runtime_error(why);
    }
  } catch (const std::exception& e) {
    fail(e.what());
    _exit(0);
  }
  PyEval_SaveThread();  // every call of the controller takes the GIL itself
  {
    Writer w;
    w.put(kAnswer);
    if (!isolation::send_all(fd, w.bytes)) _exit(0);
  }
  control::ControllerOutput out;
  out.outputs.assign(c->output_names().size(), 0.0);
  std::vector<std::uint8_t> in;
  while (isolation::receive(fd, in)) {
    Writer w;
    w.put(kAnswer);
    try {
      Reader r(in);
      switch (r.get<Op>()) {
        case Op::kStep: {
          const auto o = r.get<control::Observation>();
          const auto ref = r.get<control::Reference>();
          const auto dt = r.get<double>();
          c->step(o, ref, dt, out);
          // The rotor speeds as their count and values (one per rotor), the flags as a bool[8] and the count.
          w.span<double>({out.omega_rad_s.data(), static_cast<std::size_t>(out.omega_rad_s.size())});
          w.put(out.U).put(out.roll_des_rad).put(out.pitch_des_rad).put(out.yaw_des_rad);
          w.put(out.attitude_error).put(out.rotor_saturated.value).put(out.rotor_saturated.count);
          w.put(out.tilt_saturated);
          w.span<double>(out.outputs);
          break;
        }
        case Op::kReset: c->reset(); break;
        case Op::kSetParameters: {
          const std::vector<control::Setting> settings = get_settings(r);
          w.text(c->set_parameters(settings));
          break;
        }
      }
    } catch (const std::exception& e) {
      flush_python_streams();
      fail(e.what());
      continue;
    }
    if (!isolation::send_all(fd, w.bytes)) break;
  }
  flush_python_streams();
  _exit(0);
}

// ---- the parent's side -----------------------------------------------------------------------------

class IsolatedPythonController final : public control::Controller {
 public:
  IsolatedPythonController(std::shared_ptr<const python::PyController> prototype, std::vector<control::Setting> applied)
      : prototype_(std::move(prototype)), applied_(std::move(applied)) {
    step_timeout_s_ = prototype_->step_timeout_s();
    for (const control::Setting& s : applied_) note_setting(s);
  }

  ~IsolatedPythonController() override {
    if (child_) child_->finish(1000);
  }

  std::string_view type() const override { return "python"; }
  /// Its steps wait on the child process (a Python step that can block): hosts give it a thread.
  bool wants_own_thread() const override { return true; }

  std::unique_ptr<control::Controller> clone() const override {
    const std::lock_guard lock(mirror_mutex_);
    return std::make_unique<IsolatedPythonController>(prototype_, applied_);
  }

  std::span<const control::ParameterSpec> parameters() const override { return prototype_->parameters(); }

  std::optional<control::ParameterValue> get_parameter(std::string_view name) const override {
    const std::lock_guard lock(mirror_mutex_);  // answered here, also while a step runs
    for (auto it = applied_.rbegin(); it != applied_.rend(); ++it) {
      if (it->name == name) return it->value;
    }
    return prototype_->get_parameter(name);
  }

  std::string set_parameters(std::span<const control::Setting> settings) override {
    const std::lock_guard lock(mutex_);
    Reader r = call([] { return std::string("set_parameters"); },
                    [&](Writer& w) { put_settings(w.put(Op::kSetParameters), settings); });
    std::string why = r.text();
    if (why.empty()) {
      const std::lock_guard mirror(mirror_mutex_);
      for (const control::Setting& s : settings) {
        applied_.push_back(s);
        note_setting(s);
      }
    }
    return why;
  }

  std::span<const std::string> output_names() const override { return prototype_->output_names(); }

  void reset() override {
    const std::lock_guard lock(mutex_);
    call([] { return std::string("reset"); }, [](Writer& w) { w.put(Op::kReset); });
    steps_ = 0;
  }

  void step(const control::Observation& o, const control::Reference& ref, double dt_s,
            control::ControllerOutput& out) override {
    const std::lock_guard lock(mutex_);
    const long long n = steps_++;
    const double t = static_cast<double>(n) * dt_s;
    const double limit_s = timeout_s();
    const std::int64_t deadline =
        limit_s > 0.0 ? Child::now_ns() + static_cast<std::int64_t>((limit_s + kGraceS) * 1e9) : 0;
    std::optional<Reader> answer;
    try {
      answer.emplace(call([&] { return fmt::format("{}.step at step {} (t = {:g} s)", prototype_->name(), n, t); },
                          [&](Writer& w) { w.put(Op::kStep).put(o).put(ref).put(dt_s); }, false, deadline));
    } catch (const isolation::Interrupted&) {
      throw;
    } catch (const std::exception& e) {
      throw sim::ControllerFailure(e.what());  // exit 5, as for any controller whose step failed
    }
    Reader& r = *answer;
    const std::vector<double> omega = r.vec<double>();
    if (omega.empty() || omega.size() > static_cast<std::size_t>(model::kMaxRotors)) {
      throw std::runtime_error(
          fmt::format("{}.step: {} rotor speeds from its process, expected 4 to 8", prototype_->name(), omega.size()));
    }
    out.omega_rad_s = Eigen::Map<const model::RotorVector>(omega.data(), static_cast<Eigen::Index>(omega.size()));
    out.U = r.get<Eigen::Vector4d>();
    out.roll_des_rad = r.get<double>();
    out.pitch_des_rad = r.get<double>();
    out.yaw_des_rad = r.get<double>();
    out.attitude_error = r.get<double>();
    out.rotor_saturated.value = r.get<std::array<bool, model::kMaxRotors>>();
    out.rotor_saturated.count = r.get<int>();
    out.tilt_saturated = r.get<bool>();
    const std::vector<double> figures = r.vec<double>();
    if (figures.size() != out.outputs.size()) {
      throw std::runtime_error(fmt::format("{}.step: {} outputs from its process, {} expected", prototype_->name(),
                                           figures.size(), out.outputs.size()));
    }
    std::copy(figures.begin(), figures.end(), out.outputs.begin());
  }

 private:
  /// How long past step_timeout_s a step that StepTimeout did not stop gets before its process is killed.
  static constexpr double kGraceS = 1.0;

  double timeout_s() const {
    const std::lock_guard mirror(mirror_mutex_);
    return step_timeout_s_;
  }

  void note_setting(const control::Setting& s) {
    if (s.name == "step_timeout_s") {
      if (const double* v = std::get_if<double>(&s.value)) step_timeout_s_ = *v;
    }
  }

  /// The child, at the first call (a prototype that is only cloned never starts one).
  void start() {
    {
      // The fork happens with the GIL held and Python told (as os.fork does), so the child's
      // interpreter is whole whatever other threads of this process were doing with it.
      const py::gil_scoped_acquire gil;
      PyOS_BeforeFork();
      try {
        child_ = std::make_unique<Child>(fmt::format("Python controller {}", prototype_->name()),
                                         [this](int fd) { serve(fd, *prototype_, applied_); });
      } catch (...) {
        PyOS_AfterFork_Parent();
        throw;
      }
      PyOS_AfterFork_Parent();
    }
    call([] { return std::string("making its copy"); }, [](Writer&) {}, /*first=*/true);
  }

  /// Sends the request `fill` writes and returns the answer's payload. Throws std::runtime_error with
  /// the child's message when the call failed there, naming `what()` when the child ended or overran
  /// the deadline, isolation::Interrupted on a stop request.
  template <class What, class Fill>
  Reader call(What&& what, Fill&& fill, bool first = false, std::int64_t deadline_ns = 0) {
    if (!child_) start();
    if (child_->ended()) {
      throw std::runtime_error(
          fmt::format("{}: refused, the controller's process has ended ({})", what(), child_->end()));
    }
    if (!first) {
      Writer w;
      fill(w);
      if (!child_->send(w.bytes)) ended(what());
    }
    for (;;) {
      switch (child_->next(answer_, deadline_ns)) {
        case Child::Wait::kMessage: break;
        case Child::Wait::kEnded: ended(what());
        case Child::Wait::kTimedOut:
          child_->kill("killed");
          throw std::runtime_error(fmt::format(
              "{}: did not return within step_timeout_s = {:g} s, nor {:g} s after quadcosim.StepTimeout was "
              "raised in it (blocked outside Python); its process was killed",
              what(), timeout_s(), kGraceS));
        case Child::Wait::kStopped:
          child_->kill("killed on a stop request");
          throw isolation::Interrupted(fmt::format(
              "{}: interrupted (Ctrl-C or SIGTERM) while the controller was inside it; its process was killed",
              what()));
      }
      if (answer_.empty()) continue;
      Reader r(std::span<const std::uint8_t>(answer_).subspan(1));
      if (answer_[0] == kFailed) throw std::runtime_error(r.text());
      return r;
    }
  }

  [[noreturn]] void ended(const std::string& what) {
    throw std::runtime_error(fmt::format(
        "{}: the controller's process {} inside it (it flies in a process of its own: the run goes on to write "
        "its outputs)",
        what, child_->reap()));
  }

  std::shared_ptr<const python::PyController> prototype_;
  std::vector<control::Setting> applied_;  ///< accepted settings since the prototype, in order
  double step_timeout_s_ = 0.0;
  long long steps_ = 0;
  std::unique_ptr<Child> child_;
  std::vector<std::uint8_t> answer_;
  /// One call at a time on the socket (parameter changes come from other threads than the steps'): a
  /// change waits for the step in progress, as the child serves one request at a time.
  mutable std::mutex mutex_;
  mutable std::mutex mirror_mutex_;  ///< applied_ and step_timeout_s_: read without waiting for a step
};

}  // namespace

std::unique_ptr<control::Controller> isolate_python_controller(std::shared_ptr<const python::PyController> prototype) {
  return std::make_unique<IsolatedPythonController>(std::move(prototype), std::vector<control::Setting>{});
}

bool python_controllers_isolated() {
  const char* v = std::getenv("QUADCOSIM_PYTHON_IN_PROCESS");
  return v == nullptr || std::strcmp(v, "1") != 0;
}

}  // namespace quadcosim::embedded_python
