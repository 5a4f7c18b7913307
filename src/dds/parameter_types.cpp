#include "dds/parameter_types.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace quadcosim::dds {

std::string_view type_name(ParamType type) {
  switch (type) {
    case ParamType::kNotSet: return "not set";
    case ParamType::kBool: return "boolean";
    case ParamType::kInteger: return "integer";
    case ParamType::kDouble: return "double";
    case ParamType::kString: return "string";
    case ParamType::kByteArray: return "byte array";
    case ParamType::kBoolArray: return "boolean array";
    case ParamType::kIntegerArray: return "integer array";
    case ParamType::kDoubleArray: return "double array";
    case ParamType::kStringArray: return "string array";
  }
  return "unknown";
}

namespace {
/// A value of `type` with `member` set to `v`, the other members at their defaults.
template <class T>
ParamValue value_of(ParamType type, T ParamValue::*member, T v) {
  ParamValue p;
  p.type = type;
  p.*member = std::move(v);
  return p;
}
}  // namespace

ParamValue ParamValue::of_bool(bool v) { return value_of(ParamType::kBool, &ParamValue::bool_value, v); }
ParamValue ParamValue::of_integer(std::int64_t v) {
  return value_of(ParamType::kInteger, &ParamValue::integer_value, v);
}
ParamValue ParamValue::of_double(double v) { return value_of(ParamType::kDouble, &ParamValue::double_value, v); }
ParamValue ParamValue::of_string(std::string v) {
  return value_of(ParamType::kString, &ParamValue::string_value, std::move(v));
}

std::string_view service_suffix(ParamService service) {
  switch (service) {
    case ParamService::kGet: return "get_parameters";
    case ParamService::kGetTypes: return "get_parameter_types";
    case ParamService::kSet: return "set_parameters";
    case ParamService::kSetAtomically: return "set_parameters_atomically";
    case ParamService::kDescribe: return "describe_parameters";
    case ParamService::kList: return "list_parameters";
  }
  return "";
}

std::string NodeName::fully_qualified() const { return (ns == "/" ? "" : ns) + "/" + name; }

namespace {
bool valid_token(std::string_view t) {
  if (t.empty() || (t[0] >= '0' && t[0] <= '9')) return false;
  return std::all_of(t.begin(), t.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}
}  // namespace

NodeName parse_node_name(std::string_view text) {
  std::vector<std::string_view> tokens;
  std::string_view rest = text;
  if (!rest.empty() && rest[0] == '/') rest.remove_prefix(1);
  while (true) {
    const auto slash = rest.find('/');
    tokens.push_back(rest.substr(0, slash));
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  for (auto t : tokens) {
    if (!valid_token(t)) {
      throw std::invalid_argument("invalid ROS node name '" + std::string(text) +
                                  "': expected NAME or /NAMESPACE/NAME, each part [A-Za-z_][A-Za-z0-9_]*");
    }
  }
  NodeName n;
  n.name = std::string(tokens.back());
  if (tokens.size() > 1) {
    n.ns.clear();
    for (std::size_t i = 0; i + 1 < tokens.size(); ++i) {
      n.ns += '/';
      n.ns.append(tokens[i]);
    }
  }
  return n;
}

std::string request_topic(const NodeName& node, ParamService service) {
  return "rq" + node.fully_qualified() + "/" + std::string(service_suffix(service)) + "Request";
}

std::string reply_topic(const NodeName& node, ParamService service) {
  return "rr" + node.fully_qualified() + "/" + std::string(service_suffix(service)) + "Reply";
}

ListResult list_parameters(const std::vector<std::string>& declared, const std::vector<std::string>& prefixes,
                           std::uint64_t depth) {
  auto fewer_separators_than_depth = [depth](std::string_view s) {
    return static_cast<std::uint64_t>(std::count(s.begin(), s.end(), '.')) < depth;
  };
  const bool everything = prefixes.empty() && depth == kDepthRecursive;
  ListResult r;
  for (const auto& name : declared) {
    bool listed = everything || (prefixes.empty() && fewer_separators_than_depth(name));
    for (std::size_t i = 0; !listed && i < prefixes.size(); ++i) {
      const std::string& prefix = prefixes[i];
      if (name == prefix) {
        listed = true;
      } else if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
                 name[prefix.size()] == '.') {
        listed =
            depth == kDepthRecursive || fewer_separators_than_depth(std::string_view(name).substr(prefix.size() + 1));
      }
    }
    if (!listed) continue;
    r.names.push_back(name);
    const auto dot = name.rfind('.');
    if (dot != std::string::npos) {
      std::string p = name.substr(0, dot);
      if (std::find(r.prefixes.begin(), r.prefixes.end(), p) == r.prefixes.end()) r.prefixes.push_back(std::move(p));
    }
  }
  return r;
}

std::string python_float(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  // The shortest digits that read back as v, then Python's layout: positional for exponents in
  // [-4, 16), else d.ddde+XX with at least two exponent digits.
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
  const std::string sci(buf, r.ptr);
  const auto e = sci.find('e');
  const int exp = std::stoi(sci.substr(e + 1));
  std::string digits;
  for (char c : sci.substr(0, e)) {
    if (c >= '0' && c <= '9') digits += c;
  }
  std::string out = std::signbit(v) ? "-" : "";
  if (exp >= -4 && exp < 16) {
    if (exp < 0) {
      out += "0.";
      out.append(static_cast<std::size_t>(-exp - 1), '0');
      out += digits;
    } else {
      const auto int_digits = static_cast<std::size_t>(exp + 1);
      if (digits.size() <= int_digits) {
        out += digits + std::string(int_digits - digits.size(), '0') + ".0";
      } else {
        out.append(digits, 0, int_digits);
        out += '.';
        out.append(digits, int_digits, std::string::npos);
      }
    }
  } else {
    out += digits.substr(0, 1);
    if (digits.size() > 1) {
      out += '.';
      out.append(digits, 1, std::string::npos);
    }
    const int a = exp < 0 ? -exp : exp;
    out += std::string(exp < 0 ? "e-" : "e+") + (a < 10 ? "0" : "") + std::to_string(a);
  }
  return out;
}

namespace {

std::string python_bool(bool b) { return b ? "True" : "False"; }

// Python's repr of a str: single quotes unless the text holds a ' and no ".
std::string python_str_repr(const std::string& s) {
  const char q = (s.find('\'') != std::string::npos && s.find('"') == std::string::npos) ? '"' : '\'';
  std::string out(1, q);
  for (char c : s) {
    if (c == '\\' || c == q) {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else {
      out += c;
    }
  }
  return out + q;
}

// Python's repr of a one-byte bytes object: b'a', b'\x01', b"'".
std::string python_byte_repr(std::uint8_t b) {
  if (b == '\'') return "b\"'\"";
  if (b == '\\') return "b'\\\\'";
  if (b == '\n') return "b'\\n'";
  if (b == '\t') return "b'\\t'";
  if (b == '\r') return "b'\\r'";
  if (b >= 32 && b < 127) return std::string("b'") + static_cast<char>(b) + "'";
  static const char* hex = "0123456789abcdef";
  return std::string("b'\\x") + hex[b >> 4] + hex[b & 15] + "'";
}

template <class T, class F>
std::string python_list(const std::vector<T>& v, F item) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out += ", ";
    out += item(v[i]);
  }
  return out + "]";
}

}  // namespace

