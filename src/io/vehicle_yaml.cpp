#include "io/vehicle_yaml.hpp"

#include <fmt/format.h>

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/yaml_reader.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::io {

namespace {

using Kind = model::VehicleParameter::Kind;

// The spin signs under `key`: one per rotor of the layout, each 1 or -1.
void read_signs(YamlSection& s, const std::string& key, model::VehicleParams& v) {
  const auto n = static_cast<std::size_t>(v.rotor_count);
  const YAML::Node raw = s.node()[key];
  const std::size_t given = raw.IsSequence() ? raw.size() : 0;
  if (raw.IsSequence() && given != n) {
    s.fail(key, fmt::format("got a list of {} entries, expected {} (one per rotor of layout {}), each 1 or -1", given,
                            n, model::to_string(v.layout)));
  }
  const std::vector<double> got = s.numbers(key, {}, n);
  for (std::size_t r = 0; r < n; ++r) {
    if (got[r] != 1.0 && got[r] != -1.0) {
      s.fail(key, fmt::format("got [{:g}], expected {} entries, each 1 or -1", fmt::join(got, ", "), n));
    }
    v.spin[r] = static_cast<int>(got[r]);
  }
}

// `rotors: [{position_m: [x, y, z], spin: 1 or -1}, ...]`: a custom layout of 4 to 8 rotors.
void read_rotors(YamlSection& root, model::VehicleParams& v) {
  const std::vector<YAML::Node> list = root.sequence("rotors");
  const auto n = static_cast<int>(list.size());
  if (n < model::kMinRotors || n > model::kMaxRotors) {
    root.fail("rotors", fmt::format("got {} rotors, expected 4 to 8", n));
  }
  v.layout = model::RotorLayout::kCustom;
  v.rotor_count = n;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!list[k].IsMap()) {
      root.fail("rotors", fmt::format("entry {} is {}, expected {{position_m: [x, y, z], spin: 1 or -1}}", i + 1,
                                      YamlSection::describe(list[k])));
    }
    YamlSection r(list[k], root.file(), root.key_path("rotors") + "[" + std::to_string(i) + "]");
    if (!r.has("position_m")) r.fail("position_m", "missing; expected [x, y, z] in metres (body frame, FLU)");
    const std::vector<double> p = r.numbers("position_m", {}, 3);
    v.rotor_positions_m[k] = {p[0], p[1], p[2]};
    if (!r.has("spin")) r.fail("spin", "missing; expected 1 (clockwise seen from above) or -1");
    const double spin = r.number("spin", 1.0, -1.0, 1.0);
    if (spin != 1.0 && spin != -1.0) r.fail("spin", fmt::format("got {:g}, expected 1 or -1", spin));
    v.spin[k] = static_cast<int>(spin);
    r.reject_unknown_keys();
  }
}

// The per-rotor aerodynamic coefficients, which act only with aero.rotor_aero: true.
constexpr std::string_view kRotorAeroKeys[] = {"rotor_drag_k_d", "inflow_k_z", "flapping_k_flap",
                                               "translational_lift_k_h"};

}  // namespace

void read_vehicle(YamlSection& root, model::VehicleParams& v) {
  if (root.has("preset")) {
    const std::vector<std::string> names = model::vehicle_preset_list();
    v = model::find_vehicle_preset(root.choice("preset", names.front(), names))->params;
  }
  std::map<std::string, std::optional<YamlSection>, std::less<>> sections;
  auto section = [&](std::string_view name) -> YamlSection* {
    if (name.empty()) return &root;
    auto it = sections.find(name);
    if (it == sections.end()) it = sections.emplace(std::string(name), root.section(std::string(name))).first;
    return it->second ? &*it->second : nullptr;
  };
  const bool custom = root.has("rotors");
  const auto& table = model::vehicle_parameters();
  for (std::size_t i = 0; i < table.size(); ++i) {
    const model::VehicleParameter& p = table[i];
    YamlSection* s = section(p.section());
    if (!s) continue;
    const std::string key(p.key());
    switch (p.kind) {
      case Kind::kNumber:
        if (p.component() < 0) {
          p.ref(v) = s->number(key, p.get(v), p.range);
        } else if (p.component() == 0) {
          // Entries i, i+1, i+2 are the vector's x, y, z.
          const auto got = s->numbers(key, {p.get(v), table[i + 1].get(v), table[i + 2].get(v)}, 3);
          for (int c = 0; c < 3; ++c) {
            const model::VehicleParameter& e = table[i + static_cast<std::size_t>(c)];
            if (!e.range.contains(got[static_cast<std::size_t>(c)])) {
              s->fail(key, fmt::format("got an entry {:g}, expected numbers in {}", got[static_cast<std::size_t>(c)],
                                       e.range.text()));
            }
            e.ref(v) = got[static_cast<std::size_t>(c)];
          }
        }
        break;
      case Kind::kChoice: {
        if (key == "layout" && custom && s->has(key)) {
          const std::string l = s->choice(key, "custom", {p.choices.begin(), p.choices.end()});
          if (l != "custom") s->fail(key, "got '" + l + "' beside rotors:, which makes the layout custom");
          break;
        }
        const std::vector<std::string> choices(p.choices.begin(), p.choices.end());
        const int before = v.rotor_count;
        p.set_choice(v, s->choice(key, std::string(p.choice_of(v)), choices));
        if (v.rotor_count != before) {  // another rotor count: alternating signs, rotor 1 clockwise
          for (std::size_t r = 0; r < v.spin.size(); ++r) v.spin[r] = r % 2 == 0 ? 1 : -1;
        }
        if (key == "layout" && v.layout == model::RotorLayout::kCustom && !custom) {
          s->fail(key, "got 'custom' without rotors:, expected rotors: [{position_m: [x, y, z], spin: 1}, ...]");
        }
        break;
      }
      case Kind::kRotors:
        if (custom) read_rotors(*s, v);
        break;
      case Kind::kSigns:
        if (s->has(key)) {
          if (custom) s->fail(key, "given beside rotors:, which gives each rotor's spin; set it there");
          read_signs(*s, key, v);
        }
        break;
    }
  }
  // A per-rotor coefficient this file sets (non-zero) while the terms are off would act on nothing.
  if (YamlSection* aero = section("aero"); aero && v.aero.rotor_aero != model::RotorAero::kOn) {
    for (std::string_view key : kRotorAeroKeys) {
      const std::string k(key);
      if (aero->has(k) && model::find_vehicle_parameter("aero." + k)->get(v) != 0.0) {
        aero->fail(k, fmt::format("set to {:g} while aero.rotor_aero is false: the per-rotor terms act only with "
                                  "rotor_aero: true (add it, or remove the key)",
                                  model::find_vehicle_parameter("aero." + k)->get(v)));
      }
    }
  }
  for (auto& [name, s] : sections) {
    if (s) s->reject_unknown_keys();
  }
  root.reject_unknown_keys();
  if (std::string err = model::validate(v); !err.empty()) {
    // validate() names the field first ("spin must ..."): report it at that key.
    const std::string field = err.substr(0, err.find(' '));
    if (model::find_vehicle_parameter(field) && field.size() < err.size()) {
      root.fail(field, err.substr(field.size() + 1));
    }
    root.fail("", err);
  }
}

}  // namespace quadcosim::io
