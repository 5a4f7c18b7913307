// python/py_controller.hpp: making a Python controller from a class or an object (its declarations
// read and checked), importing one by "module:Class", and the vehicle as the dict its __init__ receives.
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <Eigen/LU>

#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "model/mixer.hpp"
#include "python/py_controller.hpp"
#include "python/py_controller_parts.hpp"
#include "python/py_runtime.hpp"
#include "util/did_you_mean.hpp"

namespace py = pybind11;

namespace quadcosim::python {

// ---------------------------------------------------------------------------------------------------
// Making one

py::dict vehicle_dict(const model::VehicleParams& vehicle) {
  py::dict d;
  for (const model::VehicleParameter& p : model::vehicle_parameters()) {
    const py::str key(std::string(p.name));
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: d[key] = p.get(vehicle); break;
      case model::VehicleParameter::Kind::kChoice: d[key] = std::string(p.choice_of(vehicle)); break;
      case model::VehicleParameter::Kind::kSigns: {
        py::list s;
        for (int i = 0; i < vehicle.rotor_count; ++i) s.append(vehicle.spin[static_cast<std::size_t>(i)]);
        d[key] = py::tuple(s);
        break;
      }
      case model::VehicleParameter::Kind::kRotors: {
        py::list rotors;
        for (int i = 0; i < vehicle.rotor_count; ++i) {
          const Eigen::Vector3d r = model::rotor_position_B(vehicle, i);
          rotors.append(py::make_tuple(r.x(), r.y(), r.z()));
        }
        d[key] = py::tuple(rotors);  // every layout's rotor positions [m]
        break;
      }
    }
  }
  d["hover_omega_rad_s"] = vehicle.hover_omega_rad_s();
  d["rotor_count"] = vehicle.rotor_count;
  // The allocation (eq. (4) inverted; the pseudo-inverse for more than four rotors): rotor speeds
  // squared from U, one row per rotor, as the C++ controllers allocate.
  const model::AllocationMatrix inverse = model::allocation_matrix(vehicle);
  py::list rows;
  for (Eigen::Index r = 0; r < inverse.rows(); ++r) {
    rows.append(py::make_tuple(inverse(r, 0), inverse(r, 1), inverse(r, 2), inverse(r, 3)));
  }
  d["mixer_inverse"] = py::tuple(rows);
  return d;
}

py::object observation_class() { return globals().observation_class; }
py::object reference_class() { return globals().reference_class; }
py::object sensor_reading_class() { return globals().sensor_reading_class; }

py::object step_timeout_type() {
  py::gil_scoped_acquire gil;
  return globals().step_timeout;
}

namespace {

/// The double a declaration's entry holds, or throws naming it.
double declared_number(const std::string& where, const py::handle& v) {
  if (!is_real_number(v)) {
    throw std::invalid_argument(fmt::format("{}: got {}, expected a number", where, describe_value(v)));
  }
  return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
}

bool valid_parameter_name(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name.front())))) return false;
  for (char ch : name) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '.') return false;
  }
  return name.back() != '.' && name.find("..") == std::string::npos;
}

}  // namespace

