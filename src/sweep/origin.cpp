// sweep/sweep.hpp: where a sweep was started (origin.json) and the plan read back from its folder.
#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "io/output_folder.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::sweep {

namespace fs = std::filesystem;

Origin origin_of(const std::string& scenario_file, const fs::path& cwd, const char* python_path_env) {
  Origin o;
  const auto absolute = [&](const fs::path& p) { return (p.is_absolute() ? p : cwd / p).lexically_normal(); };
  o.scenario_file = absolute(scenario_file).string();
  const auto add = [&](const fs::path& folder) {
    std::string text = absolute(folder).string();
    while (text.size() > 1 && text.back() == '/') text.pop_back();  // "a/b/" and "a/b" are one folder
    if (std::find(o.python_path.begin(), o.python_path.end(), text) == o.python_path.end())
      o.python_path.push_back(text);
  };
  o.cwd = absolute(".").string();
  while (o.cwd.size() > 1 && o.cwd.back() == '/') o.cwd.pop_back();
  // As the Python controller loader searches: the scenario's folder, the current directory, PYTHONPATH.
  add(fs::path(o.scenario_file).parent_path());
  add(cwd);
  const std::string env = python_path_env ? python_path_env : "";
  std::size_t b = 0;
  while (b <= env.size() && !env.empty()) {
    const std::size_t e = std::min(env.find(':', b), env.size());
    add(env.substr(b, e - b).empty() ? fs::path(".") : fs::path(env.substr(b, e - b)));  // "" is the cwd
    b = e + 1;
  }
  return o;
}

nlohmann::json origin_json(const Origin& o) {
  return {{"scenario_file", o.scenario_file}, {"cwd", o.cwd}, {"python_path", o.python_path}};
}

std::optional<Origin> read_origin(const fs::path& dir) {
  const fs::path file = dir / kOriginFile;
  if (!fs::exists(file)) return std::nullopt;
  std::ifstream in(file);
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    Origin o;
    o.scenario_file = j.at("scenario_file").get<std::string>();
    o.cwd = j.at("cwd").get<std::string>();
    o.python_path = j.at("python_path").get<std::vector<std::string>>();
    if (!fs::path(o.scenario_file).is_absolute()) throw std::invalid_argument("scenario_file is not an absolute path");
    return o;
  } catch (const std::exception& e) {
    throw io::ConfigError(
        fmt::format("{}: not a sweep's origin record ({}); remove it to continue without it", file.string(), e.what()));
  }
}

std::string python_path_env(const Origin& o, const char* current) {
  std::vector<std::string> entries = o.python_path;
  const std::string env = current ? current : "";
  std::size_t b = 0;
  while (!env.empty() && b <= env.size()) {
    const std::size_t e = std::min(env.find(':', b), env.size());
    const std::string entry = env.substr(b, e - b);
    if (!entry.empty() && std::find(entries.begin(), entries.end(), entry) == entries.end()) entries.push_back(entry);
    b = e + 1;
  }
  std::string out;
  for (const auto& entry : entries) out += (out.empty() ? "" : ":") + entry;
  return out;
}

std::string scenario_source_of(const Origin& o) {
  std::error_code ec;
  return fs::is_directory(fs::path(o.scenario_file).parent_path(), ec) ? o.scenario_file : std::string();
}

Plan plan_of(const fs::path& dir, const io::ScenarioResolvers& resolvers) {
  nlohmann::json h;
  fs::path file = dir / "summary.json";
  if (!fs::exists(file)) file = dir / "shard.json";
  std::ifstream in(file);
  if (!in)
    throw std::runtime_error((dir / "summary.json").string() + ": not found (nor shard.json): not a sweep folder");
  try {
    in >> h;
    if (h.contains("header")) h = h.at("header");
    std::vector<std::string> specs;
    for (const auto& v : h.at("vary")) specs.push_back(v.at("spec").get<std::string>());
    const fs::path scenario = dir / "scenario.yaml";
    if (!fs::exists(scenario)) throw std::runtime_error(scenario.string() + ": not found");
    // Loaded as if where the sweep's scenario file is, so that what it names relative to its folder
    // (a Python controller's module, ...) is found from any current directory.
    const std::optional<Origin> origin = read_origin(dir);
    Plan p = make_plan(scenario.string(), specs, h.at("seed").get<std::uint64_t>(), h.at("runs_per_point").get<int>(),
                       h.at("sampler").get<std::string>() == "lhs" ? Sampler::kLhs : Sampler::kRandom, resolvers,
                       origin ? scenario_source_of(*origin) : std::string());
    if (p.runs != h.at("runs").get<int>()) throw std::runtime_error("the plan gives another number of runs");
    const std::string judge = h.value("judge", std::string("spec"));
    const auto set = io::parse_judge(judge);
    if (!set) throw std::runtime_error("judge: got '" + judge + "', expected spec, paper or none");
    p.judge = *set;
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file.string() + ": not a sweep's summary (" + e.what() + ")");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  } catch (const io::ConfigError& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace quadcosim::sweep
