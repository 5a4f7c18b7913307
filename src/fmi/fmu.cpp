// Loading an FMU (fmi/fmu.hpp): unpack, parse, find and open the binary; and what both FMI
// versions' instances share (fmu_internal.hpp): the log of what the FMU said and the status checks.
#include <dlfcn.h>
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fmi/fmu_internal.hpp"

namespace quadcosim::fmi {

namespace detail {

Library::Library(const std::string& file) : file_(file) {
  dlerror();  // clear
  handle_ = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) {
    const char* why = dlerror();
    throw FmuError(
        fmt::format("{}: cannot load the FMU's binary: {} (a temporary directory on a noexec "
                    "file system? set TMPDIR elsewhere)",
                    file, why != nullptr ? why : "unknown error"));
  }
}

Library::~Library() {
  if (handle_ != nullptr) dlclose(handle_);
}

void* Library::symbol(const char* name) const {
  dlerror();
  void* address = dlsym(handle_, name);
  if (address == nullptr) {
    throw FmuError(fmt::format("{}: the FMU's binary lacks the FMI function {}", file_, name));
  }
  return address;
}

std::string binary_path(const ModelDescription& md, const std::string& root, const std::string& fmu_path) {
  namespace fs = std::filesystem;
  const std::string platform = md.version == FmiVersion::k2 ? "linux64" : "x86_64-linux";
  const std::string relative = "binaries/" + platform + "/" + md.model_identifier + ".so";
  const fs::path file = fs::path(root) / relative;
  std::error_code ec;
  if (fs::is_regular_file(file, ec)) return file.string();
  std::string present;
  for (const auto& entry : fs::directory_iterator(fs::path(root) / "binaries", ec)) {
    present += (present.empty() ? "" : ", ") + entry.path().filename().string();
  }
  throw FmuError(fmt::format("{}: has no binary for this platform: {} is missing (binaries present: {})", fmu_path,
                             relative, present.empty() ? "none" : present));
}

std::string file_uri(const std::string& absolute_path) {
  std::string uri = "file://";
  for (const unsigned char c : absolute_path) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                       c == '.' || c == '_' || c == '~' || c == '/';
    if (plain) {
      uri += static_cast<char>(c);
    } else {
      uri += fmt::format("%{:02X}", c);
    }
  }
  return uri;
}

std::string_view to_string(Status s) {
  switch (s) {
    case Status::kOk: return "OK";
    case Status::kWarning: return "Warning";
    case Status::kDiscard: return "Discard";
    case Status::kError: return "Error";
    case Status::kFatal: return "Fatal";
    case Status::kPending: return "Pending";
  }
  return "unknown status";
}

namespace {
constexpr std::size_t kRecentMessages = 16;

std::uint64_t key(VariableType type, ValueReference vr) {
  return (static_cast<std::uint64_t>(type) << 32) | static_cast<std::uint64_t>(vr);
}
std::uint8_t type_bit(VariableType type) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(type)); }
}  // namespace

InstanceCore::InstanceCore(const Fmu& fmu, std::string instance_name, LogSink sink)
    : md_(fmu.description()), instance_name_(std::move(instance_name)), sink_(std::move(sink)) {
  for (std::size_t i = 0; i < md_.variables.size(); ++i) {
    const Variable& v = md_.variables[i];
    by_vr_.emplace(key(v.type, v.vr), i);  // the first of aliases names it
    // FMI 2 gets and sets an Enumeration with fmi2GetInteger / fmi2SetInteger.
    if (md_.version == FmiVersion::k2 && v.type == VariableType::kEnumeration) {
      by_vr_.emplace(key(VariableType::kInteger, v.vr), i);
    }
  }
  for (const auto& [k, i] : by_vr_) {
    const auto vr = static_cast<ValueReference>(k & 0xffffffffu);
    if (vr >= kDenseLimit) continue;
    if (vr >= known_.size()) known_.resize(vr + 1, 0);
    known_[vr] |= type_bit(static_cast<VariableType>(k >> 32));
  }
}

void InstanceCore::on_log(Status status, const char* category, const char* message) {
  Message m{status, category != nullptr ? category : "", message != nullptr ? message : ""};
  if (sink_) {
    // The sink must not throw into the FMU's C code; a throwing sink loses its message.
    try {
      sink_(m.category, std::string(to_string(status)), m.text);
    } catch (...) {
    }
  } else {
    std::fprintf(stderr, "[FMU %s] %s %s: %s\n", instance_name_.c_str(), std::string(to_string(status)).c_str(),
                 m.category.c_str(), m.text.c_str());
  }
  recent_.push_back(std::move(m));
  if (recent_.size() > kRecentMessages) recent_.pop_front();
  ++logged_;
}

