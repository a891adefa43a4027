// Helpers shared by the URDF and MJCF readers (not part of the import interface).
#pragma once

#include "import/tree_import.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "model/input_file.hpp"

#include <cctype>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

/// A robot file's text: a regular file of at most kMaxRobotFileBytes (model/input_file.hpp), else InputError. A UTF-8
/// byte order mark at its start is dropped (XML allows one; left in, it shifted every column of line 1 by 3).
inline std::string read_text(const std::string& path) {
  std::string text = InputFile(path, "robot file", kMaxRobotFileBytes).read_all();
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  return text;
}

/// Where name="NAME" first stands in a file (line 0 when not found: compiled models keep no lines; name="..."
/// before name='...'), optionally on an element of given tags (a tendon and its actuator often share a name). The
/// text is indexed once, in one pass: searching it per element from the start made importing a chain of n links
/// take time n^2 (3 000 links: 33 s).
class Locator {
 public:
  Locator(std::string path, const std::string& text) : path_(std::move(path)) {
    int line = 1;
    std::size_t line_start = 0;
    static const std::string key = "name=";
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line, line_start = i + 1;
        continue;
      }
      if (text.compare(i, key.size(), key) != 0 || i + key.size() >= text.size()) continue;
      const char q = text[i + key.size()];
      if (q != '"' && q != '\'') continue;
      const std::size_t begin = i + key.size() + 1, end = text.find(q, begin);
      if (end == std::string::npos) continue;
      // The element's tag: the word after the '<' that opens it (within this line's reach or before).
      std::string tag;
      const std::size_t open = text.rfind('<', i);
      if (open != std::string::npos && text.find('>', open) > i)
        for (std::size_t k = open + 1;
             k < i && (std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_' || text[k] == '-'); ++k)
          tag += text[k];
      (q == '"' ? double_quoted_ : single_quoted_)[text.substr(begin, end - begin)].push_back(
          {tag, SourceLocation{path_, line, static_cast<int>(i - line_start) + 1}});
    }
  }
  /// The first occurrence of the name on an element whose tag is one of `tags` if there is one, else the first.
  SourceLocation operator()(const std::string& name, std::initializer_list<const char*> tags = {}) const {
    if (!name.empty())
      for (const auto* index : {&double_quoted_, &single_quoted_}) {
        const auto it = index->find(name);
        if (it == index->end()) continue;
        for (const auto& [tag, at] : it->second)
          for (const char* t : tags)
            if (tag == t) return at;
      }
    if (!name.empty())
      for (const auto* index : {&double_quoted_, &single_quoted_})
        if (const auto it = index->find(name); it != index->end()) return it->second.front().second;
    return SourceLocation{path_, 0, 0};
  }

 private:
  std::string path_;
  using Index = std::map<std::string, std::vector<std::pair<std::string, SourceLocation>>>;  // name -> (tag, where)
  Index double_quoted_, single_quoted_;
};

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

/// What the tree format has no place for, all of it in one error: check() either records an element as left out
/// (its category is in --ignore, with a warning) or collects it, refuse() collects an element no --ignore can leave
/// out, and finish() throws one InputError that lists every collected element with its file:line and the --ignore
/// set that leaves out what can be (a robot file with tendons, contacts and actuators took one run per category).
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
    problems_.push_back({category, where, element, why});
  }
  void refuse(const SourceLocation& where, const std::string& element, const std::string& why) {
    problems_.push_back({"", where, element, why});
  }

  /// Throws the collected elements as one error (at the first one's location), if there are any.
  void finish() const {
    if (problems_.empty()) return;
    std::vector<std::string> categories;  // in order of first appearance
    for (const Problem& p : problems_)
      if (!p.category.empty() && std::find(categories.begin(), categories.end(), p.category) == categories.end())
        categories.push_back(p.category);
    std::string ignore;
    for (const std::string& c : categories) ignore += (ignore.empty() ? "" : ",") + c;
    const std::string remedy = categories.empty() ? "" : "; pass --ignore " + ignore + " to leave it out";
    const Problem& first = problems_.front();
    if (problems_.size() == 1) throw InputError(first.where, first.element, first.why + remedy);
    constexpr std::size_t kListed = 50;  // a robot file with thousands of geoms would otherwise print them all
    std::vector<std::string> notes;
    for (std::size_t i = 0; i < problems_.size() && i < kListed; ++i) {
      const Problem& p = problems_[i];
      notes.push_back(p.where.to_string() + ": " + p.element + ": " + p.why +
                      (p.category.empty() ? " (no --ignore leaves it out)" : " (--ignore " + p.category + ")"));
    }
    if (problems_.size() > kListed) notes.push_back("... and " + std::to_string(problems_.size() - kListed) + " more");
    if (!categories.empty()) notes.push_back("pass --ignore " + ignore + " to leave out those that can be");
    throw InputError(
        first.where, first.element,
        first.why + "; " + std::to_string(problems_.size()) + " elements in all are not part of hamel's tree format:",
        std::move(notes));
  }

 private:
  struct Problem {
    std::string category;  // empty: no --ignore leaves it out
    SourceLocation where;
    std::string element, why;
  };
  const ImportOptions& options_;
  const Warn& warn_;
  ImportedTree& tree_;
  std::set<std::string> reported_;
  std::vector<Problem> problems_;
};

}  // namespace hamel::import_detail
