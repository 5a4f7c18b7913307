// The process exit codes of the quadcosim commands, stated once: the values the commands return,
// the table rendered into each command's --help footer, and (checked by tests/cli/exit_codes.py)
// the README's "Exit codes" table.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "hosts/exit_code.hpp"

namespace CLI {
class App;
}

namespace quadcosim::app {

/// The values a command returns (main() returns them as the process status): the hosts' (src/hosts/).
namespace exit_code = hosts::exit_code;

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
