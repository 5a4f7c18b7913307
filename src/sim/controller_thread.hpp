// A controller on a thread of its own. Every call into the controller runs on that thread, one at a
// time, so a controller that is slow or blocks (one written in Python that sleeps, waits on I/O or
// collects garbage) holds up that thread only: the node around it keeps taking samples, serving its
// parameter services and being stopped. The node starts a step and either waits for it with a
// limit (real time: the period) or lets the step's continuation publish its result when the
// controller returns (lockstep); see sim::ControllerNode::run_controller_on_thread.
//
// As a control::Controller this object is the controller's stand-in for the node: its table and
// output names are those of the controller at the start; get_parameter answers from the values as of
// the last call that returned (so a controller busy in its step still has its parameters read);
// set_parameters and reset run on the thread, waiting up to kCallTimeoutNs for it to be free.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "control/controller.hpp"

namespace quadcosim::sim {

class ControllerThread final : public control::Controller {
 public:
  /// How long set_parameters and reset wait for the thread to be free and for the call to return.
  static constexpr std::int64_t kCallTimeoutNs = 1'000'000'000;

  /// One step: what the controller is given, what it wrote, and what it threw (if anything).
  struct Step {
    control::Observation observation;
    control::Reference reference;
    double dt_s = 0.0;
    control::ControllerOutput output;
    std::exception_ptr error;
  };

  /// What the thread runs its loop in: `host(loop)` must call loop() once (e.g. holding a Python
  /// thread state for the thread's life, so each call into a Python controller does not make one).
  using ThreadHost = std::function<void(const std::function<void()>& loop)>;

  /// Takes `controller` over and starts the thread (the table, output names and parameter values are
  /// read here, on the calling thread), its loop run by `host` when given.
  explicit ControllerThread(std::unique_ptr<control::Controller> controller, ThreadHost host = {});
  /// Stops the thread. A call still running after 1 s (a controller that never returns) is left
  /// behind: the thread is detached with the controller, and the process may exit around it.
  ~ControllerThread() override;
  ControllerThread(const ControllerThread&) = delete;
  ControllerThread& operator=(const ControllerThread&) = delete;

  /// Starts `step` on the thread unless a call is queued or running there (then false, nothing
  /// started). `then`, when set, runs on the controller's thread after the step returned or threw,
  /// before the thread counts as free (it is free once `then` returns: a start() waiting meanwhile
  /// succeeds), and not once this object is gone; it must not call back into this object.
  bool start(std::shared_ptr<Step> step, std::function<void(Step&)> then = {});
  /// Waits up to timeout_ns for the thread to be free; true when it is (a started step returned).
  bool wait_free(std::int64_t timeout_ns);
  /// True while a call is queued or running.
  bool busy() const;

  // control::Controller
  std::string_view type() const override { return type_; }
  /// Refused (std::logic_error): a controller on a thread is flown where it is.
  std::unique_ptr<control::Controller> clone() const override;
  std::span<const control::ParameterSpec> parameters() const override { return specs_; }
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const override;
  std::string set_parameters(std::span<const control::Setting> settings) override;
  std::span<const std::string> output_names() const override { return output_names_; }
  /// Runs reset() on the thread; throws std::runtime_error when the thread stayed busy.
  void reset() override;
  /// Runs one step on the thread and waits for it without limit; rethrows what the controller threw.
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

 private:
  struct Shared;
  /// Runs `call` on the thread and waits for it, each up to timeout_ns; false when it did not run
  /// (the thread stayed busy) or did not return in time.
  bool call(const std::function<void(control::Controller&)>& call, std::int64_t timeout_ns);
  /// Reads every parameter's value into the cache (on the controller's thread, or before it starts).
  void refresh_values(const control::Controller& controller);

  std::string type_;
  std::deque<std::string> texts_;  ///< what specs_' names, units, descriptions and choices view
  std::vector<control::ParameterSpec> specs_;
  std::vector<std::string> output_names_;
  mutable std::mutex values_mutex_;
  std::map<std::string, control::ParameterValue, std::less<>> values_;
  std::shared_ptr<Shared> shared_;
};

}  // namespace quadcosim::sim
