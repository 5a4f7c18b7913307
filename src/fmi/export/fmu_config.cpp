// The FMU's kinds and names, where its configuration is read from, and its GUID. The configuration's
// JSON is written by fmu_config_write.cpp and read by fmu_config_read.cpp; the FMU's variables
// (describe()) are fmu_variables.cpp's.
#include "fmi/export/fmu_config.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

namespace quadcosim::fmi {

std::string_view to_string(FmuKind kind) { return kind == FmuKind::kPlant ? "plant" : "controller"; }

std::string_view model_identifier(FmuKind kind) {
  return kind == FmuKind::kPlant ? "quadcosim_plant" : "quadcosim_controller";
}

FmuConfig read_config(const std::string& directory) {
  std::string path = directory;
  if (!path.empty() && path.back() != '/') path += '/';
  path += kConfigFileName;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FmuError("cannot read the FMU's configuration " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return config_from_json(text.str(), path);
}

std::string make_guid(const FmuConfig& config) {
  FmuConfig c = config;
  c.guid.clear();
  const std::string text = to_json(c);
  // Two independent 64-bit FNV-1a hashes (different offsets) give the 128 bits.
  auto fnv = [&](std::uint64_t h) {
    for (const unsigned char ch : text) {
      h ^= ch;
      h *= 0x100000001b3ULL;
    }
    return h;
  };
  const std::uint64_t a = fnv(0xcbf29ce484222325ULL), b = fnv(0x84222325cbf29ce4ULL);
  char buf[48];
  std::snprintf(buf, sizeof buf, "{%08x-%04x-%04x-%04x-%012llx}", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xffff),
                static_cast<unsigned>(b >> 48), static_cast<unsigned long long>(b & 0xffffffffffffULL));
  return buf;
}

}  // namespace quadcosim::fmi
