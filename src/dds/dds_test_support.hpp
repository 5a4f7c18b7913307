// For the tests that open DDS participants in their own process: a domain of their own.
#pragma once

#include <unistd.h>

#include <cstdint>

#include "dds/participant.hpp"

namespace quadcosim::dds::test {

/// Domain 100 + (this process's id % 100), apart from other test runs, discovering over `range`.
inline RosEnvironment private_env(DiscoveryRange range = DiscoveryRange::kLocalhost) {
  RosEnvironment e;
  e.domain_id = 100 + static_cast<std::uint32_t>(getpid() % 100);
  e.range = range;
  return e;
}

}  // namespace quadcosim::dds::test
