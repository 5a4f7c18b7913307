#include "trajectory/polynomial_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <vector>

namespace quadcosim::trajectory {

namespace {

constexpr int kColumns = 1 + 4 * PiecewisePolynomial::kCoefficients;

std::vector<std::string> header_names() {
  std::vector<std::string> h = {"duration"};
  for (const char* axis : {"x", "y", "z", "yaw"}) {
    for (int i = 0; i < PiecewisePolynomial::kCoefficients; ++i)
      h.push_back(std::string(axis) + "^" + std::to_string(i));
  }
  return h;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t from = 0;
  while (true) {
    const auto comma = line.find(',', from);
    out.push_back(trim(line.substr(from, comma == std::string::npos ? std::string::npos : comma - from)));
    if (comma == std::string::npos) return out;
    from = comma + 1;
  }
}

}  // namespace

PiecewisePolynomial read_polynomial_csv(const std::string& path, double start_s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path + ": cannot open the file");
  auto fail = [&](int line, const std::string& what) -> FileError {
    return FileError(path + ": line " + std::to_string(line) + ": " + what);
  };
  const std::vector<std::string> names = header_names();
  std::vector<PiecewisePolynomial::Segment> segments;
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (trim(line).empty()) continue;
    std::vector<std::string> f = split(line);
    if (f.size() != static_cast<std::size_t>(kColumns)) {
      throw fail(number, "got " + std::to_string(f.size()) + " columns, expected " + std::to_string(kColumns) +
                             (header ? " (Duration and 8 coefficients each of x, y, z, yaw)"
                                     : " in the header Duration,x^0,...,x^7,y^0,...,y^7,z^0,...,z^7,yaw^0,...,yaw^7"));
    }
    if (!header) {
      for (int c = 0; c < kColumns; ++c) {
        std::string got = f[static_cast<std::size_t>(c)];
        std::transform(got.begin(), got.end(), got.begin(), [](unsigned char ch) { return std::tolower(ch); });
        if (got != names[static_cast<std::size_t>(c)]) {
          throw fail(number, "bad header: column " + std::to_string(c + 1) + " is '" + f[static_cast<std::size_t>(c)] +
                                 "', expected '" + names[static_cast<std::size_t>(c)] + "'");
        }
      }
      header = true;
      continue;
    }
    double v[kColumns];
    for (int c = 0; c < kColumns; ++c) {
      const std::string& text = f[static_cast<std::size_t>(c)];
      const char* b = text.data() + (text.size() > 1 && text[0] == '+' ? 1 : 0);
      const char* e = text.data() + text.size();
      const auto [end, ec] = std::from_chars(b, e, v[c]);
      const std::string where = "column " + std::to_string(c + 1) + " (" + names[static_cast<std::size_t>(c)] + ")";
      if (text.empty() || ec != std::errc() || end != e) {
        throw fail(number, where + ": got '" + text + "', expected a number");
      }
      if (!std::isfinite(v[c])) throw fail(number, where + ": got '" + text + "', expected a finite number");
    }
    if (v[0] <= 0) throw fail(number, "Duration " + f[0] + " s, expected a duration > 0");
    PiecewisePolynomial::Segment s;
    s.duration_s = v[0];
    for (int r = 0; r < 4; ++r) {
      for (int i = 0; i < PiecewisePolynomial::kCoefficients; ++i) {
        s.c(r, i) = v[1 + r * PiecewisePolynomial::kCoefficients + i];
      }
    }
    segments.push_back(s);
  }
  if (!header) throw FileError(path + ": empty file, expected the header Duration,x^0,...,yaw^7 and segments");
  if (segments.empty()) throw FileError(path + ": no segment after the header");
  return PiecewisePolynomial(std::move(segments), start_s, "polynomial file " + path);
}

void write_polynomial_csv(const std::string& path, const PiecewisePolynomial& poly) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot write the file");
  const std::vector<std::string> names = header_names();
  out << "Duration";
  for (std::size_t c = 1; c < names.size(); ++c) out << ',' << names[c];
  out << '\n';
  auto put = [&](double v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.write(buf, r.ptr - buf);
  };
  for (const auto& s : poly.segments()) {
    put(s.duration_s);
    for (int r = 0; r < 4; ++r) {
      for (int i = 0; i < PiecewisePolynomial::kCoefficients; ++i) {
        out << ',';
        put(s.c(r, i));
      }
    }
    out << '\n';
  }
  out.flush();
  if (!out) throw std::runtime_error(path + ": cannot write the file");
}

}  // namespace quadcosim::trajectory