std::shared_ptr<PyController> make_python_controller(py::object given, const model::VehicleParams& vehicle) {
  py::gil_scoped_acquire gil;
  const Globals& g = globals();
  py::object object = given;
  if (PyType_Check(given.ptr())) {
    const std::string cls = py::str(given.attr("__module__")).cast<std::string>() + "." +
                            py::str(given.attr("__qualname__")).cast<std::string>();
    // With the vehicle when __init__ takes an argument.
    bool takes_vehicle = false;
    try {
      for (const auto& item : g.signature(given).attr("parameters").attr("values")()) {
        const std::string kind = py::str(item.attr("kind").attr("name")).cast<std::string>();
        if (kind == "POSITIONAL_ONLY" || kind == "POSITIONAL_OR_KEYWORD" || kind == "VAR_POSITIONAL") {
          takes_vehicle = true;
        }
      }
    } catch (py::error_already_set&) {
      // No signature (a class implemented in C): called without arguments.
    }
    try {
      object = takes_vehicle ? given(vehicle_dict(vehicle)) : given();
    } catch (py::error_already_set& e) {
      e.restore();
      py::object error = fetch_error();
      throw ControllerError(fmt::format("{}({}) raised {}", cls, takes_vehicle ? "vehicle" : "", describe_error(error)),
                            error);
    }
  }
  const py::handle type = py::type::handle_of(object);
  auto shared = std::make_shared<PyController::Shared>();
  shared->name = py::str(type.attr("__module__")).cast<std::string>() + "." +
                 py::str(type.attr("__qualname__")).cast<std::string>();
  const std::string& name = shared->name;
  if (!py::hasattr(object, "step") || !PyCallable_Check(object.attr("step").ptr())) {
    throw std::invalid_argument(name + ": has no method step(obs, ref, dt) (docs/python.md)");
  }
  shared->has_reset = py::hasattr(object, "reset") && PyCallable_Check(object.attr("reset").ptr());
  shared->has_set_parameters =
      py::hasattr(object, "set_parameters") && PyCallable_Check(object.attr("set_parameters").ptr());

  // parameters = {name: dict(default=, unit=, min=, max=, description=) or a default value}
  std::vector<double> values;
  const py::object declared = py::getattr(object, "parameters", py::none());
  if (!declared.is_none()) {
    if (!py::isinstance<py::dict>(declared)) {
      throw std::invalid_argument(
          fmt::format("{}.parameters: got {}, expected a dict name -> dict(default=, unit=, "
                      "min=, max=, description=)",
                      name, describe_value(declared)));
    }
    for (const auto& [key, spec] : declared.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key)) {
        throw std::invalid_argument(fmt::format("{}.parameters: key {} is not a string", name, describe_value(key)));
      }
      const std::string pname = key.cast<std::string>();
      const std::string where = fmt::format("{}.parameters['{}']", name, pname);
      if (!valid_parameter_name(pname)) {
        throw std::invalid_argument(where +
                                    ": expected a name of letters, digits, '_' and '.', starting with a letter");
      }
      if (control::node_parameters().find(pname) || pname == kTimeoutName) {
        throw std::invalid_argument(where + ": the name is taken by the controller node's own parameter");
      }
      double def = 0.0, lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
      std::string unit, description;
      if (py::isinstance<py::dict>(spec)) {
        const py::dict s = spec.cast<py::dict>();
        for (const auto& [k, v] : s) {
          const std::string field = py::str(k).cast<std::string>();
          if (field == "default") {
            def = declared_number(where + "['default']", v);
          } else if (field == "min") {
            lo = declared_number(where + "['min']", v);
          } else if (field == "max") {
            hi = declared_number(where + "['max']", v);
          } else if (field == "unit" || field == "description") {
            if (!py::isinstance<py::str>(v)) {
              throw std::invalid_argument(
                  fmt::format("{}['{}']: got {}, expected a string", where, field, describe_value(v)));
            }
            (field == "unit" ? unit : description) = v.cast<std::string>();
          } else {
            throw std::invalid_argument(
                fmt::format("{}: unknown key '{}'; expected default, unit, min, max, description{}", where, field,
                            util::did_you_mean(field, {"default", "unit", "min", "max", "description"})));
          }
        }
        if (!s.contains("default")) {
          throw std::invalid_argument(where + ": no default; expected dict(default=..., ...)");
        }
      } else {
        def = declared_number(where, spec);
      }
      if (std::isnan(lo) || std::isnan(hi) || lo > hi) {
        throw std::invalid_argument(fmt::format("{}: min {:g} above max {:g}", where, lo, hi));
      }
      const std::string& n = shared->strings.emplace_back(pname);
      const std::string& u = shared->strings.emplace_back(unit);
      const std::string& dsc = shared->strings.emplace_back(
          description.empty() ? "parameter of the Python controller " + name : description);
      control::ParameterSpec ps{n, u, dsc, lo, hi, {}, true};
      // The value: the object's attribute of that name when it has a number there, else the default.
      double value = def;
      const py::object attr = py::getattr(object, pname.c_str(), py::none());
      if (!attr.is_none() && is_real_number(attr)) value = py::float_(attr).cast<double>();
      if (std::string err = control::check_value(ps, value); !err.empty()) {
        throw std::invalid_argument(where + ": " + err +
                                    (value == def ? " (its default)" : " (the object's attribute of that name)"));
      }
      shared->specs.push_back(ps);
      shared->declared.push_back(pname);
      values.push_back(value);
    }
  }
  shared->specs.push_back(control::ParameterSpec{
      kTimeoutName,
      "s",
      "longest a step may run before quadcosim.StepTimeout is raised inside it (0: no limit; a call blocked in C "
      "is only stopped when it returns)",
      0.0,
      1e6,
      {},
      false});

  const py::object outputs = py::getattr(object, "outputs", py::none());
  if (!outputs.is_none()) {
    if (py::isinstance<py::str>(outputs) || !py::isinstance<py::sequence>(outputs)) {
      throw std::invalid_argument(fmt::format("{}.outputs: got {}, expected a tuple of names (\"error.z\", ...)", name,
                                              describe_value(outputs)));
    }
    for (const auto& o : outputs) {
      if (!py::isinstance<py::str>(o) || o.cast<std::string>().empty()) {
        throw std::invalid_argument(
            fmt::format("{}.outputs: got an entry {}, expected names (strings)", name, describe_value(o)));
      }
      shared->output_names.push_back(o.cast<std::string>());
    }
    shared->reported = control::ReportedOutputs::find(shared->output_names);
  }

  double timeout = 0.0;
  if (const py::object t = py::getattr(object, "step_timeout_s", py::none()); !t.is_none()) {
    timeout = declared_number(name + ".step_timeout_s", t);
    if (std::string err = control::check_value(shared->specs.back(), timeout); !err.empty()) {
      throw std::invalid_argument(name + ".step_timeout_s: " + err);
    }
  }
  const std::size_t n_declared = values.size();
  auto c = std::shared_ptr<PyController>(
      new PyController(std::move(shared), std::move(object), std::move(values), timeout, model::Quadrotor(vehicle)));
  std::vector<std::size_t> all(n_declared);
  for (std::size_t i = 0; i < n_declared; ++i) all[i] = i;
  try {
    c->mirror_attributes(all);
  } catch (py::error_already_set& e) {
    throw std::invalid_argument(fmt::format("{}: cannot set its parameters as attributes: {}", c->name(), e.what()));
  }
  return c;
}

