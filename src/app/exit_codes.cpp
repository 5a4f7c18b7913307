#include "app/exit_codes.hpp"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "control/care.hpp"
#include "dds/parameter_client.hpp"
#include "fmi/model_description.hpp"
#include "hosts/signals.hpp"
#include "io/scenario.hpp"
#include "security/keystore.hpp"
#include "sim/controller_node.hpp"

namespace quadcosim::app {

const std::vector<ExitCodeRow>& exit_code_table() {
  using namespace exit_code;
  // README.md "Exit codes" shows these rows; tests/cli/exit_codes.py compares the two.
  static const std::vector<ExitCodeRow> table = {
      {kOk, "success", "*"},
      {kFailed, "a judged criterion failed (of the set --judge names: spec by default, or paper; never with none)",
       "run summary"},
      {kFailed, "fewer runs passed their judged criteria than --min-pass-rate asks", "sweep"},
      {kFailed, "a loop is unstable closed-loop, or left hover while measured (its margins are undefined)", "margins"},
      {kFailed, "the enclave has problems (listed)", "security"},
      {kFailed, "the node refused the value, or has no such parameter", "param"},
      {kFailed, "no message arrived on the topic", "topic"},
      {kBadInput, "bad input: a file, flag or value (the message names it); nothing was run", "*"},
      {kOutput, "an output could not be written, or a tool or system call failed", "*"},
      {kNoPeer,
       "lockstep: the peer did not answer within --timeout, the controller exited early or was killed without a "
       "code of its own, could not be told from another writer, or sent more commands than lockstep can match to "
       "ticks",
       "run plant"},
      {kNoPeer, "the node was not found, or did not answer within --timeout", "param"},
      {kControllerFailed,
       "the controller's step failed: it raised, returned garbage, crashed, exited or did not return in time (the "
       "message names the controller, the step and its time)",
       "run controller margins"},
      {kControllerFailed, "the controller's step failed in at least one run (summary.json names them)", "sweep"},
      {kPlantFailed,
       "the plant's FMU failed: it answered Error, gave a non-finite output, crashed or exited (the message names the "
       "FMU, the call, the tick and its time)",
       "run plant margins"},
      {kInterrupted, "interrupted (Ctrl-C, SIGTERM); the outputs hold what ran until then", "run plant sweep"},
  };
  return table;
}

namespace {
bool concerns(const ExitCodeRow& row, const std::string& command) {
  if (command.empty() || row.commands == "*") return true;
  std::istringstream words{std::string(row.commands)};
  for (std::string w; words >> w;) {
    if (w == command) return true;
  }
  return false;
}
}  // namespace

std::string exit_code_footer(const std::string& command) {
  std::string text = "Exit codes:";
  for (const ExitCodeRow& row : exit_code_table()) {
    if (!concerns(row, command)) continue;
    text += fmt::format("\n  {:<4} {}", row.code, row.meaning);
    if (command.empty() && row.commands != "*") text += fmt::format(" ({})", row.commands);
  }
  return text;
}

void add_exit_code_footers(CLI::App& app) {
  app.footer(exit_code_footer(""));
  for (CLI::App* sub : app.get_subcommands({})) sub->footer(exit_code_footer(sub->get_name()));
}

int run_guarded(const std::string& command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const io::ConfigError& e) {  // names its file and key
    std::cerr << "error: " << e.what() << '\n';
    return exit_code::kBadInput;
  } catch (const control::CareError& e) {
    std::cerr << "error: " << command << ": controller design failed: " << e.what() << '\n';
    return exit_code::kBadInput;
  } catch (const security::KeystoreError& e) {
    std::cerr << "error: " << command << ": " << e.what() << '\n';
    return exit_code::kBadInput;
  } catch (const sim::ControllerFailure& e) {  // names the controller, the step and its time
    std::cerr << "error: " << command << ": " << e.what() << '\n';
    // A wait on an isolated controller given up on Ctrl-C or SIGTERM ends its step too.
    return hosts::stop_signalled() ? exit_code::kInterrupted : exit_code::kControllerFailed;
  } catch (const fmi::FmuError& e) {  // names the FMU, the call, the tick and its time
    std::cerr << "error: " << command << ": " << e.what() << '\n';
    return hosts::stop_requested() ? exit_code::kInterrupted : exit_code::kPlantFailed;
  } catch (const dds::ParameterCallError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return exit_code::kNoPeer;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << command << ": " << e.what() << '\n';
    return exit_code::kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "error: " << command << ": " << e.what() << '\n';
    return exit_code::kOutput;
  }
}

}  // namespace quadcosim::app
