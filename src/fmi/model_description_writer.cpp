// modelDescription.xml for `quadcosim fmu export`: FMI 2.0 (ScalarVariable with a Real, Integer,
// Boolean or String child, ModelStructure by 1-based index) or FMI 3.0 (typed variable elements,
// ModelStructure by value reference), written with libxml2's xmlTextWriter, which escapes text and
// attribute values. Before writing, the description is checked against the rules of the standard
// that a schema cannot check (model_description_rules.hpp): a description the standard refuses is an
// FmuError naming the variable, never a broken FMU.
#include <libxml/xmlstring.h>
#include <libxml/xmlwriter.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "fmi/model_description.hpp"
#include "fmi/model_description_rules.hpp"

namespace quadcosim::fmi {

namespace {

std::string number(double x) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, ec == std::errc{} ? end : buf);
}

// ---- Writing --------------------------------------------------------------------------------------

/// xmlTextWriter with errors as FmuError.
class Writer {
 public:
  Writer() : buffer_(xmlBufferCreate(), xmlBufferFree) {
    if (!buffer_) throw FmuError("modelDescription.xml: out of memory");
    writer_.reset(xmlNewTextWriterMemory(buffer_.get(), 0));
    if (!writer_) throw FmuError("modelDescription.xml: cannot create the XML writer");
    xmlTextWriterSetIndent(writer_.get(), 1);
    xmlTextWriterSetIndentString(writer_.get(), BAD_CAST "  ");
    ok(xmlTextWriterStartDocument(writer_.get(), nullptr, "UTF-8", nullptr));
  }

  void start(const char* element) { ok(xmlTextWriterStartElement(writer_.get(), BAD_CAST element)); }
  void end() { ok(xmlTextWriterEndElement(writer_.get())); }
  void attribute(const char* name, std::string_view value) {
    const std::string v(value);
    ok(xmlTextWriterWriteAttribute(writer_.get(), BAD_CAST name, BAD_CAST v.c_str()));
  }
  void attribute(const char* name, double value) { attribute(name, number(value)); }
  void attribute(const char* name, bool value) { attribute(name, std::string_view(value ? "true" : "false")); }
  void attribute(const char* name, std::size_t value) { attribute(name, std::string_view(std::to_string(value))); }
  void comment(std::string_view text) {
    const std::string t(text);
    ok(xmlTextWriterWriteComment(writer_.get(), BAD_CAST t.c_str()));
  }

  std::string finish() {
    ok(xmlTextWriterEndDocument(writer_.get()));
    writer_.reset();  // flushes into the buffer
    return std::string(reinterpret_cast<const char*>(xmlBufferContent(buffer_.get())),
                       static_cast<std::size_t>(xmlBufferLength(buffer_.get())));
  }

 private:
  static void ok(int rc) {
    if (rc < 0) throw FmuError("modelDescription.xml: libxml2 failed to write the document");
  }
  std::unique_ptr<xmlBuffer, void (*)(xmlBufferPtr)> buffer_;
  std::unique_ptr<xmlTextWriter, void (*)(xmlTextWriterPtr)> writer_{nullptr, xmlFreeTextWriter};
};

const char* element_name(VariableType t, bool v3) {
  switch (t) {
    case VariableType::kReal: return v3 ? "Float64" : "Real";
    case VariableType::kInteger: return v3 ? "Int32" : "Integer";
    case VariableType::kBoolean: return "Boolean";
    case VariableType::kString: return "String";
    default: return "";  // refused by check()
  }
}

/// The type-specific attributes of a variable (FMI 2: on its Real/Integer/... child; FMI 3: on the
/// typed element itself); String start values are FMI 3 <Start value=""> children, written by the caller.
/// An output's `dependencies` attribute: FMI 2 lists 1-based variable indices, FMI 3 value references.
void write_dependencies(Writer& w, const ModelDescription& md, std::size_t output, bool v3) {
  const auto& deps = md.variables[output].dependencies;
  if (!deps) return;
  std::string list;
  for (const std::size_t j : *deps) {
    if (j >= md.variables.size() || md.variables[j].causality != Causality::kInput) {
      throw FmuError("modelDescription.xml: output '" + md.variables[output].name + "' depends on variable " +
                     std::to_string(j) + ", which is no input");
    }
    list += (list.empty() ? "" : " ") + std::to_string(v3 ? md.variables[j].vr : j + 1);
  }
  w.attribute("dependencies", std::string_view(list));
}

void type_attributes(Writer& w, const Variable& var, bool v3) {
  if (var.start && !(v3 && var.type == VariableType::kString)) w.attribute("start", *var.start);
  if (!var.unit.empty()) w.attribute("unit", var.unit);
  // An infinite bound is no bound (and "inf" is no xs:double): left out.
  if (var.min && std::isfinite(*var.min)) w.attribute("min", *var.min);
  if (var.max && std::isfinite(*var.max)) w.attribute("max", *var.max);
}

}  // namespace