std::shared_ptr<PyController> load_python_controller(const std::string& target, const std::filesystem::path& folder,
                                                     const model::VehicleParams& vehicle) {
  const std::size_t colon = target.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == target.size()) {
    throw std::invalid_argument("expected module:Class (e.g. my_controllers:AltitudePD), got '" + target + "'");
  }
  const std::string module_name = target.substr(0, colon), class_path = target.substr(colon + 1);
  py::gil_scoped_acquire gil;
  py::object cls;
  try {
    // The scenario's folder and the current directory in front of sys.path while importing.
    py::list path = py::module_::import("sys").attr("path");
    const py::list saved(path);
    const std::string here = std::filesystem::current_path().string();
    const std::string there = folder.empty() ? here : std::filesystem::absolute(folder).lexically_normal().string();
    path.insert(0, there == here ? py::str(here) : py::str(there));
    if (there != here) path.insert(1, py::str(here));
    try {
      cls = py::module_::import("importlib").attr("import_module")(module_name);
    } catch (...) {
      path.attr("__setitem__")(py::slice(0, static_cast<py::ssize_t>(py::len(path)), 1), saved);
      throw;
    }
    path.attr("__setitem__")(py::slice(0, static_cast<py::ssize_t>(py::len(path)), 1), saved);
    std::size_t b = 0;
    for (;;) {
      const std::size_t e = class_path.find('.', b);
      const std::string part = class_path.substr(b, e == std::string::npos ? std::string::npos : e - b);
      if (!py::hasattr(cls, part.c_str())) {
        throw std::invalid_argument(fmt::format("module '{}' ({}) has no '{}'", module_name,
                                                py::str(py::getattr(cls, "__file__", py::str("?"))).cast<std::string>(),
                                                class_path));
      }
      cls = cls.attr(part.c_str());
      if (e == std::string::npos) break;
      b = e + 1;
    }
  } catch (py::error_already_set& e) {
    e.restore();
    throw std::invalid_argument("cannot import " + target + ": " + describe_error(fetch_error()));
  }
  try {
    return make_python_controller(cls, vehicle);
  } catch (const ControllerError& e) {
    throw std::invalid_argument(e.what());
  }
}

std::string loaded_module_file(const std::string& target) {
  const std::size_t colon = target.rfind(':');
  const std::string module_name = target.substr(0, colon == std::string::npos ? target.size() : colon);
  py::gil_scoped_acquire gil;
  const py::dict modules = py::module_::import("sys").attr("modules");
  if (!modules.contains(module_name.c_str())) return "";
  const py::object file = py::getattr(modules[module_name.c_str()], "__file__", py::none());
  return py::isinstance<py::str>(file) ? file.cast<std::string>() : "";
}

}  // namespace quadcosim::python
