// Helpers shared by the URDF and MJCF readers (not part of the import interface).
#pragma once

#include "import/tree_import.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace hamel::import_detail {

inline Frame compose(const Frame& a, const Frame& b) {
  Frame c;
  for (int i = 0; i < 3; ++i) {
    c.p[i] = a.p[i];
    for (int j = 0; j < 3; ++j) {
      c.R[i][j] = 0;
      for (int k = 0; k < 3; ++k) c.R[i][j] += a.R[i][k] * b.R[k][j];
      c.p[i] += a.R[i][j] * b.p[j];
    }
  }
  return c;
}

inline Frame translation(double x, double y, double z) {
  Frame f;
  f.p[0] = x;
  f.p[1] = y;
  f.p[2] = z;
  return f;
}

/// Rotation of a unit quaternion (w, x, y, z).
inline Frame from_quaternion(const double p[3], double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  Frame f;
  f.R[0][0] = 1 - 2 * (y * y + z * z), f.R[0][1] = 2 * (x * y - w * z), f.R[0][2] = 2 * (x * z + w * y);
  f.R[1][0] = 2 * (x * y + w * z), f.R[1][1] = 1 - 2 * (x * x + z * z), f.R[1][2] = 2 * (y * z - w * x);
  f.R[2][0] = 2 * (x * z - w * y), f.R[2][1] = 2 * (y * z + w * x), f.R[2][2] = 1 - 2 * (x * x + y * y);
  for (int i = 0; i < 3; ++i) f.p[i] = p[i];
  return f;
}

/// R diag(d) Rᵀ.
inline void rotate_diagonal(const double R[3][3], const double d[3], double out[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      out[i][j] = 0;
      for (int k = 0; k < 3; ++k) out[i][j] += R[i][k] * d[k] * R[j][k];
    }
}

/// Adds a body (mass m, com c and inertia I about it, resolved in frame X) to mass properties held in the
/// frame X is relative to.
inline void add_in_frame(MassProperties& to, const Frame& X, double m, const double c[3], const double I[3][3]) {
  double cx[3], Ix[3][3];
  for (int i = 0; i < 3; ++i) {
    cx[i] = X.p[i];
    for (int j = 0; j < 3; ++j) cx[i] += X.R[i][j] * c[j];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Ix[i][j] = 0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) Ix[i][j] += X.R[i][k] * I[k][l] * X.R[j][l];
    }
  to.add(m, cx, Ix);
}

/// A file's text, for locating elements in error messages.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Where name="NAME" first stands in the file (line 0 when not found: compiled models keep no lines).
inline SourceLocation locate(const std::string& path, const std::string& text, const std::string& name) {
  SourceLocation loc{path, 0, 0};
  if (name.empty()) return loc;
  for (const char q : {'"', '\''}) {
    const std::string needle = std::string("name=") + q + name + q;
    const std::size_t at = text.find(needle);
    if (at == std::string::npos) continue;
    loc.line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < at; ++i)
      if (text[i] == '\n') ++loc.line, line_start = i + 1;
    loc.column = static_cast<int>(at - line_start) + 1;
    return loc;
  }
  return loc;
}

/// A C++ identifier made from a name in a robot file, unique among `taken`: other characters become '_', but never
/// a leading '_' or a run of them, which C++ reserves and which no suffix repairs (names such as "_", "a::b" or the
/// "_" of an unnamed body's unnamed joint once looped forever here); `fallback` (valid) when nothing is left. A
/// keyword, a reserved name or a name ending in "_dot" gets '_' appended; duplicates get "_2", "_3", ... (just the
/// number after a trailing '_').
inline std::string identifier(const std::string& raw, const std::string& fallback, std::set<std::string>& taken) {
  std::string s;
  for (char c : raw) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      s += c;
    else if (!s.empty() && s.back() != '_')
      s += '_';
  }
  if (s.empty()) s = fallback;
  if (std::isdigit(static_cast<unsigned char>(s[0]))) s = "j" + s;
  if (!is_valid_identifier(s)) s += "_";
  if (!is_valid_identifier(s)) s = fallback;
  const std::string separator = s.back() == '_' ? "" : "_";
  std::string out = s;
  for (std::size_t k = 2; taken.count(out) || !is_valid_identifier(out); ++k) {
    if (k > taken.size() + 2)  // one of k = 2 ... |taken| + 2 is free, and every candidate is valid
      throw std::logic_error("import: no identifier for " + quote(raw) + " from " + quote(s));
    out = s + separator + std::to_string(k);
  }
  taken.insert(out);
  return out;
}

/// Either records `what` as left out (its category is in --ignore, with a warning) or throws the error.
class Gate {
 public:
  Gate(const ImportOptions& o, const Warn& w, ImportedTree& t) : options_(o), warn_(w), tree_(t) {}
  void check(const std::string& category, const SourceLocation& where, const std::string& element,
             const std::string& why) {
    if (options_.ignore.count(category)) {
      if (reported_.insert(category).second)
        warn_("left out (--ignore " + category + "): " + element + " (and any further ones)");
      if (std::find(tree_.left_out.begin(), tree_.left_out.end(), category) == tree_.left_out.end())
        tree_.left_out.push_back(category);
      return;
    }
    throw InputError(where, element, why + "; pass --ignore " + category + " to leave it out");
  }

 private:
  const ImportOptions& options_;
  const Warn& warn_;
  ImportedTree& tree_;
  std::set<std::string> reported_;
};

}  // namespace hamel::import_detail
