// The process exit codes of the quadcosim commands, stated once: the values the commands return,
// the table rendered into each command's --help footer, and (checked by tests/cli/exit_codes.py)
// the README's "Exit codes" table.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

namespace quadcosim::app {

/// The values a command returns (main() returns them as the process status).
namespace exit_code {
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
}

/// One row of the table: the code, what it means, and the commands that can return it with that
/// meaning ("*": every command). A code may have one row per meaning.
struct ExitCodeRow {
  int code;
  std::string_view meaning;
  std::string_view commands;  ///< space-separated subcommand names, or "*"
};

/// Every exit code every command can return.
const std::vector<ExitCodeRow>& exit_code_table();

/// The rows that concern `command` ("" for all), as the --help footer prints them.
std::string exit_code_footer(const std::string& command);

/// Sets the "Exit codes" footer of `app` and of each of its subcommands.
void add_exit_code_footers(CLI::App& app);

/// Runs `body` (a command), mapping what it throws to an exit code after printing it on stderr:
/// io::ConfigError, std::invalid_argument, control::CareError, security::KeystoreError -> kBadInput;
/// dds::ParameterCallError -> kNoPeer; sim::ControllerFailure -> kControllerFailed; fmi::FmuError (the plant's
/// FMU failed while running) -> kPlantFailed, or kInterrupted when a stop request gave it up; any other std::exception
/// -> kOutput. `command` names the command in messages that would not otherwise say where they come from.
int run_guarded(const std::string& command, const std::function<int()>& body);

}  // namespace quadcosim::app
