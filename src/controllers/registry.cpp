#include "controllers/registry.hpp"

#include <array>

#include "util/did_you_mean.hpp"

#include "controllers/example_pd/example_pd_controller.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "controllers/se3/geometric_controller.hpp"

namespace quadcosim::controllers {

namespace {
// A controller class C with static kType and kDescription, constructible from the vehicle.
template <class C>
constexpr ControllerType entry() {
  return {C::kType, C::kDescription, [](const model::VehicleParams& vehicle) -> std::unique_ptr<control::Controller> {
            return std::make_unique<C>(vehicle);
          }};
}

// One line per controller; the first is the default.
static_assert(PaperController::kType == kDefaultControllerType, "kTypes starts with the default type");
const std::array kTypes = {
    entry<PaperController>(),
    entry<GeometricController>(),
    entry<ExamplePdController>(),
};
}  // namespace

std::span<const ControllerType> controller_types() { return kTypes; }

std::vector<std::string> controller_type_list() {
  std::vector<std::string> names;
  for (const auto& t : kTypes) names.emplace_back(t.name);
  return names;
}

std::string controller_type_names() {
  std::string names;
  for (const auto& t : kTypes) names += (names.empty() ? "" : ", ") + std::string(t.name);
  return names;
}

const ControllerType* find_controller_type(std::string_view name) {
  for (const auto& t : kTypes) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

control::ControllerConfig make_config(std::string_view type, const model::VehicleParams& vehicle) {
  const ControllerType* t = find_controller_type(type);
  if (!t) {
    std::vector<std::string> known;
    for (const auto& k : kTypes) known.emplace_back(k.name);
    throw std::invalid_argument("unknown controller type '" + std::string(type) +
                                "' (known: " + controller_type_names() + ")" + util::did_you_mean(type, known));
  }
  control::ControllerConfig c;
  c.vehicle = vehicle;
  c.controller = t->make(vehicle);
  return c;
}

control::ControllerConfig rebind_vehicle(const control::ControllerConfig& config, const model::VehicleParams& vehicle) {
  control::ControllerConfig c = make_config(config.type(), vehicle);
  c.node = config.node;
  // What was set differs from the type's defaults for the old vehicle; what was not set takes the new
  // vehicle's defaults (a controller whose defaults are designed from the vehicle: se3's gains).
  const control::ControllerConfig old_defaults = make_config(config.type(), config.vehicle);
  std::vector<control::Setting> settings;
  for (const control::ParameterSpec& s : config.controller->parameters()) {
    const std::optional<control::ParameterValue> value = config.controller->get_parameter(s.name);
    if (value != old_defaults.controller->get_parameter(s.name)) settings.push_back({std::string(s.name), *value});
  }
  std::unique_ptr<control::Controller> next = c.controller->clone();
  if (std::string err = next->set_parameters(settings); !err.empty()) throw std::invalid_argument(err);
  c.controller = std::move(next);
  return c;
}

}  // namespace quadcosim::controllers