std::string ros2_get_line(const ParamValue& v) {
  switch (v.type) {
    case ParamType::kNotSet: return "Parameter not set.";
    case ParamType::kBool: return "Boolean value is: " + python_bool(v.bool_value);
    case ParamType::kInteger: return "Integer value is: " + std::to_string(v.integer_value);
    case ParamType::kDouble: return "Double value is: " + python_float(v.double_value);
    case ParamType::kString: return "String value is: " + v.string_value;
    case ParamType::kByteArray: return "Byte values are: " + python_list(v.byte_array_value, python_byte_repr);
    case ParamType::kBoolArray:
      return "Boolean values are: " + python_list(v.bool_array_value, [](bool b) { return python_bool(b); });
    case ParamType::kIntegerArray:
      return "Integer values are: " +
             python_list(v.integer_array_value, [](std::int64_t i) { return std::to_string(i); });
    case ParamType::kDoubleArray: return "Double values are: " + python_list(v.double_array_value, python_float);
    case ParamType::kStringArray: return "String values are: " + python_list(v.string_array_value, python_str_repr);
  }
  return "Unknown parameter type '" + std::to_string(static_cast<int>(v.type)) + "'";
}

ParamValue parse_param_value(std::string_view text) {
  static const char* const kTrue[] = {"true", "True", "TRUE", "yes", "Yes", "YES", "on", "On", "ON"};
  static const char* const kFalse[] = {"false", "False", "FALSE", "no", "No", "NO", "off", "Off", "OFF"};
  for (const char* t : kTrue) {
    if (text == t) return ParamValue::of_bool(true);
  }
  for (const char* f : kFalse) {
    if (text == f) return ParamValue::of_bool(false);
  }
  std::string_view body = text;
  if (!body.empty() && body[0] == '+') body.remove_prefix(1);  // YAML allows a '+', from_chars does not
  std::int64_t i = 0;
  auto ri = std::from_chars(body.data(), body.data() + body.size(), i);
  if (!body.empty() && ri.ec == std::errc() && ri.ptr == body.data() + body.size()) return ParamValue::of_integer(i);
  std::string number(body);
  for (const char* inf : {".inf", ".Inf", ".INF"}) {
    if (number == inf) return ParamValue::of_double(HUGE_VAL);
    if (number == std::string("-") + inf) return ParamValue::of_double(-HUGE_VAL);
  }
  for (const char* nan : {".nan", ".NaN", ".NAN"}) {
    if (number == nan) return ParamValue::of_double(std::nan(""));
  }
  // from_chars reads "inf"/"nan" too, which YAML leaves as strings.
  const bool numeric = !number.empty() && number.find_first_not_of("0123456789.eE+-") == std::string::npos &&
                       number.find_first_of("0123456789") != std::string::npos;
  double d = 0.0;
  auto rd = std::from_chars(number.data(), number.data() + number.size(), d);
  if (numeric && rd.ec == std::errc() && rd.ptr == number.data() + number.size()) return ParamValue::of_double(d);
  return ParamValue::of_string(std::string(text));
}

}  // namespace quadcosim::dds
