// fmi/isolated_instance.hpp: one child process per FMU instance (isolation/child.hpp), one datagram
// per request, per answer and per log line.
#include "fmi/isolated_instance.hpp"

#include "isolation/child.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace quadcosim::fmi {

namespace {

enum class Op : std::uint8_t {
  kEnterInitialization = 1,
  kExitInitialization,
  kDoStep,
  kTerminate,
  kReset,
  kGetReal,
  kSetReal,
  kGetInteger,
  kSetInteger,
  kGetBoolean,
  kSetBoolean,
  kSetString,
  kFree,
};
constexpr std::uint8_t kLog = 'L', kAnswer = 'A', kFailed = 'F';

using isolation::Child;
using isolation::Reader;
using isolation::send_all;
using isolation::Writer;

// ---- the child: serves calls on `fd` until kFree or the parent's end ------------------------------

void serve(int fd, const std::shared_ptr<Fmu>& fmu, const std::string& name) {
  const LogSink sink = [fd](const std::string& category, const std::string& status, const std::string& message) {
    Writer w;
    w.put(kLog).text(category).text(status).text(message);
    send_all(fd, w.bytes);
  };
  const auto fail = [fd](const std::string& what) {
    Writer w;
    w.put(kFailed).text(what);
    send_all(fd, w.bytes);
  };
  std::unique_ptr<Instance> instance;
  try {
    instance = fmu->instantiate(name, sink);
  } catch (const std::exception& e) {
    fail(e.what());
    _exit(0);
  }
  {
    Writer w;
    w.put(kAnswer);
    if (!send_all(fd, w.bytes)) _exit(0);
  }
  std::vector<std::uint8_t> in;
  while (isolation::receive(fd, in)) {
    Reader r(in);
    Writer out;
    out.put(kAnswer);
    const auto op = r.get<Op>();
    try {
      switch (op) {
        case Op::kEnterInitialization: {
          const auto t = r.get<double>();
          const auto has_stop = r.get<bool>();
          const auto stop = r.get<double>();
          instance->enter_initialization(t, has_stop ? std::optional<double>(stop) : std::nullopt);
          break;
        }
        case Op::kExitInitialization: instance->exit_initialization(); break;
        case Op::kDoStep: {
          const auto t = r.get<double>();
          const auto h = r.get<double>();
          instance->do_step(t, h);
          break;
        }
        case Op::kTerminate: instance->terminate(); break;
        case Op::kReset: instance->reset(); break;
        case Op::kGetReal: {
          const auto vr = r.vec<ValueReference>();
          std::vector<double> v(vr.size());
          instance->get_real(vr, v);
          out.span<double>(v);
          break;
        }
        case Op::kSetReal: {
          const auto vr = r.vec<ValueReference>();
          const auto v = r.vec<double>();
          instance->set_real(vr, v);
          break;
        }
        case Op::kGetInteger: {
          const auto vr = r.vec<ValueReference>();
          std::vector<std::int32_t> v(vr.size());
          instance->get_integer(vr, v);
          out.span<std::int32_t>(v);
          break;
        }
        case Op::kSetInteger: {
          const auto vr = r.vec<ValueReference>();
          const auto v = r.vec<std::int32_t>();
          instance->set_integer(vr, v);
          break;
        }
        case Op::kGetBoolean: {
          const auto vr = r.vec<ValueReference>();
          std::unique_ptr<bool[]> v(new bool[vr.size()]);
          instance->get_boolean(vr, std::span<bool>(v.get(), vr.size()));
          out.span<bool>(std::span<const bool>(v.get(), vr.size()));
          break;
        }
        case Op::kSetBoolean: {
          const auto vr = r.vec<ValueReference>();
          const auto n = static_cast<std::size_t>(r.get<std::uint64_t>());
          std::unique_ptr<bool[]> v(new bool[n]);
          for (std::size_t i = 0; i < n; ++i) v[i] = r.get<bool>();
          instance->set_boolean(vr, std::span<const bool>(v.get(), n));
          break;
        }
        case Op::kSetString: {
          const auto vr = r.vec<ValueReference>();
          std::vector<std::string> v(static_cast<std::size_t>(r.get<std::uint64_t>()));
          for (auto& s : v) s = r.text();
          instance->set_string(vr, v);
          break;
        }
        case Op::kFree:
          instance.reset();  // terminate (when due) and free, here where the FMU lives
          send_all(fd, out.bytes);
          _exit(0);
      }
    } catch (const std::exception& e) {
      fail(e.what());
      continue;
    }
    if (!send_all(fd, out.bytes)) break;
  }
  _exit(0);  // the parent is gone: nothing to free for
}

// ---- the parent's side ---------------------------------------------------------------------------

class IsolatedInstance final : public Instance {
 public:
  IsolatedInstance(const std::shared_ptr<Fmu>& fmu, const std::string& name, LogSink log, double call_timeout_s)
      : Instance(fmu),
        name_(name),
        log_(std::move(log)),
        call_timeout_ns_(call_timeout_s > 0.0 ? static_cast<std::int64_t>(call_timeout_s * 1e9) : 0),
        call_timeout_s_(call_timeout_s),
        prefix_(fmu->description().version == FmiVersion::k2 ? "fmi2" : "fmi3") {
    child_ = std::make_unique<Child>(fmt::format("FMU '{}'", fmu->description().model_name),
                                     [&](int fd) { serve(fd, fmu, name); });
    call([] { return std::string("instantiate"); }, [](Writer&) {}, /*instantiate=*/true);
  }

