// The CLI's embedded Python (python/embedded/python_host.hpp), built when Python and pybind11 are found.
#include <pybind11/embed.h>
#include <pybind11/numpy.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>

#include "io/scenario.hpp"
#include "python/embedded/isolated_controller.hpp"
#include "python/embedded/python_host.hpp"
#include "python/py_controller.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace quadcosim::embedded_python {

namespace {

std::once_flag g_started;
bool g_running = false;

/// Starts the interpreter (once, on whichever thread first needs it) and releases the GIL, so the
/// threads that call controllers (a sweep's runs, a node's controller thread) can take it.
void start_python() {
  std::call_once(g_started, [] {
    // The CLI keeps its own SIGINT/SIGTERM handlers (hosts/signals.hpp): Python installs none.
    py::initialize_interpreter(/*init_signal_handlers=*/false);
    {
      // The package quadcosim where it was built, after PYTHONPATH: `import quadcosim` in a
      // controller's module finds it without the user setting anything.
      py::list path = py::module_::import("sys").attr("path");
      if (fs::exists(fs::path(QUADCOSIM_PYTHON_PACKAGE_DIR) / "quadcosim")) path.append(QUADCOSIM_PYTHON_PACKAGE_DIR);
    }
    // pybind11's numpy API is looked up once, in a function-local static whose initialisation imports
    // numpy (and so lets the GIL go): first done by two threads at once (a sweep's first steps), one
    // waits for the GIL inside the static's guard while the other holds the GIL and waits for the
    // guard. Done here, before any other thread can take the GIL.
    { const py::array_t<double> warm(1); }
    g_running = true;
    PyEval_SaveThread();  // never restored: every later use takes the GIL with gil_scoped_acquire
  });
}

/// The controller `target` names, flown in a process of its own unless QUADCOSIM_PYTHON_IN_PROCESS=1
/// (python/embedded/isolated_controller.hpp).
std::shared_ptr<const control::Controller> load(const std::string& target, const fs::path& folder,
                                                const model::VehicleParams& vehicle) {
  start_python();
  std::shared_ptr<const python::PyController> loaded = python::load_python_controller(target, folder, vehicle);
  if (!python_controllers_isolated()) return loaded;
  return isolate_python_controller(std::move(loaded));
}

}  // namespace

bool built_with_python() { return true; }

io::PythonControllerFactory python_controller_factory() {
  return [](const std::string& target, const fs::path& folder,
            const model::VehicleParams& vehicle) -> std::shared_ptr<const control::Controller> {
    return load(target, folder, vehicle);  // io names the key in its error
  };
}

std::shared_ptr<const control::Controller> make_python_controller(const std::string& spec, const fs::path& folder,
                                                                  const model::VehicleParams& vehicle,
                                                                  const std::string& what) {
  try {
    return load(spec, folder, vehicle);
  } catch (const std::exception& e) {
    throw io::ConfigError(what + ": " + e.what());
  }
}

std::string python_module_file(const std::string& target) {
  if (!g_running) return "";  // no interpreter: no Python controller was loaded
  return python::loaded_module_file(target);
}

std::function<void(const std::function<void()>&)> python_thread_host() {
  return [](const std::function<void()>& loop) {
    start_python();
    // The outer acquire makes the thread's state and keeps it; the release lets the GIL go. Each
    // call into the controller then takes the GIL on that same state.
    const py::gil_scoped_acquire keep_state;
    const py::gil_scoped_release free_gil;
    loop();
  };
}

void python_at_exit() {
  if (!g_running) return;
  const py::gil_scoped_acquire gil;
  try {
    py::module_ sys = py::module_::import("sys");
    for (const char* stream : {"stdout", "stderr"}) {
      if (py::object s = sys.attr(stream); !s.is_none()) s.attr("flush")();
    }
  } catch (py::error_already_set&) {
    // nothing more to do at exit
  }
}

}  // namespace quadcosim::embedded_python
