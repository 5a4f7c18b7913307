#include "app/foxglove_cli.hpp"

#include <fmt/format.h>

#include <string>

namespace quadcosim::app {

void add_foxglove_options(CLI::App& cmd, FoxgloveCliOptions& o, bool inprocess) {
  cmd.add_option("--foxglove", o.listen,
                 "serve the topics live to Foxglove (WebSocket, foxglove.websocket.v1) on [ADDR:]PORT "
                 "(ADDR 127.0.0.1 by default; PORT 0: a free one, printed; docs/foxglove.md)");
  auto* linger = cmd.add_option("--foxglove-linger", o.linger_s,
                                "after the run, keep serving its last state this long [s] (Ctrl-C ends it)")
                     ->check(CLI::Range(0.0, 1e6));
  auto* queue = cmd.add_option("--foxglove-queue-kib", o.queue_kib,
                               "per-client queue [KiB] above which a slow client's messages are dropped")
                    ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 20));
  auto* origin =
      cmd.add_option("--foxglove-allow-origin", o.allow_origins,
                     "admit browser pages from this Origin too (repeatable; e.g. https://app.foxglove.dev; '*': "
                     "any). Default: only clients without an Origin and pages on localhost, 127.0.0.1 or [::1]")
          ->allow_extra_args(false);
  linger->needs("--foxglove");
  queue->needs("--foxglove");
  origin->needs("--foxglove");
  if (inprocess) {
    cmd.add_option("--foxglove-wait", o.wait_s, "in-process: wait up to this long for a client to subscribe first [s]")
        ->check(CLI::Range(0.0, 1e6))
        ->needs("--foxglove");
    cmd.add_option("--foxglove-pace", o.pace,
                   "in-process: run at this many times real time, to watch it live (0: as fast as it goes)")
        ->check(CLI::Range(0.0, 1e6))
        ->needs("--foxglove");
  }
}

}  // namespace quadcosim::app
