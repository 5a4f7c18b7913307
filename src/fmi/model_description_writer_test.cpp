// modelDescription.xml writing: what write_model_description writes is read back the same by the
// parser (a second implementation, fmi/model_description.cpp), units get the SI exponents worked out
// by hand here, text is escaped, and descriptions the standard refuses are refused naming the variable.
#include <gtest/gtest.h>

#include <string>

#include "fmi/model_description.hpp"

namespace quadcosim::fmi {
namespace {

Variable real(std::string name, ValueReference vr, Causality c, Variability v, std::optional<std::string> start,
              std::string unit) {
  Variable var;
  var.name = std::move(name);
  var.vr = vr;
  var.causality = c;
  var.variability = v;
  var.start = std::move(start);
  var.unit = std::move(unit);
  return var;
}

/// A small plant-like description: inputs, outputs, parameters of every type, in FMI `version`.
ModelDescription sample(FmiVersion version) {
  ModelDescription md;
  md.version = version;
  md.fmi_version = version == FmiVersion::k3 ? "3.0" : "2.0";
  md.model_name = "quadcosim_plant";
  md.description = R"(a "quadrotor" <plant> & its rotors)";
  md.guid = "{0f1e2d3c-4b5a-6978-8796-a5b4c3d2e1f0}";
  md.generation_tool = "quadcosim 0.1.0";
  md.model_identifier = "quadcosim_plant";
  md.can_handle_variable_step = true;
  md.start_time = 0.0;
  md.stop_time = 10.0;
  md.step_size = 0.01;
  ValueReference vr = 0;
  if (version == FmiVersion::k3)
    md.variables.push_back(real("time", vr++, Causality::kIndependent, Variability::kContinuous, {}, "s"));
  Variable omega = real("omega_cmd[1]", vr++, Causality::kInput, Variability::kContinuous, "0", "rad/s");
  omega.min = 0.0;
  omega.max = 2500.0;
  omega.description = "rotor 1 speed command";
  md.variables.push_back(omega);
  md.outputs.push_back(md.variables.size());
  md.variables.push_back(real("p_W[3]", vr++, Causality::kOutput, Variability::kContinuous, {}, "m"));
  md.outputs.push_back(md.variables.size());
  Variable f = real("f_B[3]", vr++, Causality::kOutput, Variability::kContinuous, "9.80665", "m/s2");
  f.initial = Initial::kExact;
  md.variables.push_back(f);
  Variable mass = real("vehicle.mass_kg", vr++, Causality::kParameter, Variability::kFixed, "1.96", "kg");
  mass.min = 1e-6;
  mass.max = 1e12;
  md.variables.push_back(mass);
  md.variables.push_back(
      real("vehicle.km_Nm_per_rad2_s2", vr++, Causality::kParameter, Variability::kFixed, "1.5e-9", "N m/(rad/s)^2"));
  md.variables.push_back(real("controller.q", vr++, Causality::kParameter, Variability::kTunable, "0.25", "1/(N m)^2"));
  md.variables.push_back(
      real("vehicle.drag", vr++, Causality::kParameter, Variability::kFixed, "0", "N/((m/s) (rad/s))"));
  Variable on = real("realism.noise", vr++, Causality::kParameter, Variability::kFixed, "true", "");
  on.type = VariableType::kBoolean;
  md.variables.push_back(on);
  Variable seed = real("realism.seed", vr++, Causality::kParameter, Variability::kFixed, "7", "");
  seed.type = VariableType::kInteger;
  seed.min = 0;
  md.variables.push_back(seed);
  Variable mode = real("controller.mode", vr++, Causality::kParameter, Variability::kTunable, "a<b & \"c\"", "");
  mode.type = VariableType::kString;
  md.variables.push_back(mode);
  return md;
}

/// The message of the FmuError writing `md` throws ("" when it does not throw).
std::string refusal(const ModelDescription& md) {
  try {
    write_model_description(md);
  } catch (const FmuError& e) {
    return e.what();
  }
  return "";
}

class WriterVersions : public ::testing::TestWithParam<FmiVersion> {};

TEST_P(WriterVersions, ReadsBackWhatItWrote) {
  const ModelDescription md = sample(GetParam());
  const std::string xml = write_model_description(md);
  const ModelDescription back = parse_model_description(xml, "written.xml");
  EXPECT_EQ(back.version, md.version);
  EXPECT_EQ(back.fmi_version, md.fmi_version);
  EXPECT_EQ(back.model_name, md.model_name);
  EXPECT_EQ(back.description, md.description);
  EXPECT_EQ(back.guid, md.guid);
  EXPECT_EQ(back.generation_tool, md.generation_tool);
  EXPECT_EQ(back.model_identifier, md.model_identifier);
  EXPECT_EQ(back.can_handle_variable_step, true);
  EXPECT_EQ(back.start_time, 0.0);
  EXPECT_EQ(back.stop_time, 10.0);
  EXPECT_EQ(back.step_size, 0.01);
  ASSERT_EQ(back.variables.size(), md.variables.size());
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    const Variable& a = md.variables[i];
    const Variable& b = back.variables[i];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.vr, a.vr);
    EXPECT_EQ(b.type, a.type);
    EXPECT_EQ(b.causality, a.causality);
    EXPECT_EQ(b.variability, a.variability);
    EXPECT_EQ(b.start, a.start);
    EXPECT_EQ(b.unit, a.unit);
    EXPECT_EQ(b.description, a.description);
    EXPECT_EQ(b.min, a.min);
    EXPECT_EQ(b.max, a.max);
  }
  EXPECT_EQ(back.outputs, md.outputs);
  EXPECT_EQ(back.find("f_B[3]")->initial, Initial::kExact);
}

