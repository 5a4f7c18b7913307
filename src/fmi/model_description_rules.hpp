// The rules of the FMI standard that a schema cannot check, applied to a description before
// model_description_writer.cpp writes it: allowed causality/variability/initial combinations, start
// present or absent, outputs listed, value references unique, one independent variable in FMI 3,
// names, text XML can carry, and units made of known SI symbols (their base units, which the
// writer declares).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "fmi/model_description.hpp"

namespace quadcosim::fmi {

/// Exponents of the SI base units FMI's BaseUnit names (kg, m, s, A, K, mol, cd, rad) and the factor
/// to them (1 but for "deg"); offset 0 for every unit quadcosim writes.
struct BaseUnit {
  std::array<int, 8> exponent{};
  double factor = 1.0;
  static constexpr std::array<const char*, 8> kNames = {"kg", "m", "s", "A", "K", "mol", "cd", "rad"};

  BaseUnit& operator*=(const BaseUnit& o) {
    for (std::size_t i = 0; i < exponent.size(); ++i) exponent[i] += o.exponent[i];
    factor *= o.factor;
    return *this;
  }
  BaseUnit power(int n) const {
    BaseUnit r = *this;
    for (int& e : r.exponent) e *= n;
    r.factor = std::pow(factor, n);
    return r;
  }
};

/// What write_model_description writes after the checks.
struct Checked {
  std::vector<Initial> initial;    ///< per variable, as written (kUnset: attribute omitted)
  std::vector<Initial> effective;  ///< per variable, as a reader infers it (kUnset: none applies)
  std::vector<std::string> units;  ///< every unit used, in first-use order
  std::map<std::string, BaseUnit> base_units;
  bool structured = true;
};

/// Checks `md` against the rules above; throws FmuError ("modelDescription.xml: ...") naming the
/// variable or attribute that breaks one.
Checked check_model_description(const ModelDescription& md);

}  // namespace quadcosim::fmi
