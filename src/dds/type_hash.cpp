#include "dds/type_hash.hpp"

#include <openssl/evp.h>

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "dds/graph.hpp"

namespace quadcosim::dds {

namespace {

// type_description_interfaces/msg/FieldType: the ids of the element types; an array adds 48, a
// bounded sequence 96, an unbounded sequence 144.
constexpr int kNestedType = 1;
constexpr int kBoundedString = 21;
constexpr int kBoundedWString = 22;
constexpr int kArray = 48;
constexpr int kBoundedSequence = 96;
constexpr int kUnboundedSequence = 144;

const std::map<std::string, int, std::less<>>& primitive_ids() {
  // .msg names; char is uint8 and byte is octet (rosidl_adapter), float32/64 are float/double.
  static const std::map<std::string, int, std::less<>> ids = {
      {"int8", 2},     {"uint8", 3},  {"char", 3},  {"int16", 4},   {"uint16", 5},
      {"int32", 6},    {"uint32", 7}, {"int64", 8}, {"uint64", 9},  {"float32", 10},
      {"float64", 11}, {"bool", 15},  {"byte", 16}, {"string", 17}, {"wstring", 18},
  };
  return ids;
}

struct FieldType {
  int type_id = 0;
  std::uint64_t capacity = 0;
  std::uint64_t string_capacity = 0;
  std::string nested_type_name;
};

struct Field {
  std::string name;
  FieldType type;
};

bool is_name(std::string_view s, bool slashes) {
  if (s.empty()) return false;
  for (char c : s) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || (slashes && c == '/');
    if (!ok) return false;
  }
  return true;
}

std::uint64_t parse_count(std::string_view s, const std::string& where) {
  if (s.empty() || s.size() > 9) throw std::invalid_argument(where + ": bad size '" + std::string(s) + "'");
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') throw std::invalid_argument(where + ": bad size '" + std::string(s) + "'");
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return v;
}

// One line of a description, "TYPE NAME" in .msg syntax.
Field parse_field(std::string_view line, const std::string& owner) {
  const std::string where = owner + " field '" + std::string(line) + "'";
  const auto space = line.find(' ');
  if (space == std::string_view::npos) throw std::invalid_argument(where + ": expected 'TYPE NAME'");
  std::string_view type = line.substr(0, space);
  Field f;
  f.name = std::string(line.substr(space + 1));
  if (!is_name(f.name, false)) throw std::invalid_argument(where + ": bad field name");
  int container = 0;
  if (const auto open = type.find('['); open != std::string_view::npos) {
    if (type.back() != ']') throw std::invalid_argument(where + ": unterminated '['");
    const std::string_view inside = type.substr(open + 1, type.size() - open - 2);
    type = type.substr(0, open);
    if (inside.empty()) {
      container = kUnboundedSequence;
    } else if (inside.substr(0, 2) == "<=") {
      container = kBoundedSequence;
      f.type.capacity = parse_count(inside.substr(2), where);
    } else {
      container = kArray;
      f.type.capacity = parse_count(inside, where);
    }
  }
  int element = 0;
  if (type.find('/') != std::string_view::npos) {
    if (!is_name(type, true)) throw std::invalid_argument(where + ": bad type name");
    element = kNestedType;
    f.type.nested_type_name = std::string(type);
  } else if (const auto bound = type.find("<="); bound != std::string_view::npos) {
    const std::string_view base = type.substr(0, bound);
    if (base != "string" && base != "wstring") throw std::invalid_argument(where + ": only strings have a bound");
    element = base == "string" ? kBoundedString : kBoundedWString;
    f.type.string_capacity = parse_count(type.substr(bound + 2), where);
  } else {
    const auto it = primitive_ids().find(type);
    if (it == primitive_ids().end()) throw std::invalid_argument(where + ": unknown type '" + std::string(type) + "'");
    element = it->second;
  }
  f.type.type_id = element + container;
  return f;
}

std::vector<Field> parse_fields(std::string_view text, const std::string& owner) {
  std::vector<Field> fields;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    if (end > pos) fields.push_back(parse_field(text.substr(pos, end - pos), owner));
    pos = end + 1;
  }
  // rosidl gives a structure without members this one (rosidl_parser definition.py).
  if (fields.empty()) fields.push_back(parse_field("uint8 structure_needs_at_least_one_member", owner));
  return fields;
}

using Types = std::map<std::string, std::vector<Field>, std::less<>>;

void add(Types& types, const std::string& name, std::vector<Field> fields) {
  if (!is_name(name, true)) throw std::invalid_argument("type name '" + name + "' is not valid");
  if (!types.emplace(name, std::move(fields)).second) {
    throw std::invalid_argument("type " + name + " is described twice");
  }
}