TEST_P(WriterVersions, DeclaresUnitsInSiBaseUnits) {
  const std::string xml = write_model_description(sample(GetParam()));
  // Worked out by hand: N = kg m s^-2.
  EXPECT_NE(xml.find("<Unit name=\"rad/s\">\n      <BaseUnit s=\"-1\" rad=\"1\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<Unit name=\"m/s2\">\n      <BaseUnit m=\"1\" s=\"-2\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Unit name=\"N m/(rad/s)^2\">\n      <BaseUnit kg=\"1\" m=\"2\" rad=\"-2\"/>"),
            std::string::npos);
  EXPECT_NE(xml.find("<Unit name=\"1/(N m)^2\">\n      <BaseUnit kg=\"-2\" m=\"-4\" s=\"4\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Unit name=\"N/((m/s) (rad/s))\">\n      <BaseUnit kg=\"1\" rad=\"-1\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<Unit name=\"kg\">\n      <BaseUnit kg=\"1\"/>"), std::string::npos);
}

TEST_P(WriterVersions, WritesStructureAndCapabilities) {
  const bool v3 = GetParam() == FmiVersion::k3;
  ModelDescription md = sample(GetParam());
  std::string xml = write_model_description(md);
  EXPECT_NE(xml.find("variableNamingConvention=\"structured\""), std::string::npos);
  EXPECT_NE(xml.find("canHandleVariableCommunicationStepSize=\"true\""), std::string::npos);
  if (v3) {
    // p_W[3] (vr 2) and f_B[3] (vr 3) are outputs; only p_W[3] is computed in initialization.
    EXPECT_NE(xml.find("<Output valueReference=\"2\"/>\n    <Output valueReference=\"3\"/>\n    "
                       "<InitialUnknown valueReference=\"2\"/>\n  </ModelStructure>"),
              std::string::npos)
        << xml;
    EXPECT_NE(xml.find("<Start value=\"a&lt;b &amp; &quot;c&quot;\"/>"), std::string::npos);
  } else {
    // 1-based indices: omega_cmd[1] is 1, p_W[3] 2, f_B[3] 3.
    EXPECT_NE(xml.find("<Outputs>\n      <Unknown index=\"2\"/>\n      <Unknown index=\"3\"/>\n    </Outputs>\n    "
                       "<InitialUnknowns>\n      <Unknown index=\"2\"/>\n    </InitialUnknowns>"),
              std::string::npos)
        << xml;
    EXPECT_NE(xml.find("numberOfEventIndicators=\"0\""), std::string::npos);
    // An input says no `initial` in FMI 2.
    EXPECT_EQ(xml.find("causality=\"input\" variability=\"continuous\" initial"), std::string::npos);
  }
  md.can_handle_variable_step = false;
  md.variables[md.outputs[0]].name = "p W";  // not a structured name
  xml = write_model_description(md);
  EXPECT_EQ(xml.find("canHandleVariableCommunicationStepSize"), std::string::npos);
  EXPECT_NE(xml.find("variableNamingConvention=\"flat\""), std::string::npos);
}

