// The DriverHost (drivers/driver_host.hpp) of a run on the in-process transport: publish() delivers
// synchronously, so whatever answers a tick is in when the plant's publish_outputs returns, and there
// is nothing to wait for. It reads no wall clock (now_ns() is always 0: with a zero timeout the
// lockstep driver never waits, and never asks again), never stops a run, and never blocks.
#pragma once

#include <cstdint>
#include <functional>

#include "drivers/driver_host.hpp"

namespace quadcosim::inproc {

class InProcessHost final : public drivers::DriverHost {
 public:
  std::int64_t now_ns() override { return 0; }
  void wait(std::int64_t /*timeout_ns*/, const std::function<bool()>& /*woken*/) override {}
};

}  // namespace quadcosim::inproc