// Every described type, services expanded as rosidl_parser does: <S>_Request, <S>_Response,
// <S>_Event {ServiceEventInfo info; <S>_Request[<=1] request; <S>_Response[<=1] response} and the
// service type <S> {request_message; response_message; event_message}.
const Types& all_types() {
  static const Types types = [] {
    Types t;
    for (const MessageDescription& m : message_descriptions()) add(t, m.name, parse_fields(m.fields, m.name));
    for (const ServiceDescription& s : service_descriptions()) {
      const std::string n = s.name;
      add(t, n + "_Request", parse_fields(s.request, n + "_Request"));
      add(t, n + "_Response", parse_fields(s.response, n + "_Response"));
      add(t, n + "_Event",
          parse_fields("service_msgs/msg/ServiceEventInfo info\n" + n + "_Request[<=1] request\n" + n +
                           "_Response[<=1] response",
                       n + "_Event"));
      add(t, n,
          parse_fields(
              n + "_Request request_message\n" + n + "_Response response_message\n" + n + "_Event event_message", n));
    }
    return t;
  }();
  return types;
}

const std::vector<Field>& fields_of(std::string_view name, std::string_view needed_by) {
  const auto it = all_types().find(name);
  if (it == all_types().end()) {
    std::string what = "no type description for " + std::string(name);
    if (!needed_by.empty()) what += " (referenced by " + std::string(needed_by) + ")";
    throw std::invalid_argument(what + "; add it to src/dds/type_descriptions.cpp");
  }
  return it->second;
}

// Python's json.dumps(separators=(', ', ': ')) of rosidl's dicts, keys in their insertion order.
void write_individual(std::string& out, const std::string& name, const std::vector<Field>& fields) {
  out += "{\"type_name\": \"" + name + "\", \"fields\": [";
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const Field& f = fields[i];
    if (i > 0) out += ", ";
    out += "{\"name\": \"" + f.name + "\", \"type\": {\"type_id\": " + std::to_string(f.type.type_id) +
           ", \"capacity\": " + std::to_string(f.type.capacity) +
           ", \"string_capacity\": " + std::to_string(f.type.string_capacity) + ", \"nested_type_name\": \"" +
           f.type.nested_type_name + "\"}}";
  }
  out += "]}";
}

std::string sha256_hex(const std::string& data) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(data.data(), data.size(), md, &n, EVP_sha256(), nullptr) != 1 || n != 32) {
    throw std::runtime_error("type hash: OpenSSL's SHA-256 failed");
  }
  static const char* hex = "0123456789abcdef";
  std::string s;
  s.reserve(64);
  for (unsigned int i = 0; i < n; ++i) {
    s += hex[md[i] >> 4];
    s += hex[md[i] & 0xf];
  }
  return s;
}

}  // namespace

std::string type_description_json(std::string_view ros_type) {
  const std::vector<Field>& top = fields_of(ros_type, "");
  // Every type reachable through nested fields, sorted by name (std::set orders as Python's sorted()).
  std::set<std::string, std::less<>> referenced;
  std::vector<std::pair<std::string, std::string>> queue;  // (type, referenced by)
  for (const Field& f : top) {
    if (!f.type.nested_type_name.empty()) queue.emplace_back(f.type.nested_type_name, std::string(ros_type));
  }
  while (!queue.empty()) {
    const auto [name, by] = queue.back();
    queue.pop_back();
    if (!referenced.insert(name).second) continue;
    for (const Field& f : fields_of(name, by)) {
      if (!f.type.nested_type_name.empty()) queue.emplace_back(f.type.nested_type_name, name);
    }
  }
  std::string out = "{\"type_description\": ";
  write_individual(out, std::string(ros_type), top);
  out += ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const std::string& name : referenced) {
    if (!first) out += ", ";
    first = false;
    write_individual(out, name, fields_of(name, ""));
  }
  out += "]}";
  return out;
}

std::string type_hash(std::string_view ros_type) {
  static const std::map<std::string, std::string, std::less<>> hashes = [] {
    std::map<std::string, std::string, std::less<>> h;
    for (const auto& [name, fields] : all_types()) h.emplace(name, "RIHS01_" + sha256_hex(type_description_json(name)));
    return h;
  }();
  const auto it = hashes.find(ros_type);
  if (it == hashes.end()) fields_of(ros_type, "");  // throws, naming the type
  return it->second;
}

std::string type_hash_user_data(std::string_view dds_type) {
  const std::string ros_type = demangle_ros_type(dds_type);
  if (ros_type == dds_type) {
    throw std::invalid_argument("type hash: '" + std::string(dds_type) + "' is not a ROS 2 DDS type name");
  }
  return "typehash=" + type_hash(ros_type) + ";";
}

void set_endpoint_user_data(dds_qos_t* qos, std::string_view dds_type, const std::string& keys) {
  const std::string user_data = keys + type_hash_user_data(dds_type);
  dds_qset_userdata(qos, user_data.data(), user_data.size());
}

}  // namespace quadcosim::dds