TEST_P(WriterVersions, RefusesWhatTheStandardForbids) {
  const ModelDescription good = sample(GetParam());
  const std::size_t input = GetParam() == FmiVersion::k3 ? 1 : 0;
  const std::size_t output = good.outputs[0];
  ASSERT_EQ(refusal(good), "");

  ModelDescription md = good;
  md.variables[input].start.reset();
  EXPECT_EQ(refusal(md), "modelDescription.xml: variable 'omega_cmd[1]': a start value is required");

  md = good;
  md.variables[output].start = "1";  // initial defaults to calculated for an output
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'p_W[3]': a start value is not allowed (initial=calculated or causality "
            "independent)");

  md = good;
  md.outputs.erase(md.outputs.begin());
  EXPECT_EQ(refusal(md), "modelDescription.xml: output 'p_W[3]' is missing from ModelStructure");

  md = good;
  md.outputs.push_back(input);
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: ModelStructure lists 'omega_cmd[1]' as an output; its causality is input");

  md = good;
  md.variables[output].variability = Variability::kFixed;
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'p_W[3]': causality output with variability fixed is not allowed");

  md = good;
  md.variables[input + 3].initial = Initial::kCalculated;  // a parameter
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'vehicle.mass_kg': initial=calculated is not allowed with causality "
            "parameter and variability fixed");

  md = good;
  md.variables[input].unit = "furlong/fortnight";
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'omega_cmd[1]': unit 'furlong/fortnight' is not made of known SI symbols");

  md = good;
  md.variables[input].description = "bell\a";
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'omega_cmd[1]': description holds control character 7, which XML cannot "
            "carry");

  md = good;
  md.variables[input].name = "p_W[3]";
  EXPECT_EQ(refusal(md), "modelDescription.xml: variable 'p_W[3]' is declared twice");

  md = good;
  md.model_identifier = "quadcosim-plant";
  EXPECT_EQ(refusal(md), "modelDescription.xml: CoSimulation modelIdentifier 'quadcosim-plant' is not a C identifier");

  md = good;
  md.variables.back().variability = Variability::kContinuous;  // a String
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: variable 'controller.mode': only a Real/Float64 variable can be continuous");
}

INSTANTIATE_TEST_SUITE_P(Fmi, WriterVersions, ::testing::Values(FmiVersion::k2, FmiVersion::k3),
                         [](const auto& info) { return info.param == FmiVersion::k3 ? "Fmi3" : "Fmi2"; });

TEST(ModelDescriptionWriter, ValueReferencesAreUniquePerTypeInFmi2AndOverallInFmi3) {
  ModelDescription md = sample(FmiVersion::k2);
  md.variables.back().vr = 0;  // a String beside Real 0: allowed in FMI 2
  EXPECT_EQ(refusal(md), "");
  md.variables[1].vr = 0;  // two Reals
  EXPECT_EQ(refusal(md), "modelDescription.xml: variable 'p_W[3]': valueReference 0 is also that of 'omega_cmd[1]'");

  md = sample(FmiVersion::k3);
  md.variables.back().vr = 0;
  EXPECT_EQ(refusal(md), "modelDescription.xml: variable 'controller.mode': valueReference 0 is also that of 'time'");
}

TEST(ModelDescriptionWriter, Fmi3NeedsOneIndependentVariable) {
  ModelDescription md = sample(FmiVersion::k3);
  md.variables.erase(md.variables.begin());
  for (std::size_t& i : md.outputs) --i;
  EXPECT_EQ(refusal(md),
            "modelDescription.xml: FMI 3 needs exactly one variable with causality independent (time), found 0");
  md.version = FmiVersion::k2;  // optional in FMI 2
  EXPECT_EQ(refusal(md), "");
}

}  // namespace
}  // namespace quadcosim::fmi
