// Which browser pages may connect (origin_allowed, server.hpp): the Origin header of a handshake.
#include <algorithm>
#include <cctype>

#include "foxglove/server.hpp"

namespace quadcosim::foxglove {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

bool origin_allowed(const std::string& origin, const std::vector<std::string>& allowed) {
  if (origin.empty()) return true;
  std::string o = lower(origin);
  while (!o.empty() && o.back() == '/') o.pop_back();
  for (const std::string& a : allowed) {
    std::string w = lower(a);
    while (!w.empty() && w.back() == '/') w.pop_back();
    if (w == "*" || w == o) return true;
  }
  // scheme://host[:port], nothing else (no path, no user info)
  std::string rest;
  if (o.rfind("http://", 0) == 0) {
    rest = o.substr(7);
  } else if (o.rfind("https://", 0) == 0) {
    rest = o.substr(8);
  } else {
    return false;
  }
  for (const char* host : {"localhost", "127.0.0.1", "[::1]"}) {
    const std::string h(host);
    if (rest.compare(0, h.size(), h) != 0) continue;
    const std::string port = rest.substr(h.size());
    if (port.empty()) return true;
    if (port.size() >= 2 && port.size() <= 6 && port[0] == ':' &&
        std::all_of(port.begin() + 1, port.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return true;
  }
  return false;
}

}  // namespace quadcosim::foxglove