  ~IsolatedInstance() override {
    if (!child_->ended()) {
      Writer w;
      w.put(Op::kFree);
      if (child_->send(w.bytes)) {
        // Terminate and free get a while to answer; a child that hangs in them is killed (Child's end).
        std::vector<std::uint8_t> in;
        const std::int64_t deadline = Child::now_ns() + 2'000'000'000;
        while (child_->next(in, deadline) == Child::Wait::kMessage) {
          if (in.empty() || in[0] != kLog) break;
          forward_log(in);
        }
      }
    }
  }

  void enter_initialization(double start_time_s, std::optional<double> stop_time_s) override {
    call(
        [&] { return fmt::format("{}EnterInitializationMode(t = {:g})", prefix_, start_time_s); },
        [&](Writer& w) {
          w.put(Op::kEnterInitialization).put(start_time_s).put(stop_time_s.has_value()).put(stop_time_s.value_or(0.0));
        });
  }
  void exit_initialization() override {
    call([&] { return prefix_ + "ExitInitializationMode"; }, [](Writer& w) { w.put(Op::kExitInitialization); });
    limited_ = call_timeout_ns_ > 0;  // from here on a call that takes too long is given up on
  }
  void do_step(double t_s, double h_s) override {
    call([&] { return fmt::format("{}DoStep(t = {:g}, h = {:g})", prefix_, t_s, h_s); },
         [&](Writer& w) { w.put(Op::kDoStep).put(t_s).put(h_s); });
  }
  void terminate() override {
    call([&] { return prefix_ + "Terminate"; }, [](Writer& w) { w.put(Op::kTerminate); });
  }
  void reset() override {
    call([&] { return prefix_ + "Reset"; }, [](Writer& w) { w.put(Op::kReset); });
  }
  void get_real(std::span<const ValueReference> vr, std::span<double> values) override {
    Reader r = call([&] { return prefix_ + (prefix_ == "fmi2" ? "GetReal" : "GetFloat64"); },
                    [&](Writer& w) { w.put(Op::kGetReal).span(vr); });
    copy_into(r.vec<double>(), values);
  }
  void set_real(std::span<const ValueReference> vr, std::span<const double> values) override {
    call([&] { return prefix_ + (prefix_ == "fmi2" ? "SetReal" : "SetFloat64"); },
         [&](Writer& w) { w.put(Op::kSetReal).span(vr).span(values); });
  }
  void get_integer(std::span<const ValueReference> vr, std::span<std::int32_t> values) override {
    Reader r = call([&] { return prefix_ + (prefix_ == "fmi2" ? "GetInteger" : "GetInt32"); },
                    [&](Writer& w) { w.put(Op::kGetInteger).span(vr); });
    copy_into(r.vec<std::int32_t>(), values);
  }
  void set_integer(std::span<const ValueReference> vr, std::span<const std::int32_t> values) override {
    call([&] { return prefix_ + (prefix_ == "fmi2" ? "SetInteger" : "SetInt32"); },
         [&](Writer& w) { w.put(Op::kSetInteger).span(vr).span(values); });
  }
  void get_boolean(std::span<const ValueReference> vr, std::span<bool> values) override {
    Reader r = call([&] { return prefix_ + "GetBoolean"; }, [&](Writer& w) { w.put(Op::kGetBoolean).span(vr); });
    const auto n = static_cast<std::size_t>(r.get<std::uint64_t>());
    if (n != values.size()) throw FmuError("isolated FMU instance: a Boolean answer of the wrong length");
    for (std::size_t i = 0; i < n; ++i) values[i] = r.get<bool>();
  }
  void set_boolean(std::span<const ValueReference> vr, std::span<const bool> values) override {
    call([&] { return prefix_ + "SetBoolean"; },
         [&](Writer& w) {
           w.put(Op::kSetBoolean).span(vr).put(static_cast<std::uint64_t>(values.size()));
           for (const bool b : values) w.put(b);
         });
  }
  void set_string(std::span<const ValueReference> vr, std::span<const std::string> values) override {
    call([&] { return prefix_ + "SetString"; },
         [&](Writer& w) {
           w.put(Op::kSetString).span(vr).put(static_cast<std::uint64_t>(values.size()));
           for (const auto& s : values) w.text(s);
         });
  }

