// The CLI built without Python (python/embedded/python_host.hpp): --python says so; a scenario's
// `controller: {python: ...}` gets io's own error (no factory).
#include "io/scenario.hpp"
#include "python/embedded/python_host.hpp"

namespace quadcosim::embedded_python {

bool built_with_python() { return false; }

io::PythonControllerFactory python_controller_factory() { return {}; }

std::shared_ptr<const control::Controller> make_python_controller(const std::string&, const std::filesystem::path&,
                                                                  const model::VehicleParams&,
                                                                  const std::string& what) {
  throw io::ConfigError(what +
                        ": this quadcosim was built without Python (it needs pybind11 and the Python headers, "
                        "Debian: pybind11-dev python3-dev, and QUADCOSIM_BUILD_PYTHON=ON; docs/python.md)");
}

std::string python_module_file(const std::string&) { return ""; }

std::function<void(const std::function<void()>&)> python_thread_host() { return {}; }

void python_at_exit() {}

}  // namespace quadcosim::embedded_python
