// python/py_sensor_views.hpp: the extra sensors' SensorReadings of a Python controller's obs.
#include "python/py_sensor_views.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "python/py_runtime.hpp"

namespace py = pybind11;

namespace quadcosim::python {

unsigned carried_kinds(const sensors::Readings& readings) {
  unsigned bits = 0;
  sensors::for_each_kind([&]<class Kind>() {
    if (readings.carries<Kind>()) bits |= 1u << sensors::kind_index<Kind>();
  });
  return bits;
}

namespace {

/// A stamp [ns] in seconds as a message header's sec + nanosec * 1e-9 (the same double as
/// Simulation.sensors' t).
double stamp_seconds(std::int64_t ns) {
  return static_cast<double>(ns / 1'000'000'000) + static_cast<double>(ns % 1'000'000'000) * 1e-9;
}

}  // namespace

void prepare_sensors(SensorViews& v, const py::object& obs_dict, const sensors::Readings& readings) {
  const Globals& g = globals();
  int width = 0;
  sensors::for_each_kind([&]<class Kind>() {
    if (readings.carries<Kind>()) width += sensors::sample_width<Kind>();
  });
  v.buffer = py::array_t<double>(std::max(width, 1));
  v.data = v.buffer.mutable_data();
  std::fill(v.data, v.data + std::max(width, 1), std::numeric_limits<double>::quiet_NaN());
  int at = 0;
  sensors::for_each_kind([&]<class Kind>() {
    SensorView& s = v.views[sensors::kind_index<Kind>()];
    s = SensorView{};
    const py::str name{std::string(Kind::kName)};
    if (!readings.carries<Kind>()) {
      obs_dict[name] = py::none();
      return;
    }
    s.object = g.sensor_reading_class();
    s.dict = s.object.attr("__dict__");
    s.at = at;
    for (const auto& col : Kind::kColumns) {
      const py::str key(std::string(col.name));
      if (col.width > 1) {
        s.dict[key] = read_only_view(v.buffer, at, col.width);
      } else {
        s.dict[key] = col.boolean ? py::object(py::bool_(false)) : py::object(py::float_(v.data[at]));
      }
      s.keys.push_back(key);
      at += col.width;
    }
    set_borrowed(s.dict, g.t, Py_None);
    obs_dict[name] = s.object;
  });
  v.carried = carried_kinds(readings);
}

void write_sensors(SensorViews& v, const sensors::Readings& readings) {
  const Globals& g = globals();
  sensors::for_each_kind([&]<class Kind>() {
    const sensors::Reading<Kind>* reading = readings.get<Kind>();
    if (!reading) return;
    const SensorView& s = v.views[sensors::kind_index<Kind>()];
    double* d = v.data + s.at;
    const bool sampled = reading->stamp_ns >= 0;
    if (sampled) {
      sensors::write_sample<Kind>(reading->sample, d);
    } else {
      std::fill(d, d + sensors::sample_width<Kind>(), std::numeric_limits<double>::quiet_NaN());
    }
    for (std::size_t i = 0; i < Kind::kColumns.size(); ++i) {
      const auto& col = Kind::kColumns[i];
      if (col.width == 1 && col.boolean) {
        set_borrowed(s.dict, s.keys[i].ptr(), sampled && d[0] != 0.0 ? Py_True : Py_False);
      } else if (col.width == 1) {
        set_float(s.dict, s.keys[i].ptr(), d[0]);
      }
      d += col.width;
    }
    if (sampled) {
      set_float(s.dict, g.t, stamp_seconds(reading->stamp_ns));
    } else {
      set_borrowed(s.dict, g.t, Py_None);
    }
  });
}

}  // namespace quadcosim::python
