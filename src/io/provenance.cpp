#include "io/provenance.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <fstream>
#include <sstream>
#include <variant>

#include "controllers/registry.hpp"
#include "io/build_stamp.hpp"
#include "io/output_folder.hpp"

namespace quadcosim::io {

namespace fs = std::filesystem;

namespace {

nlohmann::json text_or_null(const std::string& s) { return s.empty() ? nlohmann::json() : nlohmann::json(s); }

std::string host_name() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0) return "unknown";
  return name.data();
}

// The controller the scenario file itself names (before any override): its type, "python" or "fmu";
// "" when the file cannot be read (a scenario given as a dict) or names none of them.
std::string file_controller_type(const std::string& path) {
  std::error_code ec;
  if (path.empty() || !fs::is_regular_file(path, ec)) return "";
  try {
    const YAML::Node root = YAML::LoadFile(path);
    const YAML::Node c = root["controller"];
    if (!c || !c.IsMap()) return std::string(controllers::kDefaultControllerType);
    if (c["python"]) return "python";
    if (c["fmu"]) return "fmu";
    return c["type"] ? c["type"].as<std::string>() : std::string(controllers::kDefaultControllerType);
  } catch (const std::exception&) {
    return "";
  }
}

nlohmann::json parameter_values(const control::Controller& controller) {
  nlohmann::json values = nlohmann::json::object();
  for (const control::ParameterSpec& spec : controller.parameters()) {
    const auto value = controller.get_parameter(spec.name);
    if (!value) continue;
    values[std::string(spec.name)] = std::visit([](const auto& v) { return nlohmann::json(v); }, *value);
  }
  return values;
}

// A JSON value into a YAML emitter: numbers as their JSON text (shortest round trip), strings always
// double-quoted (a host name "null" or a commit of digits stays a string).
void emit(YAML::Emitter& e, const nlohmann::json& j) {
  if (j.is_object()) {
    e << YAML::BeginMap;
    for (const auto& [key, value] : j.items()) {
      e << YAML::Key << key << YAML::Value;
      emit(e, value);
    }
    e << YAML::EndMap;
  } else if (j.is_array()) {
    e << YAML::BeginSeq;
    for (const auto& value : j) emit(e, value);
    e << YAML::EndSeq;
  } else if (j.is_null()) {
    e << YAML::Null;
  } else if (j.is_string()) {
    e << YAML::DoubleQuoted << j.get<std::string>();
  } else {
    e << j.dump();
  }
}

}  // namespace

std::string file_sha256(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  if (!ctx || EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(ctx);
    return "";
  }
  std::array<char, 65536> buf{};
  bool ok = true;
  while (in) {
    in.read(buf.data(), buf.size());
    if (in.gcount() > 0 && EVP_DigestUpdate(ctx, buf.data(), static_cast<std::size_t>(in.gcount())) != 1) ok = false;
  }
  ok = ok && in.eof();
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int n = 0;
  ok = ok && EVP_DigestFinal_ex(ctx, md.data(), &n) == 1 && n == 32;
  EVP_MD_CTX_free(ctx);
  if (!ok) return "";
  std::string hex;
  for (unsigned int i = 0; i < n; ++i) hex += fmt::format("{:02x}", md[i]);
  return hex;
}

std::vector<std::string> process_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::vector<std::string> args;
  for (std::string arg; std::getline(in, arg, '\0');) args.push_back(arg);
  return args;
}

std::string python_target_of(const YAML::Node& root) {
  if (!root.IsMap()) return "";
  const YAML::Node c = root["controller"];
  if (!c || !c.IsMap() || !c["python"] || !c["python"].IsScalar()) return "";
  return c["python"].as<std::string>();
}

nlohmann::json describe_run(const Scenario& flown, const RunContext& context) {
  nlohmann::json controller;
  const std::string type(flown.controller.type());
  controller["type"] = type;
  const std::string scenario_type = file_controller_type(flown.path);
  controller["scenario_type"] = text_or_null(scenario_type);
  controller["override"] = text_or_null(context.controller_override);
  controller["parameters"] = parameter_values(*flown.controller.controller);
  std::string label = type;
  if (!context.python_target.empty()) {
    const std::string file = context.python_module ? context.python_module(context.python_target) : "";
    std::string module_file;
    if (!file.empty()) {
      std::error_code ec;
      module_file = fs::absolute(file, ec).lexically_normal().string();
    }
    controller["python"] = {{"target", context.python_target},
                            {"module_file", text_or_null(module_file)},
                            {"sha256", text_or_null(module_file.empty() ? "" : file_sha256(module_file))}};
    label = "python " + context.python_target;
  }
  if (flown.controller_fmu) {
    std::error_code ec;
    const std::string path = fs::absolute(flown.controller_fmu->path, ec).lexically_normal().string();
    controller["fmu"] = {{"path", path}, {"sha256", text_or_null(file_sha256(path))}};
    label = "fmu " + fs::path(path).filename().string();
  }
  controller["label"] = label;

  nlohmann::json scenario = {{"file", text_or_null(flown.path)},
                             {"name", flown.name},
                             {"sha256", text_or_null(file_sha256(flown.path))},
                             {"effective", "scenario.yaml"}};
  return {{"controller", controller},
          {"transport", context.transport},
          {"clock", context.clock},
          {"command_line", process_command_line()},
          {"quadcosim_version", build_version()},
          {"git_commit", build_git_commit()},
          {"host", host_name()},
          {"scenario", scenario}};
}

std::string controller_label(const nlohmann::json& provenance) {
  const auto c = provenance.find("controller");
  if (c == provenance.end() || !c->is_object()) return "";
  if (const auto l = c->find("label"); l != c->end() && l->is_string()) return l->get<std::string>();
  if (const auto t = c->find("type"); t != c->end() && t->is_string()) return t->get<std::string>();
  return "";
}

std::string scenario_text(const YAML::Node& root, const std::string& comment) {
  std::string text;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) text += "# " + line + "\n";
  YAML::Emitter e;
  e << root;
  return text + e.c_str() + "\n";
}

std::string effective_scenario_text(const std::string& scenario_file, const std::string& controller_override) {
  std::ifstream in(scenario_file, std::ios::binary);
  if (!in) throw std::runtime_error(scenario_file + ": cannot open for reading");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (controller_override.empty()) return bytes.str();
  YAML::Node root = YAML::Load(bytes.str());
  const std::string before = file_controller_type(scenario_file);
  if (before == controller_override) return bytes.str();
  set_controller_type(root, controller_override);
  return scenario_text(root, fmt::format("The scenario as flown: {} with its controller ({}) replaced by --controller "
                                         "{}.\n(Written by quadcosim from the parsed file; its comments are not kept.)",
                                         scenario_file, before.empty() ? "?" : before, controller_override));
}

void add_provenance_to_bag_metadata(const fs::path& dir, const nlohmann::json& provenance) {
  const fs::path path = dir / "metadata.yaml";
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  std::string kept;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("quadcosim_provenance:")) break;  // a previous record: always last
    kept += line + "\n";
  }
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "quadcosim_provenance" << YAML::Value;
  emit(e, provenance);
  e << YAML::EndMap;
  write_file_atomically(path, kept + e.c_str() + "\n");
}

void write_metrics_with_provenance(const fs::path& path, nlohmann::json metrics, const nlohmann::json& provenance) {
  metrics["provenance"] = provenance;
  write_file_atomically(path, metrics.dump(2) + "\n");
}

}  // namespace quadcosim::io