void InstanceCore::begin(std::string_view call) {
  if (broken_) {
    throw FmuError(
        fmt::format("{} of FMU '{}' instance '{}': refused, the instance is unusable since {} answered "
                    "Fatal",
                    call, md_.model_name, instance_name_, broken_by_));
  }
  call_start_ = logged_;
}

std::string InstanceCore::failure(const std::string& call, std::string_view what) const {
  std::string text = fmt::format("{} of FMU '{}' instance '{}' {}", call, md_.model_name, instance_name_, what);
  // What the FMU logged during the call; the last messages before it when it logged nothing then.
  const std::size_t during = std::min(logged_ - call_start_, recent_.size());
  const std::size_t from = recent_.size() - (during > 0 ? during : std::min<std::size_t>(recent_.size(), 3));
  if (from == recent_.size()) return text + "; the FMU logged nothing";
  text += during > 0 ? "; the FMU logged: " : "; the FMU logged nothing during the call, before it: ";
  for (std::size_t i = from; i < recent_.size(); ++i) {
    if (i > from) text += " | ";
    text += fmt::format("[{}] {}", to_string(recent_[i].status), recent_[i].text);
  }
  return text;
}

void InstanceCore::handle(Status status, const std::string& call) {
  switch (status) {
    case Status::kOk: return;
    case Status::kWarning: return;  // its message went to the log already
    case Status::kFatal:
      broken_ = true;
      broken_by_ = call;
      errored = true;
      throw FmuError(failure(call, "answered Fatal (the instance is unusable now)"));
    case Status::kDiscard:
    case Status::kError:
    case Status::kPending:  // asynchronous steps are not asked for, so Pending is a failure too
      errored = true;
      throw FmuError(failure(call, fmt::format("answered {}", to_string(status))));
  }
  errored = true;
  throw FmuError(failure(call, fmt::format("answered the unknown status {}", static_cast<int>(status))));
}

void InstanceCore::expect(Phase wanted, std::string_view call) const {
  static constexpr std::string_view kNames[] = {"instantiated (before enter_initialization)",
                                                "initialization mode (before exit_initialization)",
                                                "stepping (after exit_initialization)", "terminated"};
  if (phase == wanted) return;
  throw FmuError(fmt::format("{} of FMU '{}' instance '{}': called when the instance is {}; it belongs to {}", call,
                             md_.model_name, instance_name_, kNames[static_cast<int>(phase)],
                             kNames[static_cast<int>(wanted)]));
}

std::string InstanceCore::name(ValueReference vr, VariableType type) const {
  const auto it = by_vr_.find(key(type, vr));
  if (it == by_vr_.end()) return fmt::format("value reference {}", vr);
  return md_.variables[it->second].name;
}

void InstanceCore::check_known(std::string_view call, std::span<const ValueReference> vrs, VariableType type) const {
  const std::uint8_t bit = type_bit(type);
  for (const ValueReference vr : vrs) {
    if (vr < known_.size() && (known_[vr] & bit) != 0) continue;
    if (!by_vr_.contains(key(type, vr))) {
      throw FmuError(
          fmt::format("{} of FMU '{}' instance '{}': value reference {} is no {} variable of its "
                      "modelDescription.xml",
                      call, md_.model_name, instance_name_, vr, fmi::to_string(type)));
    }
  }
}

}  // namespace detail

std::shared_ptr<Fmu> Fmu::load(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw FmuError(fmt::format("{}: no such FMU (file or directory)", path));
  detail::FmuFiles files;
  if (fs::is_directory(status)) {
    files.root = path;
  } else {
    files.unpacked = unpack(path);
    files.root = files.unpacked->path();
  }
  files.root = fs::absolute(files.root, ec).lexically_normal().string();  // the resource URI is absolute
  while (files.root.size() > 1 && files.root.back() == '/') files.root.pop_back();

  const fs::path xml_path = fs::path(files.root) / "modelDescription.xml";
  std::ifstream in(xml_path, std::ios::binary);
  if (!in) throw FmuError(fmt::format("{}: has no modelDescription.xml", path));
  std::ostringstream text;
  text << in.rdbuf();
  ModelDescription md = parse_model_description(text.str(), path + ": modelDescription.xml");
  if (md.version == FmiVersion::k2) return detail::make_fmi2_fmu(std::move(md), path, std::move(files));
  return detail::make_fmi3_fmu(std::move(md), path, std::move(files));
}

}  // namespace quadcosim::fmi
