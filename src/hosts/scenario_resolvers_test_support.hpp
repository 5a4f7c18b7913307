// The resolvers tests and test programs load scenarios with: FMUs through one loader, no Python.
#pragma once

#include "hosts/scenario_resolvers.hpp"

namespace quadcosim::hosts {

inline const io::ScenarioResolvers& test_resolvers() {
  static const io::ScenarioResolvers resolvers = scenario_resolvers();
  return resolvers;
}

}  // namespace quadcosim::hosts
