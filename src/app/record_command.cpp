// `quadcosim record`: its flags; the recorder is hosts/recorder_process.hpp.
#include <CLI/CLI.hpp>

#include "app/commands.hpp"
#include "hosts/recorder_process.hpp"

namespace quadcosim::app {

CLI::App* add_record_subcommand(CLI::App& app, RecordOptions& rec) {
  auto* rec_cmd = app.add_subcommand("record", "record a vehicle's topics over DDS into MCAP (like ros2 bag record)");
  rec_cmd->add_option("--out", rec.out, "MCAP file to write (metadata.yaml beside it)")->required();
  rec_cmd->add_option("--namespace", rec.ns, "the vehicle's namespace");
  rec_cmd->add_option("--topics", rec.topics, "only these topics (default: /clock and all of the vehicle's)");
  rec_cmd->add_option("--duration", rec.duration_s, "stop after this many seconds (default: Ctrl-C)")
      ->check(CLI::Range(0.0, 1e9));

  add_enclave_option(rec_cmd, rec.enclave);
  return rec_cmd;
}

int record_command(const RecordOptions& o) { return hosts::run_recorder(o); }

}  // namespace quadcosim::app
