// The process exit codes the hosts return, which the quadcosim commands return as they are (the
// table of what each means per command is the front end's: app/exit_codes.hpp).
#pragma once

namespace quadcosim::hosts::exit_code {

enum : int {
  kOk = 0,                ///< done; every criterion passed
  kFailed = 1,            ///< done, but the verdict is "no" (a criterion failed, a check found problems, ...)
  kBadInput = 2,          ///< a file, flag or value was wrong (the message names it); nothing was run
  kOutput = 3,            ///< an output could not be written, or a tool or system call failed
  kNoPeer = 4,            ///< a DDS peer did not answer in time (lockstep timeout, no such node)
  kControllerFailed = 5,  ///< the controller failed (raised, returned garbage, crashed, exited, hung)
  kPlantFailed = 6,       ///< the plant's FMU failed (answered Error, crashed, exited, gave a NaN)
  kInterrupted = 130      ///< SIGINT / SIGTERM (Ctrl-C) before the end; the outputs hold what ran
};

}  // namespace quadcosim::hosts::exit_code
