#include "sim/controller_thread.hpp"

#include <chrono>
#include <stdexcept>
#include <thread>

namespace quadcosim::sim {

// What the thread and its owner share. Held by both through a shared_ptr, so a thread left behind
// (a controller that never returns) keeps it and the controller alive after the owner is gone.
struct ControllerThread::Shared {
  std::mutex mutex;
  std::condition_variable changed;
  std::function<void()> queued;  ///< the next call, empty when none
  bool running = false;          ///< a call is running
  bool stop = false;
  bool abandoned = false;  ///< the owner is gone: a step's continuation must not run
  std::unique_ptr<control::Controller> controller;

  bool free() const { return !queued && !running; }

  void loop() {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [this] { return stop || queued; });
      if (!queued) return;  // stop, nothing left
      std::function<void()> call = std::move(queued);
      queued = nullptr;
      running = true;
      lock.unlock();
      call();
      lock.lock();
      running = false;
      changed.notify_all();
    }
  }
};

ControllerThread::ControllerThread(std::unique_ptr<control::Controller> controller, ThreadHost host)
    : shared_(std::make_shared<Shared>()) {
  if (!controller) throw std::invalid_argument("ControllerThread: no controller");
  type_ = std::string(controller->type());
  const auto text = [this](std::string_view s) -> std::string_view { return texts_.emplace_back(s); };
  for (const control::ParameterSpec& s : controller->parameters()) {
    control::ParameterSpec copy = s;
    copy.name = text(s.name);
    copy.unit = text(s.unit);
    copy.description = text(s.description);
    for (std::string_view& c : copy.choices) c = text(c);
    specs_.push_back(std::move(copy));
  }
  for (const std::string& n : controller->output_names()) output_names_.push_back(n);
  refresh_values(*controller);
  shared_->controller = std::move(controller);
  std::thread([shared = shared_, host = std::move(host)] {
    if (host) {
      host([&shared] { shared->loop(); });
    } else {
      shared->loop();
    }
  }).detach();
}

ControllerThread::~ControllerThread() {
  std::unique_lock lock(shared_->mutex);
  shared_->stop = true;
  shared_->changed.notify_all();
  // The thread ends once free; one that is still in the controller after a second is left behind
  // (detached from the start, it holds `shared_` and with it the controller).
  if (shared_->changed.wait_for(lock, std::chrono::seconds(1), [this] { return shared_->free(); })) {
    std::unique_ptr<control::Controller> controller = std::move(shared_->controller);
    lock.unlock();
    controller.reset();  // destroyed here, on the owner's thread, as a controller not on a thread is
  } else {
    shared_->abandoned = true;
  }
}

bool ControllerThread::start(std::shared_ptr<Step> step, std::function<void(Step&)> then) {
  const std::lock_guard lock(shared_->mutex);
  if (!shared_->free() || shared_->stop) return false;
  shared_->queued = [s = shared_.get(), step = std::move(step), then = std::move(then)] {
    try {
      s->controller->step(step->observation, step->reference, step->dt_s, step->output);
    } catch (...) {
      step->error = std::current_exception();
    }
    // The continuation runs before the thread counts as free (under the lock, so an owner that
    // gave up waiting does not go away during it), and not at all once the owner is gone. The thread
    // counts as free as the continuation returns, in the same hold of the lock: a start() waiting on
    // the lock (the next tick, asked for by the answer the continuation published) then finds it free.
    // Freed only when the loop took the lock back, that start() lost the race about one run in two
    // over DDS, and its tick went unanswered until the plant asked again 50 ms later.
    const std::lock_guard lock(s->mutex);
    if (then && !s->abandoned) then(*step);
    s->running = false;
    s->changed.notify_all();
  };
  shared_->changed.notify_all();
  return true;
}

bool ControllerThread::wait_free(std::int64_t timeout_ns) {
  std::unique_lock lock(shared_->mutex);
  return shared_->changed.wait_for(lock, std::chrono::nanoseconds(timeout_ns), [this] { return shared_->free(); });
}

bool ControllerThread::busy() const {
  const std::lock_guard lock(shared_->mutex);
  return !shared_->free();
}

bool ControllerThread::call(const std::function<void(control::Controller&)>& f, std::int64_t timeout_ns) {
  std::unique_lock lock(shared_->mutex);
  const auto limit = std::chrono::nanoseconds(timeout_ns);
  if (!shared_->changed.wait_for(lock, limit, [this] { return shared_->free(); })) return false;
  auto finished = std::make_shared<bool>(false);
  shared_->queued = [s = shared_.get(), &f, finished] {
    f(*s->controller);
    const std::lock_guard l(s->mutex);
    *finished = true;
  };
  shared_->changed.notify_all();
  if (shared_->changed.wait_for(lock, limit, [&] { return *finished; })) return true;
  // Not returned in time: `f` must not outlive this frame, so the call, if it has not started,
  // is taken back; one already running is waited for (it references `f`).
  if (shared_->queued) {
    shared_->queued = nullptr;
    return false;
  }
  shared_->changed.wait(lock, [&] { return *finished; });
  return true;
}

std::unique_ptr<control::Controller> ControllerThread::clone() const {
  throw std::logic_error("ControllerThread::clone: a controller on its own thread is flown where it is");
}

std::optional<control::ParameterValue> ControllerThread::get_parameter(std::string_view name) const {
  const std::lock_guard lock(values_mutex_);
  const auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

void ControllerThread::refresh_values(const control::Controller& controller) {
  std::map<std::string, control::ParameterValue, std::less<>> values;
  for (const control::ParameterSpec& s : specs_) {
    if (auto v = controller.get_parameter(s.name)) values.emplace(std::string(s.name), std::move(*v));
  }
  const std::lock_guard lock(values_mutex_);
  values_ = std::move(values);
}

std::string ControllerThread::set_parameters(std::span<const control::Setting> settings) {
  std::string result;
  std::exception_ptr error;
  const bool ran = call(
      [&](control::Controller& c) {
        try {
          result = c.set_parameters(settings);
          refresh_values(c);
        } catch (...) {
          error = std::current_exception();
        }
      },
      kCallTimeoutNs);
  if (!ran) {
    std::string names;
    for (const control::Setting& s : settings) names += (names.empty() ? "" : ", ") + s.name;
    return names + ": the controller is busy (a call into it has not returned for " +
           std::to_string(kCallTimeoutNs / 1'000'000'000) + " s); nothing changed";
  }
  if (error) std::rethrow_exception(error);
  return result;
}

void ControllerThread::reset() {
  std::exception_ptr error;
  const bool ran = call(
      [&](control::Controller& c) {
        try {
          c.reset();
        } catch (...) {
          error = std::current_exception();
        }
      },
      kCallTimeoutNs);
  if (!ran) throw std::runtime_error(type_ + " controller: reset: the controller is busy (a call has not returned)");
  if (error) std::rethrow_exception(error);
}

void ControllerThread::step(const control::Observation& observation, const control::Reference& reference, double dt_s,
                            control::ControllerOutput& out) {
  auto s = std::make_shared<Step>();
  s->observation = observation;
  s->reference = reference;
  s->dt_s = dt_s;
  s->output = out;
  while (!start(s)) wait_free(kCallTimeoutNs);
  while (!wait_free(kCallTimeoutNs)) {
  }
  if (s->error) std::rethrow_exception(s->error);
  out = std::move(s->output);
}

}  // namespace quadcosim::sim
