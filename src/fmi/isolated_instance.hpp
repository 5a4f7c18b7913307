// An FMU instance whose calls run in a child process (fmi/fmu.hpp's Instance, forwarded): what FMI
// tools do for FMUs they do not trust. The master forks once per instance, after the FMU is loaded;
// the child instantiates it and serves each call, the parent waits for the answer. An FMU that
// crashes, aborts, calls exit() or _exit() inside a call ends only its child: the call throws
// FmuError naming the FMU, the instance, the call (with its time) and how the process ended
// ("killed by signal 11 (Segmentation fault)", "exited with status 0"), and every later call is
// refused. A call that does not return cannot be waited out for ever: while it waits, the master
// polls the stop check (isolation::set_stop_check: Ctrl-C, SIGTERM) every 50 ms and, once asked to
// stop, kills the child and throws InstanceInterrupted. With a call timeout, a call after
// initialisation that takes longer is given up on too: the child is killed and the call throws
// FmuError naming the call, the limit and the scenario key (`step_timeout_s`).
//
// The child dies with its parent (PR_SET_PDEATHSIG, SIGKILL) and ignores SIGINT: a Ctrl-C is the
// parent's to handle. What the FMU logs is sent to the parent and reaches the instance's LogSink in
// order, before the call's answer. Values travel as their bytes: results are bit for bit those of the
// same calls in-process (docs/reliability.md, "Foreign code").
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "fmi/fmu.hpp"

namespace quadcosim::fmi {

/// A wait on an isolated instance was ended by the stop check (Ctrl-C, SIGTERM): the child is killed.
class InstanceInterrupted : public FmuError {
 public:
  using FmuError::FmuError;
};

/// Starts a child process that instantiates `fmu` (fmu->instantiate(instance_name, ...)) and returns
/// the instance that forwards every call to it. Throws FmuError when the child cannot be started or
/// the instantiation fails (its message, as in-process), or ends the child. `call_timeout_s` > 0
/// limits each call after exit_initialization (FmuMapping::step_timeout_s); 0: no limit.
std::unique_ptr<Instance> instantiate_isolated(const std::shared_ptr<Fmu>& fmu, const std::string& instance_name,
                                               LogSink log = {}, double call_timeout_s = 0.0);

}  // namespace quadcosim::fmi
