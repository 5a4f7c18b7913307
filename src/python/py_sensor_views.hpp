// A Python controller's obs.magnetometer, obs.barometer, obs.gnss (python/py_controller.hpp): one
// SensorReading per extra sensor the vehicle carries, whose attributes C++ rewrites from the step's
// control::Observation::sensors. Internal to the Python controller.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <tuple>
#include <vector>

#include "sensors/readings.hpp"

namespace quadcosim::python {

inline constexpr std::size_t kSensorKinds = std::tuple_size_v<sensors::Kinds>;

/// obs.<sensor> of one extra sensor the vehicle carries: a SensorReading whose attributes are the
/// columns of the registry's kind (sensors/registry.hpp), made once with the Call.
struct SensorView {
  pybind11::object object, dict;       ///< the SensorReading and its __dict__; null when the kind is not carried
  std::vector<pybind11::object> keys;  ///< each column's attribute name (a vector's: its array is in place)
  int at = 0;                          ///< where the sample's packed columns are in SensorViews::buffer
};

/// The step's extra sensors: which kinds the views were made for, each kind's view, the memory of
/// their columns (every carried kind's sample packed, sensors::write_sample).
struct SensorViews {
  unsigned carried = ~0u;
  std::array<SensorView, kSensorKinds> views;
  pybind11::array_t<double> buffer;
  double* data = nullptr;
};

/// Which kinds `readings` carries, one bit per kind (sensors::kind_index).
unsigned carried_kinds(const sensors::Readings& readings);

/// (Re)makes obs.magnetometer, obs.barometer, obs.gnss for the kinds `readings` carries (None for the
/// others): every number NaN, every flag False and t None until the first sample.
void prepare_sensors(SensorViews& v, const pybind11::object& obs_dict, const sensors::Readings& readings);

/// Writes each carried kind's reading into its view.
void write_sensors(SensorViews& v, const sensors::Readings& readings);

}  // namespace quadcosim::python
