// modelDescription.xml parsing: FMI 2.0 and 3.0 documents written here by hand, and the refusals,
// each naming what was wrong.
#include <gtest/gtest.h>

#include <string>

#include "fmi/model_description.hpp"

namespace quadcosim::fmi {
namespace {

const char* const kFmi2 = R"(<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="PointMass" guid="{8c4e810f-3df3-4a00-8276-176fa3c9f000}"
    description="a lifted point mass" generationTool="by hand" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="point_mass" canHandleVariableCommunicationStepSize="true"
      canBeInstantiatedOnlyOncePerProcess="false"/>
  <UnitDefinitions><Unit name="m"/></UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Position"><Real quantity="Length" unit="m"/></SimpleType>
  </TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="2.5" stepSize="1e-2"/>
  <ModelVariables>
    <ScalarVariable name="omega_cmd[1]" valueReference="0" causality="input" variability="continuous"
        description="rotor speed command">
      <Real unit="rad/s" start="0" min="0" max="2000"/>
    </ScalarVariable>
    <ScalarVariable name="mass_kg" valueReference="10" causality="parameter" variability="fixed" initial="exact">
      <Real unit="kg" start="1.5" min="0"/>
    </ScalarVariable>
    <ScalarVariable name="p_W[3]" valueReference="22" causality="output" initial="exact">
      <Real declaredType="Position" start="0"/>
    </ScalarVariable>
    <ScalarVariable name="steps" valueReference="1" causality="output">
      <Integer start="0"/>
    </ScalarVariable>
    <ScalarVariable name="armed" valueReference="2" causality="input"><Boolean start="true"/></ScalarVariable>
    <ScalarVariable name="label" valueReference="3" causality="parameter" variability="fixed"><String start="x"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs><Unknown index="3"/><Unknown index="4" dependencies=""/></Outputs>
    <InitialUnknowns><Unknown index="3"/></InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
)";

const char* const kFmi3 = R"(<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="PointMass3" instantiationToken="{token-3}">
  <CoSimulation modelIdentifier="point_mass3" canHandleVariableCommunicationStepSize="true"/>
  <UnitDefinitions><Unit name="m/s"/></UnitDefinitions>
  <TypeDefinitions><Float64Type name="Velocity" unit="m/s"/></TypeDefinitions>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="omega_cmd[1]" valueReference="1" causality="input" start="0" unit="rad/s"/>
    <Float64 name="v_W[3]" valueReference="7" causality="output" declaredType="Velocity"/>
    <Int32 name="count" valueReference="8" causality="output" min="-5" max="5"/>
    <Float32 name="small" valueReference="9" causality="local"/>
    <Float64 name="vec" valueReference="10" causality="local"><Dimension start="3"/></Float64>
    <Boolean name="on" valueReference="11" causality="parameter" variability="fixed" start="false"/>
    <String name="text" valueReference="12" causality="parameter" variability="fixed"><Start value="a b"/></String>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="7"/>
    <Output valueReference="8"/>
  </ModelStructure>
</fmiModelDescription>
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The message of the FmuError parsing `xml` throws ("" when it does not throw).
std::string refusal(const std::string& xml) {
  try {
    parse_model_description(xml, "test.xml");
  } catch (const FmuError& e) {
    return e.what();
  }
  return "";
}

TEST(ModelDescription, ReadsFmi2) {
  const ModelDescription md = parse_model_description(kFmi2, "test.xml");
  EXPECT_EQ(md.version, FmiVersion::k2);
  EXPECT_EQ(md.fmi_version, "2.0");
  EXPECT_EQ(md.model_name, "PointMass");
  EXPECT_EQ(md.description, "a lifted point mass");
  EXPECT_EQ(md.guid, "{8c4e810f-3df3-4a00-8276-176fa3c9f000}");
  EXPECT_EQ(md.generation_tool, "by hand");
  EXPECT_EQ(md.model_identifier, "point_mass");
  EXPECT_TRUE(md.can_handle_variable_step);
  EXPECT_FALSE(md.can_be_instantiated_only_once_per_process);
  EXPECT_EQ(md.start_time, 0.0);
  EXPECT_EQ(md.stop_time, 2.5);
  EXPECT_EQ(md.step_size, 0.01);
  ASSERT_EQ(md.variables.size(), 6u);

  const Variable* omega = md.find("omega_cmd[1]");
  ASSERT_NE(omega, nullptr);
  EXPECT_EQ(omega->vr, 0u);
  EXPECT_EQ(omega->type, VariableType::kReal);
  EXPECT_EQ(omega->causality, Causality::kInput);
  EXPECT_EQ(omega->variability, Variability::kContinuous);
  EXPECT_EQ(omega->initial, Initial::kUnset);
  EXPECT_EQ(omega->unit, "rad/s");
  EXPECT_EQ(omega->start, "0");
  EXPECT_EQ(omega->min, 0.0);
  EXPECT_EQ(omega->max, 2000.0);
  EXPECT_EQ(omega->description, "rotor speed command");

  const Variable* mass = md.find("mass_kg");
  ASSERT_NE(mass, nullptr);
  EXPECT_EQ(mass->vr, 10u);
  EXPECT_EQ(mass->causality, Causality::kParameter);
  EXPECT_EQ(mass->variability, Variability::kFixed);
  EXPECT_EQ(mass->initial, Initial::kExact);
  EXPECT_EQ(mass->start, "1.5");
  EXPECT_EQ(mass->max, std::nullopt);

  const Variable* z = md.find("p_W[3]");
  ASSERT_NE(z, nullptr);
  EXPECT_EQ(z->unit, "m");  // from its declared type
  EXPECT_EQ(z->causality, Causality::kOutput);

  EXPECT_EQ(md.find("steps")->type, VariableType::kInteger);
  EXPECT_EQ(md.find("steps")->variability, Variability::kDiscrete);  // Integer: not continuous
  EXPECT_EQ(md.find("armed")->type, VariableType::kBoolean);
  EXPECT_EQ(md.find("label")->type, VariableType::kString);
  EXPECT_EQ(md.find("label")->start, "x");
  EXPECT_EQ(md.find("p_W[1]"), nullptr);

  ASSERT_EQ(md.outputs.size(), 2u);
  EXPECT_EQ(md.variables[md.outputs[0]].name, "p_W[3]");
  EXPECT_EQ(md.variables[md.outputs[1]].name, "steps");
}

TEST(ModelDescription, ReadsFmi3) {
  const ModelDescription md = parse_model_description(kFmi3, "test.xml");
  EXPECT_EQ(md.version, FmiVersion::k3);
  EXPECT_EQ(md.guid, "{token-3}");
  EXPECT_EQ(md.model_identifier, "point_mass3");
  EXPECT_FALSE(md.step_size.has_value());
  ASSERT_EQ(md.variables.size(), 8u);
  EXPECT_EQ(md.find("text")->type, VariableType::kString);
  EXPECT_EQ(md.find("text")->start, "a b");
  EXPECT_EQ(md.find("time")->causality, Causality::kIndependent);
  EXPECT_EQ(md.find("omega_cmd[1]")->vr, 1u);
  EXPECT_EQ(md.find("omega_cmd[1]")->unit, "rad/s");
  EXPECT_EQ(md.find("v_W[3]")->unit, "m/s");
  EXPECT_EQ(md.find("v_W[3]")->type, VariableType::kReal);
  EXPECT_EQ(md.find("count")->type, VariableType::kInteger);
  EXPECT_EQ(md.find("count")->variability, Variability::kDiscrete);
  EXPECT_EQ(md.find("count")->min, -5.0);
  EXPECT_EQ(md.find("small")->type, VariableType::kOther);
  EXPECT_EQ(md.find("vec")->type, VariableType::kOther);  // an array
  EXPECT_EQ(md.find("on")->type, VariableType::kBoolean);
  EXPECT_EQ(md.find("on")->start, "false");
  ASSERT_EQ(md.outputs.size(), 2u);
  EXPECT_EQ(md.variables[md.outputs[0]].name, "v_W[3]");
  EXPECT_EQ(md.variables[md.outputs[1]].name, "count");
}

TEST(ModelDescription, NamesItsEnums) {
  EXPECT_EQ(to_string(Causality::kCalculatedParameter), "calculatedParameter");
  EXPECT_EQ(to_string(Causality::kStructuralParameter), "structuralParameter");
  EXPECT_EQ(to_string(Variability::kTunable), "tunable");
  EXPECT_EQ(to_string(Initial::kApprox), "approx");
  EXPECT_EQ(to_string(VariableType::kReal), "Real");
}

TEST(ModelDescription, RefusesMalformedXml) {
  const std::string message = refusal(std::string(kFmi2).substr(0, 400));
  EXPECT_NE(message.find("test.xml: not well-formed XML at line"), std::string::npos) << message;
  EXPECT_NE(refusal("").find("test.xml: not well-formed XML"), std::string::npos);
  EXPECT_NE(refusal("<a>").find("test.xml: not well-formed XML"), std::string::npos);
}

TEST(ModelDescription, RefusesModelExchangeOnly) {
  const std::string xml =
      replace(kFmi2, R"(<CoSimulation modelIdentifier="point_mass")", R"(<ModelExchange modelIdentifier="point_mass")");
  const std::string message = refusal(xml);
  EXPECT_NE(message.find("test.xml: model 'PointMass' has no CoSimulation element: quadcosim masters co-simulation "
                         "FMUs only (this one is for model exchange)"),
            std::string::npos)
      << message;
}

TEST(ModelDescription, NamesTheCulprit) {
  struct Case {
    std::string from, to, expected;
  };
  const Case cases[] = {
      {R"(name="mass_kg" valueReference="10")", R"(name="mass_kg")",
       "test.xml: ScalarVariable 'mass_kg' has no valueReference (line "},
      {R"(valueReference="10")", R"(valueReference="-1")",
       "ScalarVariable 'mass_kg': valueReference=\"-1\" is not an unsigned 32-bit integer"},
      {R"(valueReference="10")", R"(valueReference="4294967296")",
       "ScalarVariable 'mass_kg': valueReference=\"4294967296\" is not an unsigned 32-bit integer"},
      {R"(unit="kg" start="1.5" min="0")", R"(unit="kg" start="1.5" min="zero")",
       "ScalarVariable 'mass_kg': min=\"zero\" is not a number"},
      {R"(causality="parameter" variability="fixed" initial)", R"(causality="param" variability="fixed" initial)",
       "ScalarVariable 'mass_kg': causality=\"param\" is none of"},
      {R"(variability="fixed" initial="exact")", R"(variability="fixd" initial="exact")",
       "ScalarVariable 'mass_kg': variability=\"fixd\" is none of"},
      {R"(initial="exact")", R"(initial="maybe")", "ScalarVariable 'mass_kg': initial=\"maybe\" is none of"},
      {R"(<Real unit="kg" start="1.5" min="0"/>)", "", "ScalarVariable 'mass_kg' has no type element"},
      {R"(<Real unit="kg" start="1.5" min="0"/>)", "<Float64/>", "ScalarVariable 'mass_kg' has a <Float64>"},
      {R"(name="mass_kg")", R"(name="p_W[3]")", "two variables are named 'p_W[3]' (numbers 2 and 3)"},
      {R"(guid=)", R"(guide=)", "test.xml: fmiModelDescription has no guid"},
      {R"(fmiVersion="2.0")", R"(fmiVersion="1.0")",
       "fmiVersion=\"1.0\" is not supported: quadcosim masters FMI 2.0 and 3.0"},
      {R"(modelIdentifier="point_mass")", R"(modelIdentifier="../../evil")",
       "CoSimulation: modelIdentifier=\"../../evil\" is not a C identifier"},
      {R"(canHandleVariableCommunicationStepSize="true")", R"(canHandleVariableCommunicationStepSize="yes")",
       "CoSimulation: canHandleVariableCommunicationStepSize=\"yes\" is not a boolean"},
      {R"(stopTime="2.5")", R"(stopTime="2.5s")", "DefaultExperiment: stopTime=\"2.5s\" is not a number"},
      {R"(<Unknown index="4" dependencies=""/>)", R"(<Unknown index="7"/>)",
       "ModelStructure/Outputs/Unknown: index=\"7\" is no variable (1 to 6)"},
      {R"(<fmiModelDescription fmiVersion)", R"(<fmiModelDescriptio fmiVersion)", "not well-formed XML"},
      {R"(<?xml version="1.0" encoding="UTF-8"?>)", R"(<!DOCTYPE x [<!ENTITY a "b">]>)", "has a DOCTYPE"},
  };
  for (const Case& c : cases) {
    const std::string message = refusal(replace(kFmi2, c.from, c.to));
    EXPECT_NE(message.find(c.expected), std::string::npos) << "got: " << message << "\nwanted: " << c.expected;
  }
  const std::string fmi3 =
      refusal(replace(kFmi3, R"(<Output valueReference="8"/>)", R"(<Output valueReference="99"/>)"));
  EXPECT_NE(fmi3.find("ModelStructure/Output: valueReference 99 is no variable's"), std::string::npos) << fmi3;
  const std::string token = refusal(replace(kFmi3, "instantiationToken", "guid"));
  EXPECT_NE(token.find("fmiModelDescription has no instantiationToken"), std::string::npos) << token;
  const std::string type = refusal(replace(kFmi3, "<Int32 name", "<Real name"));
  EXPECT_NE(type.find("ModelVariables holds a <Real>, which is no FMI 3.0 variable type"), std::string::npos) << type;
}

TEST(ModelDescription, RefusesAnExternalEntity) {
  // An external entity (a classic XXE) is neither fetched nor substituted: libxml2 refuses it in an
  // attribute, and any DOCTYPE is refused anyway.
  const std::string xml =
      R"(<?xml version="1.0"?><!DOCTYPE fmiModelDescription [<!ENTITY x SYSTEM "file:///etc/passwd">]>
<fmiModelDescription fmiVersion="2.0" modelName="&x;" guid="g"><CoSimulation modelIdentifier="m"/></fmiModelDescription>)";
  const std::string message = refusal(xml);
  EXPECT_TRUE(message.find("has a DOCTYPE") != std::string::npos ||
              message.find("references external entity 'x'") != std::string::npos)
      << message;
  EXPECT_EQ(message.find("root:"), std::string::npos) << message;
}

}  // namespace
}  // namespace quadcosim::fmi
