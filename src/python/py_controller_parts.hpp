// What the source files of the Python controller (python/py_controller.hpp) share: the tables every
// copy shares (PyController::Shared), the step's Python objects (PyController::Call) and where their
// arrays are in its buffer. py_controller.cpp holds the controller's life and parameters,
// py_controller_step.cpp its step, py_controller_make.cpp how one is made from a Python object.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <deque>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller_config.hpp"
#include "python/py_controller.hpp"
#include "python/py_sensor_views.hpp"

namespace quadcosim::python {

/// The parameter every Python controller has beside its declared ones.
inline constexpr std::string_view kTimeoutName = "step_timeout_s";

struct PyController::Shared {
  std::string name;                           ///< module.Class
  std::deque<std::string> strings;            ///< owns what the specs' string_views show
  std::vector<control::ParameterSpec> specs;  ///< the declared ones, then step_timeout_s
  std::vector<std::string> declared;          ///< their names (attributes of the object)
  std::vector<std::string> output_names;
  control::ReportedOutputs reported;  ///< where among output_names the class reports its attitude setpoint
  bool has_reset = false, has_set_parameters = false;
};

/// The objects of the step call, made at the first step.
struct PyController::Call {
  pybind11::object step;      ///< the bound method
  pybind11::object obs, ref;  ///< Observation and Reference instances
  pybind11::object obs_dict, ref_dict;
  pybind11::array_t<double> buffer;  ///< the arrays' memory: obs p v q w f, ref p v a j
  double* data = nullptr;
  pybind11::object dt;
  double dt_value = std::numeric_limits<double>::quiet_NaN();
  int mode = -1;
  SensorViews sensors;  ///< obs.magnetometer, obs.barometer, obs.gnss
};

// Offsets of the arrays in Call::buffer.
enum Offset {
  kObsP = 0,
  kObsV = 3,
  kObsQ = 6,
  kObsW = 10,
  kObsF = 13,
  kRefP = 16,
  kRefV = 19,
  kRefA = 22,
  kRefJ = 25,
  kBufferSize = 28
};

}  // namespace quadcosim::python