std::string write_model_description(const ModelDescription& md) {
  const Checked checked = check_model_description(md);
  const bool v3 = md.version == FmiVersion::k3;
  Writer w;
  w.start("fmiModelDescription");
  w.attribute("fmiVersion", std::string_view(v3 ? "3.0" : "2.0"));
  w.attribute("modelName", md.model_name);
  w.attribute(v3 ? "instantiationToken" : "guid", md.guid);
  if (!md.description.empty()) w.attribute("description", md.description);
  if (!md.generation_tool.empty()) w.attribute("generationTool", md.generation_tool);
  w.attribute("variableNamingConvention", std::string_view(checked.structured ? "structured" : "flat"));
  if (!v3) w.attribute("numberOfEventIndicators", std::string_view("0"));

  w.start("CoSimulation");
  w.attribute("modelIdentifier", md.model_identifier);
  if (md.can_handle_variable_step) w.attribute("canHandleVariableCommunicationStepSize", true);
  if (md.can_be_instantiated_only_once_per_process) w.attribute("canBeInstantiatedOnlyOncePerProcess", true);
  if (md.can_get_and_set_fmu_state) w.attribute(v3 ? "canGetAndSetFMUState" : "canGetAndSetFMUstate", true);
  w.end();

  if (!checked.units.empty()) {
    w.start("UnitDefinitions");
    for (const std::string& name : checked.units) {
      w.start("Unit");
      w.attribute("name", name);
      w.start("BaseUnit");
      const BaseUnit& u = checked.base_units.at(name);
      for (std::size_t i = 0; i < u.exponent.size(); ++i) {
        if (u.exponent[i] != 0) w.attribute(BaseUnit::kNames[i], std::string_view(std::to_string(u.exponent[i])));
      }
      if (u.factor != 1.0) {
        char buf[32];
        const auto r = std::to_chars(buf, buf + sizeof buf, u.factor);  // shortest round trip
        w.attribute("factor", std::string_view(buf, static_cast<std::size_t>(r.ptr - buf)));
      }
      w.end();
      w.end();
    }
    w.end();
  }

  for (const auto& [name, value] : {std::pair{"startTime", md.start_time}, std::pair{"stopTime", md.stop_time},
                                    std::pair{"stepSize", md.step_size}}) {
    if (value && !std::isfinite(*value))
      throw FmuError(std::string("modelDescription.xml: DefaultExperiment ") + name + " is not finite");
  }
  if (md.start_time || md.stop_time || md.step_size) {
    w.start("DefaultExperiment");
    if (md.start_time) w.attribute("startTime", *md.start_time);
    if (md.stop_time) w.attribute("stopTime", *md.stop_time);
    if (md.step_size) w.attribute("stepSize", *md.step_size);
    w.end();
  }

  w.start("ModelVariables");
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    const Variable& var = md.variables[i];
    if (!v3) w.comment(" index " + std::to_string(i + 1) + " ");
    w.start(v3 ? element_name(var.type, true) : "ScalarVariable");
    w.attribute("name", var.name);
    w.attribute("valueReference", std::string_view(std::to_string(var.vr)));
    if (!var.description.empty()) w.attribute("description", var.description);
    w.attribute("causality", to_string(var.causality));
    w.attribute("variability", to_string(var.variability));
    if (checked.initial[i] != Initial::kUnset) w.attribute("initial", to_string(checked.initial[i]));
    if (v3) {
      type_attributes(w, var, true);
      if (var.type == VariableType::kString && var.start) {
        w.start("Start");
        w.attribute("value", *var.start);
        w.end();
      }
    } else {
      w.start(element_name(var.type, false));
      type_attributes(w, var, false);
      w.end();
    }
    w.end();
  }
  w.end();

  // Initial unknowns: outputs computed (or guessed) in initialization, and calculated parameters;
  // there are no continuous states exposed (co-simulation only), so nothing else.
  std::vector<std::size_t> initial_unknowns;
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    const Variable& var = md.variables[i];
    const Initial init = checked.effective[i];
    if ((var.causality == Causality::kOutput && (init == Initial::kApprox || init == Initial::kCalculated)) ||
        var.causality == Causality::kCalculatedParameter)
      initial_unknowns.push_back(i);
  }

  w.start("ModelStructure");
  if (v3) {
    for (const std::size_t i : md.outputs) {
      w.start("Output");
      w.attribute("valueReference", std::string_view(std::to_string(md.variables[i].vr)));
      write_dependencies(w, md, i, v3);
      w.end();
    }
    for (const std::size_t i : initial_unknowns) {
      w.start("InitialUnknown");
      w.attribute("valueReference", std::string_view(std::to_string(md.variables[i].vr)));
      w.end();
    }
  } else {
    if (!md.outputs.empty()) {
      w.start("Outputs");
      for (const std::size_t i : md.outputs) {
        w.start("Unknown");
        w.attribute("index", i + 1);
        write_dependencies(w, md, i, v3);
        w.end();
      }
      w.end();
    }
    if (!initial_unknowns.empty()) {
      w.start("InitialUnknowns");
      for (const std::size_t i : initial_unknowns) {
        w.start("Unknown");
        w.attribute("index", i + 1);
        w.end();
      }
      w.end();
    }
  }
  w.end();

  w.end();  // fmiModelDescription
  return w.finish();
}

}  // namespace quadcosim::fmi