 private:
  template <class T>
  static void copy_into(const std::vector<T>& from, std::span<T> to) {
    if (from.size() != to.size()) throw FmuError("isolated FMU instance: an answer of the wrong length");
    std::copy(from.begin(), from.end(), to.begin());
  }

  std::string who() const {
    return fmt::format("FMU '{}' ({}) instance '{}'", description().model_name, fmu_->path(), name_);
  }

  void forward_log(const std::vector<std::uint8_t>& in) {
    Reader r(std::span<const std::uint8_t>(in).subspan(1));
    const std::string category = r.text(), status = r.text(), message = r.text();
    last_logged_ = fmt::format("[{}] {}", status, message);
    if (log_) {
      try {
        log_(category, status, message);
      } catch (...) {
      }
    } else {
      std::fprintf(stderr, "[FMU %s] %s %s: %s\n", name_.c_str(), status.c_str(), category.c_str(), message.c_str());
    }
  }

  /// Sends the request `fill` writes, forwards what the FMU logs meanwhile and returns the answer's
  /// payload (kept in answer_). Throws FmuError with the child's message when the call failed there,
  /// naming `call_text()` when the child ended, InstanceInterrupted when asked to stop.
  template <class Text, class Fill>
  Reader call(Text&& call_text, Fill&& fill, bool instantiate = false) {
    if (child_->ended()) {
      throw FmuError(
          fmt::format("{} of {}: refused, the FMU's process has ended ({})", call_text(), who(), child_->end()));
    }
    if (!instantiate) {
      Writer w;
      fill(w);
      if (!child_->send(w.bytes)) return child_ended(call_text());
    }
    const std::int64_t deadline = limited_ ? Child::now_ns() + call_timeout_ns_ : 0;
    for (;;) {
      switch (child_->next(answer_, deadline)) {
        case Child::Wait::kMessage: break;
        case Child::Wait::kEnded: return child_ended(call_text());
        case Child::Wait::kTimedOut:
          child_->kill(fmt::format("killed after step_timeout_s = {:g} s", call_timeout_s_));
          throw FmuError(fmt::format(
              "{} of {}: did not return within step_timeout_s = {:g} s; the FMU's process was killed{} "
              "(an FMU whose steps take longer needs a larger `step_timeout_s:` in its plant:/controller: section)",
              call_text(), who(), call_timeout_s_,
              last_logged_.empty() ? "; the FMU logged nothing" : "; it logged last: " + last_logged_));
        case Child::Wait::kStopped:
          child_->kill("killed on a stop request");
          throw InstanceInterrupted(
              fmt::format("{} of {}: interrupted (Ctrl-C or SIGTERM) while the FMU was inside the call; its "
                          "process was killed",
                          call_text(), who()));
      }
      if (answer_.empty()) continue;
      if (answer_[0] == kLog) {
        forward_log(answer_);
        continue;
      }
      if (answer_[0] == kFailed) {
        Reader r(std::span<const std::uint8_t>(answer_).subspan(1));
        throw FmuError(r.text());
      }
      return Reader(std::span<const std::uint8_t>(answer_).subspan(1));
    }
  }

  [[noreturn]] Reader child_ended(const std::string& call_text) {
    const std::string end = child_->reap();
    throw FmuError(
        fmt::format("{} of {}: the FMU's process {} inside the call{}", call_text, who(), end,
                    last_logged_.empty() ? "; the FMU logged nothing" : "; it logged last: " + last_logged_));
  }

  std::string name_;
  LogSink log_;
  std::int64_t call_timeout_ns_ = 0;
  double call_timeout_s_ = 0.0;
  bool limited_ = false;  ///< past initialisation with a call timeout
  std::string prefix_;
  std::unique_ptr<Child> child_;
  std::string last_logged_;
  std::vector<std::uint8_t> answer_;
};

}  // namespace

std::unique_ptr<Instance> instantiate_isolated(const std::shared_ptr<Fmu>& fmu, const std::string& instance_name,
                                               LogSink log, double call_timeout_s) {
  return std::make_unique<IsolatedInstance>(fmu, instance_name, std::move(log), call_timeout_s);
}

}  // namespace quadcosim::fmi
