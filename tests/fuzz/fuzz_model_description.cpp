// libFuzzer target: any bytes as modelDescription.xml (fmi/model_description.hpp).
//
// The parser may refuse the input with fmi::FmuError (its message names the element, attribute and
// value); any other exception, a crash or undefined behaviour is a bug. A description that parses
// must hold what the master relies on: outputs that index its variables, unique names that find()
// finds, a model identifier that is a C identifier (it names the binary's file).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fmi/model_description.hpp"

namespace {

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz_model_description: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace quadcosim::fmi;
  ModelDescription md;
  try {
    md = parse_model_description(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.xml");
  } catch (const FmuError&) {
    return 0;
  }
  require(!md.model_identifier.empty(), "an empty modelIdentifier was accepted");
  for (char c : md.model_identifier) {
    require(c == '_' || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'),
            "a modelIdentifier that is no C identifier was accepted");
  }
  for (std::size_t i : md.outputs) require(i < md.variables.size(), "an output index beyond the variables");
  for (const Variable& v : md.variables) {
    require(md.find(v.name) == &v, "find() does not find a variable by its name");
    require(!to_string(v.type).empty() && !to_string(v.causality).empty() && !to_string(v.variability).empty() &&
                !to_string(v.initial).empty(),
            "an enumeration without a name");
  }
  return 0;
}
