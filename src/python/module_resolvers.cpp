// python/module_resolvers.hpp: the module's resolvers, made once.
#include "python/module_resolvers.hpp"

#include "hosts/scenario_resolvers.hpp"
#include "python/py_controller.hpp"

namespace quadcosim::python {

const io::ScenarioResolvers& module_resolvers() {
  static const io::ScenarioResolvers resolvers =
      hosts::scenario_resolvers(&load_python_controller, &loaded_module_file);
  return resolvers;
}

}  // namespace quadcosim::python
